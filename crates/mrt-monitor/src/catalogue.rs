//! The message types a [`Tap`](crate::Tap) records: every type of `mrt-msgs`' catalogue, with
//! its bus id, its name, its JSON schema and how a bus message of it becomes JSON.

use mrt_core::{Message, MsgType};
use mrt_dcdt::Msg;
use mrt_msgs::{
    BehaviorStatus, CameraFrame, DeviceAct, DeviceFrame, FinalWhistle, GameInfo, Localization,
    MateReport, MotorCommand, Odometry, Percepts, PlanRequest, PlannedPath, ReloadRequest,
    RobotCommand, RobotEnd, SonarScan, WorldSnapshot,
};
use schemars::JsonSchema;
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
}

/// The JSON schema of `T`.
pub fn schema_of<T: JsonSchema>() -> serde_json::Value {
    schemars::schema_for!(T).to_value()
}

fn json_of<T: Message + Serialize>(m: &Msg) -> Encoded {
    m.get::<T>().ok().map(serde_json::to_vec)
}

/// A camera frame without its image: a frame's pixels as JSON numbers would make a match's
/// recording gigabytes (the image schema stays, its value is `null`).
fn camera_frame_json(m: &Msg) -> Encoded {
    let f = m.get::<CameraFrame>().ok()?;
    if f.image.is_none() {
        return Some(serde_json::to_vec(f));
    }
    Some(serde_json::to_vec(&CameraFrame { image: None, ..f.clone() }))
}

macro_rules! catalogue {
    ($($ty:ty $(=> $json:expr)?),* $(,)?) => {
        /// Every catalogue type, in the order of `mrt_msgs`' table.
        pub const CATALOGUE: &[Entry] = &[$(Entry {
            ty: <$ty as Message>::TYPE,
            name: <$ty as Message>::NAME,
            schema: schema_of::<$ty>,
            to_json: catalogue!(@json $ty $(, $json)?),
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
    MateReport,
    SonarScan,
    MotorCommand,
    Odometry,
    CameraFrame => camera_frame_json,
    DeviceFrame,
    DeviceAct,
    FinalWhistle,
    RobotEnd,
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
}
