//! The message types a [`Tap`](crate::Tap) records: every type of `mrt-msgs`' catalogue, with
//! its bus id, its name, its JSON schema and how a bus message of it becomes JSON.

use mrt_core::{Message, MsgType};
use mrt_dcdt::describe::{DescribeError, SelfDescribing};
use mrt_dcdt::{DeliveryWarranty, Endpoint, Msg};
use mrt_msgs::{
    BehaviorPush, BehaviorPushReply, BehaviorStatus, CameraFrame, GameInfo, HfsmStructure,
    Localization, MateReport, MotorCommand, Odometry, Percepts, PlanRequest, PlannedPath,
    ReloadRequest, RobotCommand, SonarScan, WorldSnapshot,
};
use schemars::JsonSchema;
use serde::de::DeserializeOwned;
use serde::Serialize;

/// A bus message as JSON: `None` when the message is of another type or its payload does not
/// decode.
pub type Encoded = Option<Result<Vec<u8>, serde_json::Error>>;

/// One message type of the catalogue.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// Its bus id.
    pub ty: MsgType,
    /// Its name (the Rust type's), which names its schema and ends its topics.
    pub name: &'static str,
    /// Its JSON schema (draft 2020-12).
    pub schema: fn() -> serde_json::Value,
    /// A bus message of this type as JSON.
    pub to_json: fn(&Msg) -> Encoded,
    /// A bus message of this type as the MRT manual's XML self-describing form (§3.2),
    /// generated from its type (`mrt_dcdt::describe`); `None` when the message is of another
    /// type or its payload does not decode.
    pub to_xml: fn(&Msg) -> Option<Result<String, DescribeError>>,
    /// A message of this type read from JSON and published on `ep`'s bus (what a program in
    /// another language sends through `mrt edge`).
    pub publish_json: fn(&Endpoint, &[u8], DeliveryWarranty) -> Result<(), serde_json::Error>,
}

/// The JSON schema of `T`.
pub fn schema_of<T: JsonSchema>() -> serde_json::Value {
    schemars::schema_for!(T).to_value()
}

fn json_of<T: Message + Serialize>(m: &Msg) -> Encoded {
    m.get::<T>().ok().map(serde_json::to_vec)
}

fn xml_of<T: Message + Serialize>(m: &Msg) -> Option<Result<String, DescribeError>> {
    let value = m.get::<T>().ok()?;
    Some(SelfDescribing::of_message(value, m.creation_time()).map(|d| d.to_xml()))
}

fn publish_json<T: Message + DeserializeOwned>(
    ep: &Endpoint,
    json: &[u8],
    warranty: DeliveryWarranty,
) -> Result<(), serde_json::Error> {
    ep.publish_with(serde_json::from_slice::<T>(json)?, warranty, 0);
    Ok(())
}

/// A camera frame without its images: a frame's pixels as JSON numbers would make a match's
/// recording gigabytes (the images' schema stays, their values are `null`). The other fields
/// are copied one by one, not the images (a new field must be added here, or it fails to
/// compile).
fn camera_frame_json(m: &Msg) -> Encoded {
    let f = m.get::<CameraFrame>().ok()?;
    if f.image.is_none() && f.up_image.is_none() {
        return Some(serde_json::to_vec(f));
    }
    let CameraFrame { time, sightings, robots, image: _, pan, up_image: _ } = f;
    let bare = CameraFrame {
        time: *time,
        sightings: *sightings,
        robots: robots.clone(),
        image: None,
        pan: *pan,
        up_image: None,
    };
    Some(serde_json::to_vec(&bare))
}

macro_rules! catalogue {
    ($($ty:ty $(=> $json:expr)?),* $(,)?) => {
        /// Every catalogue type, in the order of `mrt_msgs`' table.
        pub const CATALOGUE: &[Entry] = &[$(Entry {
            ty: <$ty as Message>::TYPE,
            name: <$ty as Message>::NAME,
            schema: schema_of::<$ty>,
            to_json: catalogue!(@json $ty $(, $json)?),
            to_xml: xml_of::<$ty>,
            publish_json: publish_json::<$ty>,
        }),*];
    };
    (@json $ty:ty) => { json_of::<$ty> };
    (@json $ty:ty, $json:expr) => { $json };
}

