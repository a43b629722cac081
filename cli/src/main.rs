//! `chassis`: the command-line tool for the chassis motor-controller board. Decode captures,
//! encode frames, talk to a board over a serial port, serve a simulated one. Every bad input
//! (a missing port, a file that is not there, odd hex, a value out of range, a silent board)
//! is one line on stderr and a non-zero exit.

#[macro_use]
extern crate chassis_cli;

mod check;
mod decode;
mod detect;
mod driving;
mod encode;
mod generation;
mod input;
mod monitor;
mod names;
mod record;
mod ros2;
mod sim;
mod v1;
mod v2020;
mod value;

use chassis_cli::{connect, ending, newfile, port, stopping};

use chassis_protocol::detect::Firmware;
use clap::{Parser, Subcommand};
use std::io::Write;
use std::process::ExitCode;

/// The chassis motor-controller board's command-line tool.
#[derive(Debug, Parser)]
#[command(name = "chassis", version, about)]
struct Cli {
    /// The board's serial port (115 200 8N1), for the commands that talk to a board.
    #[arg(long, global = true, value_name = "PATH")]
    port: Option<String>,
    /// Record both directions of the command's traffic into FILE, time-stamped (read it back
    /// with `chassis decode FILE --input saleae-csv --quiet-ms 40 --master-analyzer master`).
    #[arg(long, global = true, value_name = "FILE")]
    record: Option<String>,
    /// The board's firmware: 2020 (FF FE frames) or v1.0.0 (7B … 7D frames; also v1). Without
    /// it, each command finds out from what the board sends (`chassis detect` says which);
    /// `chassis sim` serves a 2020 board.
    #[arg(long, global = true, value_name = "VERSION", value_parser = connect::firmware_arg)]
    firmware: Option<chassis_protocol::detect::Firmware>,
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Debug, Subcommand)]
enum Cmd {
    /// Decode a capture: one JSON object per frame per line, a summary on stderr.
    Decode(decode::DecodeArgs),
    /// Print a master → board frame's bytes as hex.
    Encode {
        #[command(subcommand)]
        frame: encode::Frame,
    },
    /// Say which firmware the board runs (2020 or v1.0.0), from what it sends: listens first,
    /// then, on a quiet line, sends a register read of each firmware (nothing else). Exit status
    /// 0, 3 when nothing came, 4 when bytes of neither firmware came.
    Detect,
    /// Read a register (2020: each read verified, two replies must agree; v1.0.0: a readback,
    /// system / geometry / body-velocity / motor-speeds / pid, or one of their fields).
    Get {
        /// The register (2020: max-speed, kp, ki, gyro-gain, system-mode, gyro-calibration,
        /// motor-voltage, battery-range, pending-angle).
        register: String,
    },
    /// Write a register and read it back (battery-range: FULL CUTOFF, 0.01 V each; v1.0.0: a
    /// settings field, e.g. wheel-diameter, written with the rest of its frame as read).
    Set(generation::SetArgs),
    /// Every register as JSON; or save them to a file, or restore them from one.
    Settings {
        /// Write the settings to FILE.
        #[arg(long, value_name = "FILE", conflicts_with = "restore")]
        save: Option<String>,
        /// Write the settings in FILE to the board (never starts a gyro calibration).
        #[arg(long, value_name = "FILE")]
        restore: Option<String>,
    },
    /// Store the current settings in the board's flash.
    Save,
    /// Calibrate the gyro again (30 s: put the chassis down, then keep it still).
    CalibrateGyro,
    /// Stop the chassis, and cancel a turn the board still has pending.
    Stop,
    /// Drive at a velocity for a while, then stop (Ctrl-C stops at once). 2020: --x --y --z
    /// (the board's raw units); v1.0.0: --vx --vy (m/s) --wz (rad/s).
    Drive(generation::DriveArgs),
    /// Turn by DEGREES (sent once: the board adds turns up) and wait until it is done (Ctrl-C
    /// cancels the turn).
    Turn {
        /// Degrees, positive or negative.
        #[arg(allow_hyphen_values = true)]
        degrees: f64,
    },
    /// A live view of the telemetry; with --drive, keys drive the chassis.
    Monitor {
        /// Drive with the keys (arrows / WASD, space stops; 2020: t turns 90° once; v1.0.0:
        /// z / x rotate at 0.5 rad/s).
        #[arg(long)]
        drive: bool,
        /// The speed the keys drive at: on the 2020 firmware in the board's raw units
        /// (1..=65535), on v1.0.0 in mm/s (300 = 0.3 m/s; 1..=2000).
        #[arg(long, default_value = "300")]
        speed: String,
    },
    /// Check a board end to end: the firmware's bring-up from this PC (link and rates, every
    /// register, drive type, forward, sideways, a 90° turn, stop, battery, a control loop; on
    /// v1.0.0: the velocity followed, a rotation at a rate, the forced stop, settings only read).
    /// Exit status 0 when every check passes, else the failed check's code (10..=18).
    Check(generation::CheckArgs),
    /// Capture what the board sends, time-stamped, into a file `chassis decode --input
    /// saleae-csv --quiet-ms 40` reads back (sends nothing; Ctrl-C ends it, the file complete).
    Record {
        /// The capture file to write.
        #[arg(long, value_name = "FILE")]
        out: String,
        /// Stop after SECONDS (default: until Ctrl-C).
        #[arg(long = "for", value_name = "SECONDS", allow_hyphen_values = true)]
        seconds: Option<f64>,
    },
    /// Run the ROS 2 node (`chassis-ros2`, installed beside this tool or on PATH) with these
    /// arguments: `chassis ros2 --port PATH [--firmware 2020|v1.0.0] [--params FILE.yaml]
    /// [--stamped] [--no-tf] …` (`chassis ros2 --help` lists them). Its exit status is this
    /// command's.
    #[command(disable_help_flag = true)]
    Ros2 {
        /// The node's arguments, passed as given.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<std::ffi::OsString>,
    },
    /// Serve a simulated board (prints where).
    Sim {
        /// On a new pseudo-terminal (prints its path).
        #[arg(long, conflicts_with = "tcp")]
        pty: bool,
        /// On a TCP address, e.g. 127.0.0.1:7878 (what the QEMU firmware connects to).
        #[arg(long, value_name = "ADDR")]
        tcp: Option<String>,
        /// Line errors per byte, a third each dropped, changed and added (e.g. 1e-3).
        #[arg(long, value_name = "RATE", default_value = "0")]
        faults: f64,
        /// Seed of the board's noise and faults.
        #[arg(long, default_value = "1")]
        seed: u64,
        /// Write the board's true pose to FILE every 10 ms of board time, one line
        /// `t_ms x_m y_m yaw_rad` (x forward, y left, yaw counter-clockwise, since power-up;
        /// with --tcp, each client's board starts the file afresh).
        #[arg(long, value_name = "FILE")]
        pose: Option<std::path::PathBuf>,
    },
}

