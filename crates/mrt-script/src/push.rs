//! Behaviors sent to a running robot (ThinkingCap/TeamChaos report §3.2: "if the edited behavior contains no
//! syntax errors, it can be sent to the robot at any time, without the need of stopping or
//! rebooting it"; `mrt behave push`).
//!
//! A [`BehaviorPush`] names a file of the robot's behavior directory and carries its new
//! text. The robot checks the name (a bare `*.lua` name: a push never writes outside the
//! directory) and the size, then a thread of its own, **off the control path**, compiles the
//! text and, when it compiles, writes it into the directory (a temporary file renamed over
//! the old one, so a reader never sees half a file). At the next cycle boundary the behavior
//! Member swaps the compiled chunk in ([`Watchdog::install`](crate::Watchdog::install)), as a
//! local hot reload does. Either way the robot answers with a [`BehaviorPushReply`]: what was
//! swapped in, or the error with its line, the running version kept. A file that does not
//! compile is never written, and one the robot refuses at loading (an HFSM naming a state it
//! does not have) is taken back off the disk: the directory keeps holding what runs, so a
//! robot that restarts starts with it.

use crate::error::ScriptError;
use crate::watch::{compile_source, Change};
use mrt_msgs::{BehaviorPush, BehaviorPushReply};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, Receiver, TryRecvError};

/// The largest behavior file a robot takes (1 MiB; the shipped ones are a few KiB).
pub const MAX_PUSH_BYTES: usize = 1 << 20;

/// Pushes compiled at once, at most; more are refused until one is done.
pub const MAX_PENDING: usize = 4;

/// Why a file name cannot be pushed, `None` when it can: a bare name of letters, digits,
/// `_`, `-` and `.`, ending in `.lua`, not starting with a dot, at most 128 bytes.
pub fn bad_name(file: &str) -> Option<&'static str> {
    if file.len() > 128 {
        return Some("the name is longer than 128 bytes");
    }
    if !file.ends_with(".lua") || file.len() == ".lua".len() {
        return Some("a behavior file's name ends in .lua");
    }
    if !file.bytes().all(|b| b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.')) {
        return Some(
            "a bare file name of the behavior directory (letters, digits, _ - .), no directories",
        );
    }
    if file.starts_with('.') {
        return Some("the name starts with a dot");
    }
    None
}

/// What a written push replaced, to put back if the robot refuses it.
enum Previous {
    /// The file did not exist.
    Absent,
    /// The file's former bytes.
    Was(Vec<u8>),
}

/// A compiled file written into the directory, and what it replaced.
struct Written {
    change: Change,
    previous: Previous,
}

/// A push being compiled.
struct Pending {
    request: u64,
    file: String,
    done: Receiver<Result<Written, ScriptError>>,
}

/// A compiled push, ready to be swapped in ([`Pusher::settle`]).
pub struct Ready {
    /// The request.
    pub request: u64,
    /// The file, as the request named it.
    pub file: String,
    written: Result<Written, ScriptError>,
}

/// One robot's pushes: checked, compiled and written off the control path (module docs).
pub struct Pusher {
    robot: u32,
    dir: PathBuf,
    pending: Vec<Pending>,
}

impl Pusher {
    /// The pushes for the robot of Agora `robot`, whose behaviors are in `dir`.
    pub fn new(robot: u32, dir: impl Into<PathBuf>) -> Pusher {
        Pusher { robot, dir: dir.into(), pending: Vec::new() }
    }

