//! A Member that records its Agora's messages (crate doc).

use crate::camera::CompressedImage;
use crate::catalogue;
use crate::record::SharedRecorder;
use mrt_core::MsgType;
use mrt_dcdt::{Context, Member, MemberError, RequestType};
use mrt_msgs::CameraFrame;
use std::collections::BTreeMap;

/// Records every catalogue message published in its Agora ([`catalogue::CATALOGUE`]) on the
/// topic `/<prefix>/<type name>` (e.g. `/home/2/WorldSnapshot`), at the message's creation
/// time, and every n-th camera image as a JPEG on `/<prefix>/camera` when the recorder
/// asks for images ([`Recorder::with_images`](crate::Recorder::with_images)). It subscribes with [`RequestType::Local`]: each robot's own messages, once (a
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
            let json = match (e.to_json)(&m) {
                Some(Ok(json)) => json,
                _ => {
                    rec.failed();
                    continue;
                }
            };
            let channel = match self.channels.get(&e.ty) {
                Some(&c) => c,
                None => {
                    let topic = format!("/{}/{}", self.prefix, e.name);
                    let c = rec.channel(&topic, e.name, e.schema).map_err(|e| e.to_string())?;
                    self.channels.insert(e.ty, c);
                    c
                }
            };
            rec.write(channel, m.creation_time(), &json).map_err(|e| e.to_string())?;
            let every = u64::from(rec.images_every());
            if let (true, Ok(frame)) = (every > 0, m.get::<CameraFrame>()) {
                if let Some(image) = &frame.image {
                    if self.images % every == 0 {
                        let topic = format!("/{}/camera", self.prefix);
                        match CompressedImage::jpeg(image, m.creation_time(), "camera") {
                            Some(jpeg) => rec
                                .record(&topic, m.creation_time(), &jpeg)
                                .map_err(|e| e.to_string())?,
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
