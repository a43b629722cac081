//! `chassis ros2 ARGS…`: the front door to the ROS 2 node. The node is its own program,
//! `chassis-ros2` (crate `chassis-ros2`), so that this tool stays light: it is looked for next
//! to this program's own executable, then on `PATH`, and run with every argument as given; its
//! exit status is this command's. On Unix the node replaces this process (`exec`), so the
//! signals a service manager sends reach it directly and it stops the chassis itself.

use std::ffi::{OsStr, OsString};
use std::path::PathBuf;
use std::process::Command;

/// The node's program name.
const NODE: &str = "chassis-ros2";

/// The exit status when the node is not installed (a shell's "command not found").
pub const NOT_INSTALLED: u8 = 127;

/// The node's file name on this OS.
fn file_name() -> OsString {
    let mut name = OsString::from(NODE);
    name.push(std::env::consts::EXE_SUFFIX);
    name
}

/// Where the node is: next to this executable, else the first on `PATH`.
fn find() -> Option<PathBuf> {
    let name = file_name();
    let beside = std::env::current_exe()
        .ok()
        .and_then(|exe| exe.parent().map(|dir| dir.join(&name)))
        .filter(|path| path.is_file());
    beside.or_else(|| {
        std::env::split_paths(&std::env::var_os("PATH")?)
            .map(|dir| dir.join(&name))
            .find(|path| path.is_file())
    })
}

/// Runs the node with `args`: its exit status, or why it could not be run (with the status).
pub fn run<S: AsRef<OsStr>>(args: &[S]) -> Result<u8, (String, u8)> {
    let Some(node) = find() else {
        return Err((
            format!(
                "ros2: the ROS 2 node `{NODE}` is not installed (looked next to this program and on PATH): install it with `cargo install --path ros2` from the project's sources, or put it next to `chassis`"
            ),
            NOT_INSTALLED,
        ));
    };
    let mut command = Command::new(&node);
    command.args(args);
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt as _;
        // Only returns if the node could not be started.
        let e = command.exec();
        Err((format!("ros2: cannot run {}: {e}", node.display()), 126))
    }
    #[cfg(not(unix))]
    {
        let status = command
            .status()
            .map_err(|e| (format!("ros2: cannot run {}: {e}", node.display()), 126))?;
        Ok(status
            .code()
            .and_then(|c| u8::try_from(c).ok())
            .unwrap_or(1))
    }
}
