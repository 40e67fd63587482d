//! HBM behaviors given as text ([`Hbm::from_sources`]) load and run exactly as the directory
//! they come from (the seed's TeamChaos behaviors), and their errors name `<name>.lua`.

#![allow(clippy::unwrap_used)]

use mrt_msgs::robot::{lps, Lpo, WorldSnapshot};
use mrt_script::chaos::{install, RobotIo};
use mrt_script::hbm::{behavior_files, Hbm};
use mrt_script::{LuaRuntime, Sandbox, ScriptError};
use std::cell::RefCell;
use std::path::Path;
use std::rc::Rc;

fn teamchaos() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../behaviors/teamchaos")
}

fn runtime() -> (LuaRuntime, Rc<RefCell<RobotIo>>) {
    let rt = LuaRuntime::new(Sandbox::default()).unwrap();
    let io = Rc::new(RefCell::new(RobotIo::default()));
    install(&rt, io.clone()).unwrap();
    (rt, io)
}

fn world() -> WorldSnapshot {
    let mut w = WorldSnapshot::default();
    w.lps[lps::BALL] = Lpo { rho: 0.9, theta: 0.4, reliability: 0.9, ..Lpo::default() };
    w
}

#[test]
fn the_teamchaos_behaviors_run_the_same_from_text() {
    let dir = teamchaos();
    let files: Vec<(String, String)> = behavior_files(&dir)
        .unwrap()
        .into_iter()
        .map(|(name, path)| (name, std::fs::read_to_string(path).unwrap()))
        .collect();
    let texts: Vec<(&str, &str)> = files.iter().map(|(n, t)| (n.as_str(), t.as_str())).collect();
    let setup = std::fs::read_to_string(dir.join("hbm.lua")).unwrap();

    let (rt_a, io_a) = runtime();
    let from_dir = Hbm::load_dir(&rt_a, &dir, io_a.clone()).unwrap();
    let (rt_b, io_b) = runtime();
    let from_text = Hbm::from_sources(&rt_b, Some(&setup), &texts, io_b.clone()).unwrap();
    assert_eq!(from_dir.names(), from_text.names());
    for name in ["go2ball", "faceball", "goalkeeper"] {
        for (rt, io, hbm) in [(&rt_a, &io_a, &from_dir), (&rt_b, &io_b, &from_text)] {
            io.borrow_mut().new_cycle(world());
            io.borrow_mut().activate(name);
            hbm.run(rt, name).unwrap();
        }
        assert_eq!(io_a.borrow().command, io_b.borrow().command, "{name}");
    }
}

#[test]
fn errors_name_the_behavior_file() {
    let (rt, io) = runtime();
    let e = Hbm::from_sources(&rt, None, &[("broken", "rule(")], io.clone()).err().unwrap();
    assert!(matches!(&e, ScriptError::Syntax { .. } | ScriptError::Runtime { .. }), "{e:?}");
    assert!(e.to_string().contains("broken.lua"), "{e}");
    let (rt, io) = runtime();
    let e = Hbm::from_sources(&rt, Some("error('no')"), &[], io).err().unwrap();
    assert!(e.to_string().contains("hbm.lua"), "{e}");
}
