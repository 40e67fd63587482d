//! A Member that records its Agora's messages (crate doc).

use crate::camera::CompressedImage;
use crate::catalogue;
use crate::foxglove::{self, FrameTransform};
use crate::profile::VIEW_PRECISION;
use crate::record::SharedRecorder;
use mrt_core::MsgType;
use mrt_dcdt::{Context, Member, MemberError, RequestType};
use mrt_msgs::{CameraFrame, Localization};
use std::collections::BTreeMap;

/// Records every catalogue message published in its Agora ([`catalogue::CATALOGUE`]) on the
/// topic `/<prefix>/<type name>` (e.g. `/home/2/WorldSnapshot`), at the message's creation
/// time (those the recorder's profile keeps: [`Recorder::due`](crate::Recorder::due)), and
/// every n-th camera image as a JPEG on `/<prefix>/camera` when the recorder asks for images
/// ([`Recorder::with_images`](crate::Recorder::with_images)). Foxglove's views
/// ([`foxglove`]): the believed pose of each `Localization` as a
/// `foxglove.FrameTransform` on `/<prefix>/pose`, and the errors and faults the robot reports
/// as `foxglove.Log` lines on `/log`. It subscribes with [`RequestType::Local`]: each robot's own messages, once (a
/// teammate's report is recorded on the teammate's topic). A message that does not encode is
/// counted in the recorder's summary and left out; a recorder that fails stops the tap's
/// Member with the error (the rest of the robot runs on).
pub struct Tap {
    prefix: String,
    recorder: SharedRecorder,
    channels: BTreeMap<MsgType, u16>,
    /// Camera images seen, for [`Recorder::with_images`](crate::Recorder::with_images).
    images: u64,
}

impl Tap {
    /// A tap recording under `/<prefix>/` into `recorder`.
    pub fn new(prefix: impl Into<String>, recorder: SharedRecorder) -> Tap {
        Tap { prefix: prefix.into(), recorder, channels: BTreeMap::new(), images: 0 }
    }
}

impl Member for Tap {
    fn name(&self) -> String {
        format!("tap-{}", self.prefix)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        for e in catalogue::CATALOGUE {
            ctx.subscribe(e.ty, RequestType::Local);
        }
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut rec = self.recorder.lock().map_err(|_| "the recorder's lock is poisoned")?;
        while let Some(m) = ctx.receive_msg() {
            let Some(e) = catalogue::entry(m.msg_type()) else { continue };
            let time = m.creation_time();
            for log in foxglove::logs_of(&m, &self.prefix, time) {
                rec.record("/log", time, &log).map_err(|e| e.to_string())?;
            }
            let channel = match self.channels.get(&e.ty) {
                Some(&c) => c,
                None => {
                    let topic = format!("/{}/{}", self.prefix, e.name);
                    let c = rec.channel(&topic, e.name, e.schema).map_err(|e| e.to_string())?;
                    self.channels.insert(e.ty, c);
                    c
                }
            };
            if rec.due(channel, time) {
                match (e.to_json)(&m) {
                    Some(Ok(json)) => rec.write(channel, time, &json).map_err(|e| e.to_string())?,
                    _ => rec.failed(),
                }
            }
            if let Ok(l) = m.get::<Localization>() {
                let pose = FrameTransform::believed(&self.prefix, &l.pose.inner, time);
                let topic = format!("/{}/pose", self.prefix);
                rec.record_rounded(&topic, time, &pose, VIEW_PRECISION)
                    .map_err(|e| e.to_string())?;
            }
            let every = u64::from(rec.images_every());
            if let (true, Ok(frame)) = (every > 0, m.get::<CameraFrame>()) {
                if let Some(image) = &frame.image {
                    if self.images % every == 0 {
                        let topic = format!("/{}/camera", self.prefix);
                        match CompressedImage::jpeg(image, time, "camera") {
                            Some(jpeg) => {
                                rec.record(&topic, time, &jpeg).map_err(|e| e.to_string())?
                            }
                            None => rec.failed(),
                        }
                    }
                    self.images += 1;
                }
            }
        }
        Ok(())
    }
}
