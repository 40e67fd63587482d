//! `mrt`: the MRT command line.
//!
//! - `mrt sim [--seed N] [--matches N] [--plot match.svg] [--distributed]` plays a simulated
//!   match (with `--distributed`, each robot in a process of its own over zenoh);
//! - `mrt bb serve|get|set|watch|list` serves a blackboard with its relay, or talks to one;
//! - `mrt demo [hello-agora|two-agoras]` runs a numbered example and prints what happens;
//! - `mrt behave FILE [--world world.json] [--cycles N]` runs a Lua behavior or HFSM offline;
//!   `mrt behave push FILE --robot ID --net CONFIG` sends an edited one to a running robot;
//! - `mrt hfsm dot FILE [--dot out.dot] [--svg out.svg]` draws an HFSM;
//! - `mrt plan path --from X,Y --to X,Y [--obstacles ...] [--json] [--svg out.svg]` plans a
//!   path with SPIKE;
//! - `mrt soak matches|hour` runs the soak campaigns of `docs/reliability.md`;
//! - `mrt mice calibrate LOG [--json]` calibrates the two-mice odometry (MRT manual §4.2) from
//!   the log of its readings (`docs/mice.md`; `mrt sim --calibrate-mice` on a simulated robot);
//! - `mrt check FILE...` checks DCDT Agora configuration files (MRT manual §3.3.1) and
//!   prints each in canonical form, or the first error with file, line and column.
//!
//! Logging goes through `tracing`; set `RUST_LOG` (e.g. `RUST_LOG=mrt_dcdt=debug`) for more.
#![deny(clippy::print_stdout)]

/// `println!` for results: ends the program quietly when standard output has been closed
/// (`mrt sim | head -3`), where `println!` would panic on the broken pipe.
macro_rules! outln {
    ($($arg:tt)*) => { $crate::write_line(format_args!($($arg)*)) };
}

mod bb;
mod behave;
mod brian;
#[cfg(feature = "net")]
mod distributed;
#[cfg(feature = "net")]
mod edge;
mod interrupt;
mod mice;
#[cfg(feature = "net")]
mod mujoco;
mod plan;
mod push;
mod replay;
mod sim;
mod soak;
#[cfg(feature = "net")]
mod topic;
mod vision;
#[cfg(feature = "net")]
mod world;

use anyhow::{Context as _, Result};
use clap::{Parser, Subcommand, ValueEnum};
use mrt_dcdt::config::AgoraConfig;
use std::path::PathBuf;

#[derive(Parser)]
#[command(name = "mrt", version, about = "MRT: Modular Robotic Toolkit")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum PlanCommand {
    /// A path from --from to --to that keeps the robot's radius and a safety distance from
    /// every obstacle: its corners, its length and the time it took (docs/planning.md).
    Path(plan::PathArgs),
}

#[derive(Subcommand)]
enum VisionCommand {
    /// Classify images with a colour file and find the ball through a camera file: one JSON
    /// line per image.
    Detect(vision::DetectArgs),
    /// Save what a simulated camera sees: a robot placed on the simulator's field, the ball
    /// and other robots where you say.
    Render(vision::RenderArgs),
    /// Help tune a colour file: per class, histograms of the hue, saturation and value of the
    /// pixels it takes (JSON), and with --out an SVG of them and an image of what each class
    /// covers.
    Calibrate(vision::CalibrateArgs),
    /// Measure the vision against the simulator's truth: random scenes rendered and seen, the
    /// detection rate and the errors of the ball, the nets, the posts and the other robots.
    Survey(vision::SurveyArgs),
}

#[cfg(feature = "net")]
#[derive(Subcommand)]
enum WorldCommand {
    /// A match (or the empty-goal scenario) in the MuJoCo world: prints the score, the goals
    /// and the world's report (JSON).
    Mujoco(mujoco::MujocoArgs),
}

