//! `mrt behave push FILE --robot ID --net CONFIG`: an edited behavior sent to a running robot
//! (ThinkingCap/TeamChaos report §3.2: the HBM editor checked a behavior for syntax errors and "if the edited
//! behavior contains no syntax errors, it can be sent to the robot at any time, without the
//! need of stopping or rebooting it").
//!
//! The file is compiled here first, so a syntax error is told with this file's path and line
//! and nothing is sent. Then an Agora of this process joins the robots' network (as `mrt
//! topic` does), waits until robot ID's behavior Member is heard subscribing to pushes, sends
//! a [`BehaviorPush`] and waits for the robot's [`BehaviorPushReply`]
//! (`mrt_script::push` is the robot's side).

use anyhow::{bail, Context as _, Result};
use mrt_msgs::{BehaviorPush, BehaviorPushReply};
use mrt_script::push::{bad_name, MAX_PUSH_BYTES};
use std::path::{Path, PathBuf};

/// `mrt behave push`.
#[derive(clap::Args)]
pub struct PushArgs {
    /// The edited behavior file (`*.lua`, an HFSM `*.hfsm.lua`, or `hbm.lua`).
    pub file: PathBuf,
    /// The robot's Agora id (robot k of a distributed match is Agora k + 1; `mrt topic
    /// list` names them).
    #[arg(long)]
    pub robot: u32,
    /// The DCDT Agora configuration file (MRT manual §3.3.1) of the robots' network: `mrt
    /// sim --distributed` prints the one of its match.
    #[arg(long, value_name = "CONFIG")]
    pub net: PathBuf,
    /// The name the file gets in the robot's behavior directory (default: FILE's name).
    #[arg(long = "as", value_name = "NAME")]
    pub name: Option<String>,
    /// This Agora's id on the network (it must differ from every robot's).
    #[arg(long, default_value_t = 901)]
    pub id: u32,
    /// How long to wait for the robot to be found and to answer, s.
    #[arg(long, default_value_t = 10.0)]
    pub timeout: f64,
    /// Print the robot's answer as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Reads and checks the file as the robot will: its name, its size, its syntax. Returns the
/// push to send.
fn prepare(args: &PushArgs) -> Result<BehaviorPush> {
    let name = match &args.name {
        Some(n) => n.clone(),
        None => args
            .file
            .file_name()
            .and_then(|n| n.to_str())
            .map(str::to_string)
            .with_context(|| format!("{}: no file name", args.file.display()))?,
    };
    if let Some(why) = bad_name(&name) {
        bail!("{name:?} cannot be pushed: {why} (name it with --as)");
    }
    let size = std::fs::metadata(&args.file)
        .with_context(|| format!("cannot read {}", args.file.display()))?
        .len();
    if size > MAX_PUSH_BYTES as u64 {
        bail!(
            "{}: {size} bytes, more than the {MAX_PUSH_BYTES} a robot takes",
            args.file.display()
        );
    }
    let source = mrt_core::read_text(&args.file, mrt_core::MAX_SCRIPT_BYTES)
        .with_context(|| format!("cannot read {}", args.file.display()))?;
    // The editor's check: a file that does not compile is not sent.
    let shown = args.file.display().to_string();
    if let Err(e) = mrt_script::compile_source(&shown, source.clone()) {
        bail!("{e} (not sent)");
    }
    let request = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
        ^ (u64::from(std::process::id()) << 40);
    Ok(BehaviorPush { robot: args.robot, request, file: name, source })
}

/// Runs `mrt behave push`: exit status 0 when the robot runs the new version, 1 when it kept
/// the old one (its error printed) or could not be reached.
pub fn push(args: &PushArgs) -> Result<()> {
    if !(args.timeout.is_finite() && args.timeout > 0.0 && args.timeout <= 3600.0) {
        bail!("--timeout must be more than 0 and at most 3600 s, not {}", args.timeout);
    }
    let push = prepare(args)?;
    let reply = send(&args.net, args.id, &push, std::time::Duration::from_secs_f64(args.timeout))?;
    if args.json {
        outln!("{}", serde_json::to_string(&reply)?);
    }
    match (&reply.installed, &reply.error) {
        (true, _) => {
            if !args.json {
                // The reply comes over the network: its names are escaped.
                outln!(
                    "robot {}: {} installed (swapped in: {})",
                    reply.robot,
                    mrt_core::printable(&reply.file),
                    mrt_core::printable(&reply.reloaded.join(", "))
                );
            }
            Ok(())
        }
        (false, error) => bail!(
            "robot {} kept its running version: {}",
            reply.robot,
            error.as_deref().unwrap_or("refused")
        ),
    }
}

#[cfg(not(feature = "net"))]
fn send(_: &Path, _: u32, _: &BehaviorPush, _: std::time::Duration) -> Result<BehaviorPushReply> {
    bail!("this mrt was built without networking (feature `net`): it cannot reach a robot")
}

/// Joins the network of `net` as Agora `id`, sends `push` once robot `push.robot` listens for
/// pushes, and waits for its reply.
#[cfg(feature = "net")]
fn send(
    net: &Path,
    id: u32,
    push: &BehaviorPush,
    timeout: std::time::Duration,
) -> Result<BehaviorPushReply> {
    use mrt_dcdt::{AgoraId, DeliveryWarranty, Message, RequestType};
    use std::time::{Duration, Instant};
    let end = Instant::now() + timeout;
    let mut agora = mrt_dcdt::Agora::from_config(net, id)
        .map_err(|e| anyhow::anyhow!("{}: {e}", net.display()))?;
    let mut ep = agora.endpoint();
    ep.subscribe_to::<BehaviorPushReply>(RequestType::Remote);
    let link = mrt_net::connect(&agora).map_err(|e| anyhow::anyhow!("{}: {e}", net.display()))?;
    let robot = AgoraId(push.robot);
    if !link.wait_until(timeout, |l| l.subscribers(BehaviorPush::TYPE).contains(&robot)) {
        bail!(
            "robot {}: no behavior Member of that Agora listens for pushes after {:.1} s (Agoras \
             on the network: {:?}; a robot running Lua behaviors does)",
            push.robot,
            timeout.as_secs_f64(),
            link.agoras().iter().map(|a| a.0).collect::<Vec<_>>()
        );
    }
    // The robot hears this Agora's wish for replies with its own discovery: give it a moment.
    std::thread::sleep(Duration::from_millis(200));
    ep.publish_with(push.clone(), DeliveryWarranty::Reliable, 0);
    loop {
        while let Some(m) = ep.receive_msg() {
            if let Ok(r) = m.get::<BehaviorPushReply>() {
                if r.request == push.request && r.robot == push.robot {
                    return Ok(r.clone());
                }
            }
        }
        let left = end.saturating_duration_since(Instant::now());
        if left.is_zero() {
            bail!(
                "robot {}: no answer within {:.1} s (is it running? its log says more)",
                push.robot,
                timeout.as_secs_f64()
            );
        }
        ep.wait_msg(left.min(Duration::from_millis(100)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(file: &Path) -> PushArgs {
        PushArgs {
            file: file.to_path_buf(),
            robot: 3,
            net: PathBuf::from("net.cfg"),
            name: None,
            id: 901,
            timeout: 1.0,
            json: false,
        }
    }

    #[test]
    fn a_file_with_a_syntax_error_is_not_sent_and_its_line_is_told() {
        let dir = std::env::temp_dir().join(format!("mrt-push-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bad = dir.join("attacker.lua");
        std::fs::write(&bad, "-- one\nfunction go(\n").unwrap();
        let e = prepare(&args(&bad)).unwrap_err().to_string();
        assert!(e.contains("attacker.lua:3:") && e.contains("not sent"), "{e}");
        let good = dir.join("keeper.lua");
        std::fs::write(&good, "x = 1\n").unwrap();
        let p = prepare(&args(&good)).unwrap();
        assert_eq!((p.robot, p.file.as_str(), p.source.as_str()), (3, "keeper.lua", "x = 1\n"));
        let mut renamed = args(&good);
        renamed.name = Some("../escape.lua".into());
        assert!(prepare(&renamed).unwrap_err().to_string().contains("cannot be pushed"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