catalogue! {
    WorldSnapshot,
    RobotCommand,
    BehaviorStatus,
    ReloadRequest,
    BehaviorPush,
    BehaviorPushReply,
    HfsmStructure,
    MateReport,
    SonarScan,
    MotorCommand,
    Odometry,
    CameraFrame => camera_frame_json,
    GameInfo,
    Localization,
    Percepts,
    PlanRequest,
    PlannedPath,
}

/// The catalogue's entry for bus id `ty`.
pub fn entry(ty: MsgType) -> Option<&'static Entry> {
    CATALOGUE.iter().find(|e| e.ty == ty)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every catalogue type of `mrt-msgs`' table is here once, under its table name, and its
    /// schema is an object schema that names it.
    #[test]
    fn the_catalogue_covers_the_table_and_every_schema_names_its_type() {
        let table = mrt_msgs::ids::TABLE;
        for e in CATALOGUE {
            assert_eq!(mrt_msgs::ids::name_of(e.ty), Some(e.name), "{}", e.name);
            let schema = (e.schema)();
            assert_eq!(schema["title"], e.name, "{schema}");
            assert_eq!(CATALOGUE.iter().filter(|o| o.ty == e.ty).count(), 1);
        }
        // The table's others are the engines' own (SelfDescribing, BbUpdate, the probes).
        assert_eq!(CATALOGUE.len() + 6, table.len());
    }

    /// A camera frame is recorded with everything but its images' pixels.
    #[test]
    fn a_camera_frame_is_recorded_without_its_images() {
        use mrt_dcdt::{DeliveryWarranty, Msg, MsgHeader};
        use mrt_msgs::{Image, Sighting};
        let image = Image { width: 2, height: 1, rgb: vec![7; 6] };
        let mut frame = CameraFrame {
            time: 1.5,
            pan: Some(0.25),
            image: Some(image.clone()),
            up_image: Some(image),
            ..Default::default()
        };
        frame.sightings[mrt_msgs::sighting::BALL] = Some(Sighting { distance: 2.0, bearing: 0.1 });
        let header = MsgHeader {
            msg_type: CameraFrame::TYPE,
            member_id: mrt_core::MemberId(1),
            agora_id: mrt_core::AgoraId(1),
            priority: 0,
            warranty: DeliveryWarranty::None,
            creation_time: mrt_core::Time(0),
        };
        let msg: Box<Msg> = Box::new(Msg::new(header, frame.clone()));
        let json = (entry(CameraFrame::TYPE).unwrap().to_json)(&msg);
        let back: CameraFrame = serde_json::from_slice(&json.unwrap().unwrap()).unwrap();
        assert_eq!(back, CameraFrame { image: None, up_image: None, ..frame });
        // The XML form keeps the image as its size only.
        let xml = (entry(CameraFrame::TYPE).unwrap().to_xml)(&msg).unwrap().unwrap();
        assert!(xml.contains("symbol=\"&lt;") || xml.contains("bytes"), "{xml}");
    }

    #[test]
    fn every_type_has_its_xml_form_and_no_other_types() {
        let header = |ty| mrt_dcdt::MsgHeader {
            msg_type: ty,
            member_id: mrt_core::MemberId(1),
            agora_id: mrt_core::AgoraId(2),
            priority: 0,
            warranty: DeliveryWarranty::None,
            creation_time: mrt_core::Time(1_500_000_000),
        };
        let snapshot = Msg::new(header(WorldSnapshot::TYPE), WorldSnapshot::default());
        for e in CATALOGUE {
            let xml = (e.to_xml)(&snapshot);
            assert_eq!(xml.is_some(), e.ty == WorldSnapshot::TYPE, "{}", e.name);
        }
        let xml = (entry(WorldSnapshot::TYPE).unwrap().to_xml)(&snapshot).unwrap().unwrap();
        let back = SelfDescribing::from_xml(&xml).unwrap();
        assert_eq!(back.timestamp, mrt_core::Time(1_500_000_000));
        assert_eq!(back.objects[0].name, "WorldSnapshot");
    }
}
