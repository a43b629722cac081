//! `chassis-ros2`: the ROS 2 node for the chassis board (`chassis-ros2 --help`).

use chassis_cli::ending;
use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    // First: a signal at any moment from here on stops the chassis once it moves.
    ending::catch_from_start();
    let args = chassis_ros2::app::Args::parse();
    ending::for_command(ending::Kind::Brief);
    match chassis_ros2::app::run(&args) {
        Ok(code) => ExitCode::from(code),
        Err((message, code)) => {
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr(), "chassis-ros2: {message}");
            ExitCode::from(code)
        }
    }
}