#[derive(Subcommand)]
enum Command {
    /// Play a simulated robot-soccer match on the embedded default world (or a series).
    Sim(sim::SimArgs),
    /// What a recording (`mrt sim --record`, an MCAP file) holds: its topics, their schemas,
    /// message counts and time spans (docs/monitor.md).
    Replay(replay::ReplayArgs),
    /// Run one robot: its Agora on the devices its robot file names (configs/robot/; `mrt sim
    /// --distributed` starts each of its robots with this command).
    #[cfg(feature = "net")]
    Robot(world::RobotArgs),
    /// Play in a world nobody here wrote: `mrt world mujoco` starts the MuJoCo world
    /// (worlds/mujoco/, Python) and one `mrt robot` per robot on its devices (docs/devices.md).
    #[cfg(feature = "net")]
    World {
        #[command(subcommand)]
        command: WorldCommand,
    },
    /// The messages of robots running anywhere on the network: which types and who publishes
    /// them (`list`), one type as JSON Lines (`echo`), its rate (`hz`); `mrt sim
    /// --distributed` prints its match's network file (docs/monitor.md).
    #[cfg(feature = "net")]
    Topic {
        #[command(subcommand)]
        command: topic::TopicCommand,
    },
    /// Record every bus message of the robots on a network (other processes, other machines)
    /// into an MCAP file, for `mrt replay` and Foxglove (docs/monitor.md).
    #[cfg(feature = "net")]
    Record(topic::RecordArgs),
    /// Serve the web monitor on the robots of a network, live (docs/monitor.md).
    #[cfg(feature = "net")]
    Monitor(topic::MonitorArgs),
    /// The robots' messages for programs in other languages: JSON and the manual's XML
    /// self-describing form on plain zenoh keys, and JSON from them onto the robots' bus
    /// (docs/network.md, "Programs in other languages").
    #[cfg(feature = "net")]
    Edge(edge::EdgeArgs),
    /// Vision tools: find the ball in camera images (`detect`), tune colours (`calibrate`),
    /// save what a simulated camera sees (`render`), measure the vision on it (`survey`).
    Vision {
        #[command(subcommand)]
        command: VisionCommand,
    },
    /// The blackboard: serve one with its relay, or get, set, watch and list variables
    /// through a relay (docs/relay-protocol.md).
    Bb {
        #[command(subcommand)]
        command: bb::BbCommand,
    },
    /// Run a demo: an Agora with Members exchanging messages.
    Demo {
        /// Which example to run.
        #[arg(value_enum, default_value_t = Demo::HelloAgora)]
        which: Demo,
    },
    /// Mr. BRIAN fuzzy behaviors: check, evaluate or draw a configuration directory.
    Brian {
        #[command(subcommand)]
        command: BrianCommand,
    },
    /// Run a Lua behavior or HFSM (`*.hfsm.lua`) against world snapshots and print each
    /// cycle's commands as JSON Lines (behaviors are looked up beside FILE); or send an
    /// edited behavior to a running robot (`mrt behave push FILE --robot ID --net CONFIG`).
    Behave(BehaveArgs),
    /// SPIKE, the path planner (MRT manual ch. 9): plan a path on the soccer field or a map
    /// file.
    Plan {
        #[command(subcommand)]
        command: PlanCommand,
    },
    /// Hierarchical state machines (ThinkingCap HFSM).
    Hfsm {
        #[command(subcommand)]
        command: HfsmCommand,
    },
    /// Check DCDT Agora configuration files.
    Check {
        /// Configuration files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Soak campaigns: many random matches, or one robot for a simulated hour
    /// (docs/reliability.md).
    Soak {
        #[command(subcommand)]
        command: soak::SoakCommand,
    },
    /// The two-mice odometry sensor (MRT manual ch. 4): calibrate it from the log of its
    /// readings (docs/mice.md).
    Mice {
        #[command(subcommand)]
        command: mice::MiceCommand,
    },
}

#[derive(Subcommand)]
enum BrianCommand {
    /// Check every file of a configuration (silent when correct; exit status 1 on an error).
    Check {
        /// The configuration directory.
        dir: PathBuf,
    },
    /// Run cycles read as JSON Lines (`{"Name": value}` or `{"Name": [value, reliability]}`)
    /// and print one JSON object of commands per cycle.
    Eval {
        /// The configuration directory.
        dir: PathBuf,
        /// Input cycles (default: standard input).
        #[arg(long)]
        input: Option<PathBuf>,
        /// Add every predicate, predicate action, CANDO and WANT under `_trace`.
        #[arg(long)]
        trace: bool,
        /// How reliability counts: `manual` (the MRT manual's) or `original` (the original
        /// C++ engine's: CANDO/WANT gated on reliability, rules blind to it). Default: the
        /// configuration's `engine.txt`, else `manual`.
        #[arg(long, value_parser = ["manual", "original"])]
        semantics: Option<String>,
    },
    /// Draw every input and output shape as SVG.
    Plot {
        /// The configuration directory.
        dir: PathBuf,
        /// The SVG file to write.
        #[arg(long, default_value = "shapes.svg")]
        out: PathBuf,
    },
}

#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
struct BehaveArgs {
    #[command(subcommand)]
    command: Option<BehaveCommand>,
    /// The behavior or HFSM file.
    #[arg(required = true)]
    file: Option<PathBuf>,
    /// World snapshots as JSON: one object (used every cycle) or an array (one per cycle).
    /// Without it the world is empty: nothing seen.
    #[arg(long)]
    world: Option<PathBuf>,
    /// Cycles to run, 1 to 1 000 000 000 (default: 1, or the array's length). Cycles
    /// are run as they come: a long run needs no more memory than a short one.
    #[arg(long)]
    cycles: Option<u64>,
    /// Simulated time between cycles, for worlds without a time, 1 to 3 600 000 ms.
    #[arg(long, default_value_t = 100)]
    period_ms: u64,
}

#[derive(Subcommand)]
enum BehaveCommand {
    /// Send an edited behavior file to a running robot (ThinkingCap/TeamChaos report §3.2): checked for syntax
    /// errors here first, then compiled by the robot off its control path and swapped in at
    /// a cycle boundary, or refused with the error and its line while the old version keeps
    /// running (docs/behaviors.md, "Sending a behavior to a running robot").
    Push(push::PushArgs),
}

#[derive(Subcommand)]
enum HfsmCommand {
    /// Write the machine as Graphviz dot (standard output or `--dot`) and draw it as SVG.
    Dot {
        /// The HFSM file.
        file: PathBuf,
        /// Where to write the dot text (default: standard output).
        #[arg(long)]
        dot: Option<PathBuf>,
        /// Where to draw the machine as SVG.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Demo {
    /// 01: a periodic producer and an on-message consumer, on threads, in real time.
    HelloAgora,
    /// 02: two Agoras in one process, Local vs Remote subscriptions, simulated time.
    TwoAgoras,
}

/// Writes one line to standard output; a closed pipe ends the program with status 0 (the
/// reader has what it wanted), any other write error with status 1.
fn write_line(args: std::fmt::Arguments<'_>) {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.write_all(b"\n")) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: cannot write to standard output: {e}");
        std::process::exit(1);
    }
}

/// Blocks until the process is interrupted: Ctrl-C's handler (in `main`) exits it. For
/// commands that serve until stopped (`--serve`).
fn wait_for_ctrl_c() -> ! {
    loop {
        std::thread::park();
    }
}

/// Whether an error comes from writing to a closed pipe.
fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

fn main() -> std::process::ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn,zenoh=error")),
        )
        .with_writer(std::io::stderr)
        // Colour only on a terminal: a log file or a pipe gets plain text.
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
    interrupt::install();
    match run(Cli::parse().command) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) if is_broken_pipe(&e) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // An error may quote its input (a script's message, a file's name or line):
            // escape sequences in it are shown, not obeyed.
            eprintln!("Error: {}", mrt_core::printable(&format!("{e:?}")));
            std::process::ExitCode::FAILURE
        }
    }
}