    /// Takes a push: `None` when it is for another robot or is being compiled, a reply
    /// (refused) when its name, its size or the number of pushes in flight rule it out.
    pub fn receive(&mut self, push: &BehaviorPush) -> Option<BehaviorPushReply> {
        if push.robot != self.robot {
            return None;
        }
        let refuse = |why: String| Some(refused(self.robot, push.request, &push.file, &why, None));
        if let Some(why) = bad_name(&push.file) {
            return refuse(format!("{:?}: {why}", clipped(&push.file)));
        }
        if push.source.len() > MAX_PUSH_BYTES {
            return refuse(format!(
                "{}: {} bytes, more than the {MAX_PUSH_BYTES} a behavior file may have",
                push.file,
                push.source.len()
            ));
        }
        if self.pending.len() >= MAX_PENDING {
            return refuse(format!(
                "{}: {MAX_PENDING} pushes are being compiled; send it again",
                push.file
            ));
        }
        let (tx, done) = channel();
        let (dir, file, source) = (self.dir.clone(), push.file.clone(), push.source.clone());
        let spawned = std::thread::Builder::new().name(format!("push:{file}")).spawn(move || {
            let _ = tx.send(compile_and_write(&dir, &file, source));
        });
        if let Err(e) = spawned {
            return refuse(format!("{}: cannot start the compiler's thread: {e}", push.file));
        }
        self.pending.push(Pending { request: push.request, file: push.file.clone(), done });
        None
    }

    /// The pushes compiled since the last call, in the order they came.
    pub fn ready(&mut self) -> Vec<Ready> {
        let mut out = Vec::new();
        self.pending.retain(|p| match p.done.try_recv() {
            Ok(written) => {
                out.push(Ready { request: p.request, file: p.file.clone(), written });
                false
            }
            Err(TryRecvError::Empty) => true,
            Err(TryRecvError::Disconnected) => {
                let why = format!("{}: the compiler's thread stopped", p.file);
                out.push(Ready {
                    request: p.request,
                    file: p.file.clone(),
                    written: Err(ScriptError::Setup(why)),
                });
                false
            }
        });
        out
    }

    /// Whether pushes are being compiled.
    pub fn busy(&self) -> bool {
        !self.pending.is_empty()
    }

    /// Swaps a compiled push in with `install` (at a cycle boundary:
    /// [`Watchdog::install`](crate::Watchdog::install)) and gives the reply. A push the robot
    /// refuses is taken back off the disk.
    pub fn settle(
        &self,
        ready: Ready,
        install: impl FnOnce(Change) -> Result<Vec<String>, ScriptError>,
    ) -> BehaviorPushReply {
        let (request, file) = (ready.request, ready.file);
        let outcome = match ready.written {
            Err(e) => Err(e),
            Ok(Written { change, previous }) => {
                let path = change.path.clone();
                let outcome = install(change);
                if outcome.is_err() {
                    let restored = match &previous {
                        Previous::Absent => std::fs::remove_file(&path),
                        Previous::Was(bytes) => write_atomically(&path, bytes),
                    };
                    if let Err(e) = restored {
                        tracing::warn!(
                            "{}: cannot put the refused push's file back: {e}",
                            path.display()
                        );
                    }
                }
                outcome
            }
        };
        match outcome {
            Ok(reloaded) => BehaviorPushReply {
                robot: self.robot,
                request,
                file,
                installed: true,
                reloaded,
                error: None,
                line: None,
            },
            Err(e) => {
                let line = e.line().and_then(|l| u32::try_from(l).ok());
                refused(self.robot, request, &file, &e.to_string(), line)
            }
        }
    }
}

fn refused(
    robot: u32,
    request: u64,
    file: &str,
    why: &str,
    line: Option<u32>,
) -> BehaviorPushReply {
    BehaviorPushReply {
        robot,
        request,
        file: clipped(file),
        installed: false,
        reloaded: Vec::new(),
        error: Some(why.to_string()),
        line,
    }
}

/// A name from the network, cut to a size fit for a reply.
fn clipped(file: &str) -> String {
    file.chars().take(128).collect()
}

/// Compiles `source`, and when it compiles writes it as `dir/file`, remembering what was there.
fn compile_and_write(dir: &Path, file: &str, source: String) -> Result<Written, ScriptError> {
    let compiled = compile_source(file, source)?;
    let path = std::path::absolute(dir.join(file)).unwrap_or_else(|_| dir.join(file));
    let io = |source| ScriptError::Io { file: file.to_string(), source };
    let previous = match mrt_core::read_bounded(&path, mrt_core::MAX_SCRIPT_BYTES) {
        Ok(bytes) => Previous::Was(bytes),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Previous::Absent,
        Err(e) => return Err(io(e)),
    };
    write_atomically(&path, compiled.source().as_bytes()).map_err(io)?;
    let change = Change { path, name: file.to_string(), compiled: Ok(compiled) };
    Ok(Written { change, previous })
}