impl Cmd {
    /// The generation a silent line is taken as: the one the command's own arguments belong to
    /// (`drive --vy`, `get geometry`: v1.0.0), so that its error says that nothing answered
    /// rather than that the arguments are the other firmware's.
    fn belongs_to(&self) -> Firmware {
        let v1 = match self {
            Cmd::Drive(drive) => drive.si(),
            Cmd::Get { register } | Cmd::Set(generation::SetArgs { register, .. }) => {
                connect::only_v1_name(register)
            }
            _ => false,
        };
        if v1 {
            Firmware::V1_0_0
        } else {
            connect::DEFAULT_FIRMWARE
        }
    }

    /// What the command is, for the ways it can end early.
    const fn kind(&self) -> ending::Kind {
        match self {
            Cmd::Decode { .. } | Cmd::Encode { .. } | Cmd::Sim { .. } | Cmd::Ros2 { .. } => {
                ending::Kind::NoBoard
            }
            Cmd::Drive { .. }
            | Cmd::Turn { .. }
            | Cmd::Monitor { .. }
            | Cmd::Check { .. }
            | Cmd::Record { .. }
            | Cmd::CalibrateGyro => ending::Kind::Lasting,
            Cmd::Detect
            | Cmd::Get { .. }
            | Cmd::Set { .. }
            | Cmd::Settings { .. }
            | Cmd::Save
            | Cmd::Stop => ending::Kind::Brief,
        }
    }
}

fn main() -> ExitCode {
    // First: a signal at any moment from here on has its documented effect.
    ending::catch_from_start();
    // `chassis ros2 …`: every argument after `ros2` is the node's, its own `--port` included.
    let mut argv = std::env::args_os().skip(1);
    if argv.next().is_some_and(|first| first == "ros2") {
        let args: Vec<std::ffi::OsString> = argv.collect();
        return node_exit(ros2::run(&args));
    }
    let cli = Cli::parse();
    ending::for_command(cli.command.kind());
    let result = options(&cli).and_then(|()| run(&cli));
    // A `--record` file never attached to a port is thrown away (what was there stays); one
    // that could not be written fails the command.
    port::discard_unused_recording();
    let result = match (result, port::record_error()) {
        (Ok(()), Some(e)) => Err((e, 1)),
        (Err((message, code)), Some(e)) => Err((format!("{message}; {e}"), code)),
        (result, None) => result,
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err((message, code)) if message.is_empty() => ExitCode::from(code),
        Err((message, code)) => {
            last_words(format!("chassis: {message}\n"));
            ExitCode::from(code)
        }
    }
}

/// The exit of `chassis ros2`: the node's status, or why it did not run.
fn node_exit(result: Result<u8, (String, u8)>) -> ExitCode {
    match result {
        Ok(code) => ExitCode::from(code),
        Err((message, code)) => {
            last_words(format!("chassis: {message}\n"));
            ExitCode::from(code)
        }
    }
}

