//! The `mcap` target: recordings (`mrt sim --record`, read back by `mrt replay`).

use super::{Harness, Seed, Target};
use crate::FuzzError;
use mrt_core::Time;
use mrt_monitor::{Recorder, Recording};
use mrt_msgs::{GameInfo, SonarScan, WorldSnapshot};
use std::path::Path;

pub(super) const MCAP: Target = Target {
    name: "mcap",
    about: "MCAP recordings: Recording::topics (mrt replay) and one topic's messages read back as their type",
    keywords: &["\u{89}MCAP0\r\n", "zstd", "json", "jsonschema", "/home/0/WorldSnapshot"],
    structured: None,
    seeds: recording_seeds,
    harness: |_| Ok(Box::new(Recordings)),
};

/// A recording of a few messages of three types on four topics, zstd-compressed like
/// `mrt sim --record`'s.
fn recording_seeds(_: &Path) -> Result<Vec<Seed>, FuzzError> {
    let path = std::env::temp_dir().join(format!("mrt-fuzz-seed-{}.mcap", std::process::id()));
    let io = |source: std::io::Error| FuzzError::Io { path: path.clone(), source };
    let failed = |e: mrt_monitor::RecordError| io(std::io::Error::other(e.to_string()));
    let mut rec = Recorder::create(&path).map_err(failed)?;
    for k in 0..3u64 {
        let t = Time(k * 100_000_000);
        rec.record("/home/0/WorldSnapshot", t, &WorldSnapshot::default()).map_err(failed)?;
        rec.record("/home/0/GameInfo", t, &GameInfo::default()).map_err(failed)?;
        let scan = SonarScan { sonars: vec![mrt_msgs::Sonar::new(0.0, f64::INFINITY)] };
        rec.record("/away/1/SonarScan", t, &scan).map_err(failed)?;
    }
    rec.finish().map_err(failed)?;
    let bytes = std::fs::read(&path).map_err(io)?;
    std::fs::remove_file(&path).map_err(io)?;
    Ok(vec![Seed::new("match.mcap", bytes)])
}

struct Recordings;

impl Harness for Recordings {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        let r = Recording::from_bytes(input.to_vec(), Path::new("fuzz.mcap"));
        let Ok(topics) = r.topics() else { return false };
        let counted: u64 = topics.iter().map(|t| t.count).sum();
        if let Ok(worlds) = r.messages::<WorldSnapshot>("/home/0/WorldSnapshot") {
            assert!(worlds.len() as u64 <= counted, "more messages than the topics counted");
        }
        true
    }
}
