//! Ctrl-C, and likewise SIGTERM and SIGHUP. By default it ends the program at once (exit
//! status 130), after removing the compiled-in behaviors' directories that the killed process
//! would otherwise leave behind.
//! A command that must finish what it writes (`mrt record --net`: an MCAP file without its
//! summary and index is only readable by scanning it) asks for [`finish_on_ctrl_c`]: the first
//! Ctrl-C then only raises [`interrupted`], which the command polls, and a second one ends the
//! program as before.

use std::sync::atomic::{AtomicBool, Ordering};

/// Whether the running command finishes its work itself on Ctrl-C.
static FINISHES_ITSELF: AtomicBool = AtomicBool::new(false);
/// Whether Ctrl-C was pressed while the command finishes itself.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Installs the Ctrl-C handler (once, at the start of `main`).
pub fn install() {
    if let Err(e) = ctrlc::set_handler(on_ctrl_c) {
        eprintln!("warning: cannot install the Ctrl-C handler: {e}");
    }
}

fn on_ctrl_c() {
    if FINISHES_ITSELF.load(Ordering::SeqCst) && !INTERRUPTED.swap(true, Ordering::SeqCst) {
        eprintln!("\ninterrupted: finishing (Ctrl-C again to quit at once)");
        return;
    }
    mrt_robot::files::remove_embedded_dirs();
    std::process::exit(130);
}

/// From now on, the first Ctrl-C sets [`interrupted`] instead of ending the program.
pub fn finish_on_ctrl_c() {
    FINISHES_ITSELF.store(true, Ordering::SeqCst);
}

/// Whether Ctrl-C asked the command to finish.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first Ctrl-C of a command that finishes itself only raises the flag (the second
    /// would end the process, which a unit test cannot show: the CLI test
    /// `record_net_finishes_its_file_on_ctrl_c` does).
    #[test]
    fn the_first_ctrl_c_of_a_command_that_finishes_itself_only_raises_the_flag() {
        assert!(!interrupted());
        finish_on_ctrl_c();
        on_ctrl_c();
        assert!(interrupted());
    }
}