fn run(command: Command) -> Result<()> {
    match command {
        Command::Demo { which: Demo::HelloAgora } => {
            outln!("MRT demo 01_hello_agora: a Greeter (periodic, 100 ms) and a Listener (on-message)\n");
            mrt_examples::hello_agora::main().context("the hello-agora demo failed")?;
        }
        Command::Demo { which: Demo::TwoAgoras } => {
            mrt_examples::two_agoras::main().context("the two-agoras demo failed")?;
        }
        Command::Brian { command } => match command {
            BrianCommand::Check { dir } => brian::check(&dir)?,
            BrianCommand::Eval { dir, input, trace, semantics } => {
                brian::eval(&dir, input.as_deref(), trace, semantics.as_deref())?
            }
            BrianCommand::Plot { dir, out } => brian::plot(&dir, &out)?,
        },
        Command::Sim(args) => sim::run(&args)?,
        Command::Replay(args) => replay::run(&args)?,
        #[cfg(feature = "net")]
        Command::Topic { command } => topic::run(&command)?,
        #[cfg(feature = "net")]
        Command::Record(args) => topic::record(&args)?,
        #[cfg(feature = "net")]
        Command::Monitor(args) => topic::monitor(&args)?,
        #[cfg(feature = "net")]
        Command::Edge(args) => edge::run(&args)?,
        Command::Soak { command } => soak::run(&command)?,
        Command::Mice { command } => mice::run(&command)?,
        #[cfg(feature = "net")]
        Command::Robot(args) => world::robot(&args)?,
        #[cfg(feature = "net")]
        Command::World { command: WorldCommand::Mujoco(args) } => mujoco::play(&args)?,
        Command::Bb { command } => bb::run(command)?,
        Command::Vision { command: VisionCommand::Detect(args) } => vision::detect(&args)?,
        Command::Vision { command: VisionCommand::Render(args) } => vision::render(&args)?,
        Command::Vision { command: VisionCommand::Calibrate(args) } => vision::calibrate(&args)?,
        Command::Vision { command: VisionCommand::Survey(args) } => vision::survey(&args)?,
        Command::Plan { command: PlanCommand::Path(args) } => plan::path(&args)?,
        Command::Behave(BehaveArgs { command: Some(BehaveCommand::Push(args)), .. }) => {
            push::push(&args)?
        }
        Command::Behave(BehaveArgs { command: None, file, world, cycles, period_ms }) => {
            let file = file.context("mrt behave needs a FILE")?;
            behave::behave(&file, world.as_deref(), cycles, period_ms)?
        }
        Command::Hfsm { command: HfsmCommand::Dot { file, dot, svg } } => {
            behave::hfsm_dot(&file, dot.as_deref(), svg.as_deref())?
        }
        Command::Check { files } => {
            let mut failed = 0;
            for f in &files {
                let checked = AgoraConfig::from_file(f).map_err(anyhow::Error::from);
                match checked.and_then(|cfg| check_network(f, cfg)) {
                    Ok(cfg) => outln!("# {}: ok\n{cfg}", f.display()),
                    Err(e) => {
                        eprintln!("error: {}", mrt_core::printable(&e.to_string()));
                        failed += 1;
                    }
                }
            }
            if failed > 0 {
                anyhow::bail!("{failed} of {} configuration files have errors", files.len());
            }
        }
    }
    Ok(())
}

/// What the network makes of a configuration (serial lines' options, addresses), as an
/// Agora that starts with it would: `mrt check` refuses what the Agora would.
fn check_network(file: &std::path::Path, cfg: AgoraConfig) -> anyhow::Result<AgoraConfig> {
    #[cfg(feature = "net")]
    if let Err(e) = mrt_net::NetConfig::from_agora_config(&cfg) {
        anyhow::bail!("{}: {e}", file.display());
    }
    let _ = file;
    Ok(cfg)
}
