//! A configuration held in memory ([`BrianSources`]) loads and runs exactly as the directory it
//! was read from, and refuses what a directory refuses (rule files outside it, missing files).
#![allow(clippy::unwrap_used)]

use mrt_fuzzy::brian::{Brian, BrianSources};
use mrt_fuzzy::BrianError;
use std::path::Path;

fn shipped(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/brian").join(name)
}

#[test]
fn shipped_configurations_run_the_same_from_memory() {
    let cycles: [&[(&str, f64, f64)]; 3] = [
        &[("TargetDistance", 45.0, 1.0), ("TargetAngle", 10.0, 1.0)],
        &[("TargetDistance", 300.0, 0.8), ("ObstacleDistance", 20.0, 1.0)],
        &[("BallDistance", 500.0, 1.0), ("BallAngle", 30.0, 1.0)],
    ];
    for name in ["harvester", "milan"] {
        let mut disk = Brian::from_dir(shipped(name)).unwrap();
        let sources = BrianSources::read_dir(shipped(name)).unwrap();
        assert!(sources.get("behavior.txt").is_some());
        let mut memory = Brian::from_sources(&sources).unwrap();
        assert_eq!(disk.warnings().len(), memory.warnings().len(), "{name}");
        for inputs in cycles {
            assert_eq!(disk.run(inputs).to_map(), memory.run(inputs).to_map(), "{name}");
        }
    }
}

fn harvester_with_list(list: &str) -> Result<Brian, BrianError> {
    let mut sources = BrianSources::read_dir(shipped("harvester")).unwrap();
    sources.insert("behavior.txt", list);
    Brian::from_sources(&sources)
}

#[test]
fn rule_paths_are_taken_lexically_and_stay_inside() {
    let ok = harvester_with_list(
        "(level 1 GoToTarget ./behaviors/../behaviors/GoToTarget.rul)\n\
         (level 1 GoToHome behaviors//GoToHome.rul)\n\
         (level 2 AvoidObstacle behaviors/AvoidObstacle.rul)",
    );
    assert!(ok.is_ok(), "{ok:?}");
    for outside in ["../harvester/behaviors/GoToHome.rul", "/etc/passwd", "behaviors/../../x.rul"] {
        let e = harvester_with_list(&format!("(level 1 GoToHome {outside})")).unwrap_err();
        assert!(e.to_string().contains("outside the configuration directory"), "{outside}: {e}");
    }
    let e = harvester_with_list("(level 1 GoToHome behaviors/Nowhere.rul)").unwrap_err();
    assert!(e.to_string().contains("cannot open the rule file"), "{e}");
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let mut sources = BrianSources::read_dir(shipped("milan")).unwrap();
    sources.remove("want.txt");
    let e = Brian::from_sources(&sources).unwrap_err();
    assert!(matches!(&e, BrianError::Io { file, .. } if file == Path::new("want.txt")), "{e}");
    // PredicateActions.ini is optional, as in a directory.
    let mut sources = BrianSources::read_dir(shipped("harvester")).unwrap();
    sources.remove("PredicateActions.ini");
    let e = Brian::from_sources(&sources).unwrap_err();
    assert!(!matches!(e, BrianError::Io { .. }), "{e}");
}

#[test]
fn invalid_utf8_is_located_as_on_disk() {
    let mut sources = BrianSources::read_dir(shipped("harvester")).unwrap();
    sources.insert("ctof.txt", b"(TargetDistance Distance)\n(Bad\xff Angle)".to_vec());
    let e = Brian::from_sources(&sources).unwrap_err().to_string();
    assert!(e.contains("ctof.txt") && e.contains("line 2"), "{e}");
}