/// Writes `path` through a temporary file beside it, renamed over it: a reader (the robot's
/// file watcher, a restarting robot) sees the old file or the new one, never half of one.
fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.{}.push", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settled(pusher: &mut Pusher, push: &BehaviorPush, ok: bool) -> BehaviorPushReply {
        assert!(pusher.receive(push).is_none(), "refused at once");
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
        loop {
            if let Some(ready) = pusher.ready().pop() {
                return pusher.settle(ready, |c| match ok {
                    true => Ok(vec![c.name]),
                    false => {
                        Err(ScriptError::Invalid { file: c.name, line: 4, message: "no".into() })
                    }
                });
            }
            assert!(std::time::Instant::now() < deadline, "never compiled");
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    }

    #[test]
    fn a_push_is_written_when_taken_and_taken_back_when_refused() {
        let dir = std::env::temp_dir().join(format!("mrt-pusher-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("old.lua"), "x = 1\n").unwrap();
        let mut pusher = Pusher::new(7, &dir);
        let push = |file: &str, source: &str| BehaviorPush {
            robot: 7,
            request: 1,
            file: file.into(),
            source: source.into(),
        };
        // Another robot's push is not this robot's business.
        assert!(pusher.receive(&BehaviorPush { robot: 8, ..push("old.lua", "x = 2") }).is_none());
        assert!(!pusher.busy());
        // Taken: on disk.
        let r = settled(&mut pusher, &push("old.lua", "x = 2\n"), true);
        assert!(r.installed && r.error.is_none(), "{r:?}");
        assert_eq!(std::fs::read_to_string(dir.join("old.lua")).unwrap(), "x = 2\n");
        // Refused at loading: the file that ran is back; a new file is gone again.
        let r = settled(&mut pusher, &push("old.lua", "x = 3\n"), false);
        assert_eq!((r.installed, r.line), (false, Some(4)));
        assert_eq!(std::fs::read_to_string(dir.join("old.lua")).unwrap(), "x = 2\n");
        settled(&mut pusher, &push("new.lua", "y = 1\n"), false);
        assert!(!dir.join("new.lua").exists());
        // A syntax error: never written, told with its line.
        let r = settled(&mut pusher, &push("old.lua", "x = = 4\n"), true);
        assert!(!r.installed && r.line == Some(1), "{r:?}");
        assert!(r.error.as_deref().is_some_and(|e| e.starts_with("old.lua:1:")), "{r:?}");
        assert_eq!(std::fs::read_to_string(dir.join("old.lua")).unwrap(), "x = 2\n");
        // Names and sizes are refused at once.
        let r = pusher.receive(&push("../x.lua", "")).unwrap();
        assert!(!r.installed && r.error.unwrap().contains("no directories"));
        let big = "-".repeat(MAX_PUSH_BYTES + 1);
        assert!(pusher.receive(&push("big.lua", &big)).unwrap().error.unwrap().contains("bytes"));
        let names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["old.lua"], "stray files");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn only_bare_lua_names_of_the_directory_are_taken() {
        for ok in ["attacker.lua", "player.hfsm.lua", "hbm.lua", "go-2_ball.lua"] {
            assert_eq!(bad_name(ok), None, "{ok}");
        }
        for bad in [
            "",
            ".lua",
            "attacker",
            "../attacker.lua",
            "/etc/passwd.lua",
            "sub/attacker.lua",
            "..\\x.lua",
            ".hidden.lua",
            "a b.lua",
            "é.lua",
            &"a".repeat(130),
        ] {
            assert!(bad_name(bad).is_some(), "{bad:?} taken");
        }
    }
}