/// Runs the command: `Err` with the message and the exit status. A command cut short by an
/// ending (a signal, its terminal or input gone) exits with the ending's status.
fn run(cli: &Cli) -> Result<(), (String, u8)> {
    let failed = |e: String| (e, ending::ended().map_or(1, ending::Ending::exit_status));
    let path = || port(cli.port.as_deref()).map_err(|e| (e, 1));
    match &cli.command {
        Cmd::Decode(args) => decode::run(args, cli.firmware).map_err(failed),
        Cmd::Encode { frame } => {
            say!("{}", encode::hex(&encode::encode(frame).map_err(failed)?));
            Ok(())
        }
        Cmd::Sim {
            pty,
            tcp,
            faults,
            seed,
            pose,
        } => sim::run(
            *pty,
            tcp.as_deref(),
            cli.firmware,
            *faults,
            *seed,
            pose.as_deref(),
        )
        .map_err(failed),
        Cmd::Ros2 { args } => {
            // `chassis --port P --firmware F ros2 …`: the global options go to the node too.
            let mut all: Vec<std::ffi::OsString> = Vec::new();
            if let Some(port) = &cli.port {
                all.extend(["--port".into(), port.into()]);
            }
            if let Some(firmware) = cli.firmware {
                all.extend(["--firmware".into(), firmware.name().into()]);
            }
            all.extend(args.iter().cloned());
            match ros2::run(&all)? {
                0 => Ok(()),
                code => Err((String::new(), code)),
            }
        }
        Cmd::Record { out, seconds } => record::record(path()?, out, *seconds).map_err(failed),
        Cmd::Detect => detect::detect_command(path()?),
        Cmd::Check(check) => {
            let path = path()?;
            let firmware = connect::generation_for_check(path, cli.firmware)?;
            generation::of(firmware).check(path, check)
        }
        command => {
            let path = path()?;
            let firmware =
                connect::generation_or(path, cli.firmware, command.belongs_to()).map_err(failed)?;
            on_board(generation::of(firmware), path, command).map_err(failed)
        }
    }
}

/// A command that talks to a board, by the generation it runs.
fn on_board(board: &dyn generation::Generation, path: &str, command: &Cmd) -> Result<(), String> {
    match command {
        Cmd::Get { register } => board.get(path, register),
        Cmd::Set(set) => board.set(path, set),
        Cmd::Settings { save, restore } => {
            board.settings(path, save.as_deref(), restore.as_deref())
        }
        Cmd::Save => board.save(path),
        Cmd::CalibrateGyro => board.calibrate_gyro(path),
        Cmd::Stop => board.stop(path),
        Cmd::Drive(drive) => board.drive(path, drive),
        Cmd::Turn { degrees } => board.turn(path, *degrees),
        Cmd::Monitor { drive, speed } => board.monitor(path, *drive, speed),
        _ => Err("this command talks to no board".into()),
    }
}

/// Writes `line` on stderr, waiting at most half a second: a terminal that takes no output (a
/// stalled ssh link) does not keep a command that has stopped the chassis from ending.
fn last_words(line: String) {
    let (done, wait) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut err = std::io::stderr();
        let _ = err.write_all(line.as_bytes());
        let _ = err.flush();
        let _ = done.send(());
    });
    let _ = wait.recv_timeout(std::time::Duration::from_millis(500));
}

/// The global options that only some commands take: refused where they mean nothing, and
/// `--record` armed.
fn options(cli: &Cli) -> Result<(), (String, u8)> {
    let (name, talks) = match cli.command {
        Cmd::Decode { .. } => ("decode", false),
        Cmd::Encode { .. } => ("encode", false),
        Cmd::Sim { .. } => ("sim", false),
        Cmd::Ros2 { .. } if cli.record.is_some() => {
            return Err((
                "ros2: --record is not for the ROS 2 node (it talks to the board itself)".into(),
                2,
            ));
        }
        Cmd::Ros2 { .. } => ("ros2", true),
        Cmd::Record { .. } => ("record", true),
        _ => ("", true),
    };
    if !talks && cli.port.is_some() {
        return Err((
            format!("{name} talks to no board: --port is for the commands that do"),
            2,
        ));
    }
    if let Some(file) = &cli.record {
        if !talks {
            return Err((
                format!("{name} talks to no board: --record FILE is for the commands that do"),
                2,
            ));
        }
        if name == "record" {
            return Err((
                "record: give the file with --out FILE (--record is for the other commands)".into(),
                2,
            ));
        }
        port::record_to(file).map_err(|e| (e, 1))?;
    }
    Ok(())
}

fn port(cli_port: Option<&str>) -> Result<&str, String> {
    cli_port.ok_or_else(|| "this command talks to a board: give its serial port with --port PATH (or try `chassis sim --pty`)".to_string())
}
