//! `chassis`: the command-line tool for the chassis motor-controller board. Decode captures,
//! encode frames, talk to a board over a serial port, serve a simulated one. Every bad input
//! (a missing port, a file that is not there, odd hex, a value out of range, a silent board)
//! is one line on stderr and a non-zero exit.

/// `println!` that never panics: a closed pipe (`| head`) or a full disk on standard output
/// must not end a command that may be driving the chassis. The command goes on, and its exit
/// status stands.
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}

/// `eprintln!` that never panics (as [`say!`]).
macro_rules! tell {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($t)*);
    }};
}

/// `eprint!` that never panics, flushed (a question before an answer).
macro_rules! tell_partial {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let mut err = std::io::stderr();
        let _ = write!(err, $($t)*);
        let _ = err.flush();
    }};
}

mod check;
mod check_v1;
mod connect;
mod device;
mod encode;
mod ending;
mod input;
mod monitor;
mod names;
mod newfile;
mod port;
mod record;
mod sim;
mod stopping;
mod v1cmd;
mod value;

use chassis_capture as decode;
use chassis_protocol::detect::Firmware;
use clap::{Parser, Subcommand};
use names::RegisterName;
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
    Decode {
        /// The capture file ("-" or nothing: standard input).
        file: Option<String>,
        /// The master → board direction.
        #[arg(long)]
        uplink: bool,
        /// The master → board side of the same capture (both sides time-stamped: --input
        /// saleae-csv). Its reads tell the board side's parser which reply is awaited, as the
        /// driver does; the frames of both sides come out in time order, each with "from".
        #[arg(long, value_name = "FILE", conflicts_with = "uplink")]
        master: Option<String>,
        /// Both sides in one Saleae Logic 2 export: the rows of the analyser named NAME are
        /// the master → board side, the others the board's (as --master FILE).
        #[arg(
            long,
            value_name = "NAME",
            conflicts_with_all = ["uplink", "master"]
        )]
        master_analyzer: Option<String>,
        /// How the capture is written.
        #[arg(long, value_enum, default_value = "raw")]
        input: decode::Input,
        /// How frames are written.
        #[arg(long, value_enum, default_value = "json")]
        format: decode::Format,
        /// A gap in the time stamps longer than MS is a quiet line (a logic analyser's capture:
        /// 2; a `chassis record` capture, stamped when the host read the bytes: 40, as the host
        /// driver judges).
        #[arg(long, value_name = "MS", default_value = "2")]
        quiet_ms: f64,
    },
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
    Set {
        /// The register.
        register: String,
        /// The value (decimal or 0x hex).
        #[arg(allow_hyphen_values = true)]
        value: String,
        /// battery-range only: the cut-off voltage.
        #[arg(allow_hyphen_values = true)]
        cutoff: Option<String>,
        /// Go ahead with a write that starts a 30 s gyro calibration (gyro-calibration 0xFFFF,
        /// system-mode switching bit 3 on).
        #[arg(long)]
        yes: bool,
    },
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
    Drive {
        #[command(flatten)]
        axes: encode::Axes,
        /// v1.0.0: sideways velocity, m/s.
        #[arg(long, value_name = "M/S", allow_hyphen_values = true)]
        vx: Option<f64>,
        /// v1.0.0: forward velocity, m/s.
        #[arg(long, value_name = "M/S", allow_hyphen_values = true)]
        vy: Option<f64>,
        /// v1.0.0: rotation, rad/s (counter-clockwise positive).
        #[arg(long, value_name = "RAD/S", allow_hyphen_values = true)]
        wz: Option<f64>,
        /// How long, in seconds.
        #[arg(long = "for", value_name = "SECONDS", allow_hyphen_values = true)]
        seconds: f64,
    },
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
    Check {
        /// Only what neither moves the chassis nor writes to the board: link, registers,
        /// battery.
        #[arg(long)]
        no_motion: bool,
        /// Do not ask before the chassis moves.
        #[arg(long)]
        yes: bool,
        /// Set this drive type on the board (the board's own is kept if not given; 2020 only).
        #[arg(long, value_enum, value_name = "TYPE", conflicts_with = "no_motion")]
        drive_type: Option<DriveTypeName>,
    },
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
    },
}

/// A drive type, by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum DriveTypeName {
    /// 0: omni wheels.
    Omni,
    /// 1: mecanum wheels.
    Mecanum,
    /// 2: differential, with encoders.
    Differential,
    /// 3: differential, without encoders (duty cycles).
    DifferentialOpenLoop,
}

impl DriveTypeName {
    const fn drive_type(self) -> chassis_protocol::DriveType {
        use chassis_protocol::DriveType;
        match self {
            DriveTypeName::Omni => DriveType::Omni,
            DriveTypeName::Mecanum => DriveType::Mecanum,
            DriveTypeName::Differential => DriveType::Differential,
            DriveTypeName::DifferentialOpenLoop => DriveType::DifferentialOpenLoop,
        }
    }
}

impl Cmd {
    /// What the command is, for the ways it can end early.
    const fn kind(&self) -> ending::Kind {
        match self {
            Cmd::Decode { .. } | Cmd::Encode { .. } | Cmd::Sim { .. } => ending::Kind::NoBoard,
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
    let cli = Cli::parse();
    ending::for_command(cli.command.kind());
    let result = options(&cli).and_then(|()| match cli.command {
        Cmd::Check {
            no_motion,
            yes,
            drive_type,
        } => port(cli.port.as_deref())
            .map_err(|e| (e, 1))
            .and_then(|path| {
                if connect::generation_for_check(path, cli.firmware)? == Firmware::V1_0_0
                {
                    if drive_type.is_some() {
                        return Err((
                            not_on_v1(
                                "check --drive-type",
                                "it has no drive-type register (each velocity frame carries the vendor's type byte): run `chassis check` without it",
                            ),
                            1,
                        ));
                    }
                    return check_v1::check(path, no_motion, yes);
                }
                check::check(
                    path,
                    no_motion,
                    yes,
                    drive_type.map(DriveTypeName::drive_type),
                )
            }),
        Cmd::Detect => port(cli.port.as_deref())
            .map_err(|e| (e, 1))
            .and_then(connect::detect_command),
        // A signal the command caught (and stopped the chassis for): 128 + its number, as a
        // shell reports a process the signal ended.
        _ => run(cli).map_err(|e| (e, ending::ended().map_or(1, ending::Ending::exit_status))),
    });
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
        Err((message, code)) => {
            last_words(format!("chassis: {message}\n"));
            ExitCode::from(code)
        }
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

/// Writes the frames found, one per line, and the summary on stderr.
fn write_decoded(decoded: &decode::Decoded, format: decode::Format) -> Result<(), String> {
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let mut written = Ok(());
    for found in &decoded.frames {
        let line = match format {
            decode::Format::Json => found.json.to_string(),
            decode::Format::Text => found.text.clone(),
        };
        written = writeln!(out, "{line}");
        if written.is_err() {
            break;
        }
    }
    if written.is_ok() {
        written = out.flush();
    }
    match written {
        // A closed pipe (`| head`): the reader has what it wanted.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(format!("standard output: {e}")),
        Ok(()) => {
            tell!("chassis decode: {}", decoded.summary);
            Ok(())
        }
    }
}

/// The bytes of a capture (`None` or "-": standard input), at most [`input::CAPTURE_MAX`].
fn read_input(file: Option<&str>) -> Result<Vec<u8>, String> {
    input::read(file, input::CAPTURE_MAX, "capture")
}

/// A 2020 register by its name on the command line.
fn register_2020(name: &str) -> Result<RegisterName, String> {
    <RegisterName as clap::ValueEnum>::from_str(name, false).map_err(|_| {
        let names: Vec<String> = <RegisterName as clap::ValueEnum>::value_variants()
            .iter()
            .filter_map(|v| clap::ValueEnum::to_possible_value(v).map(|p| p.get_name().to_string()))
            .collect();
        format!(
            "{name:?} is not a register of the 2020 firmware: give one of {}",
            names.join(", ")
        )
    })
}

/// The line for a command that has no meaning on v1.0.0.
/// The generation a register or field name belongs to (a name of neither: 2020, whose error
/// lists the names).
fn names_generation(name: &str) -> Firmware {
    let v1 = chassis_protocol::v1::Readback::from_name(name).is_some()
        || chassis_protocol::v1::FIELDS.iter().any(|(n, _)| *n == name);
    if v1 && chassis_protocol::Register::from_name(name).is_none() {
        Firmware::V1_0_0
    } else {
        Firmware::V2020
    }
}

fn not_on_v1(command: &str, why: &str) -> String {
    format!("{command}: this board runs the v1.0.0 firmware, and {why}")
}

/// A command run from `main` that never reaches `run`.
fn unreachable_in_run(command: &str) -> Result<(), String> {
    Err(format!("{command}: its own exit status"))
}

fn port(cli_port: Option<&str>) -> Result<&str, String> {
    cli_port.ok_or_else(|| "this command talks to a board: give its serial port with --port PATH (or try `chassis sim --pty`)".to_string())
}

fn run(cli: Cli) -> Result<(), String> {
    let p = cli.port.as_deref();
    match cli.command {
        Cmd::Decode {
            file,
            uplink,
            master,
            master_analyzer,
            input,
            format,
            quiet_ms,
        } => {
            if !(quiet_ms > 0.0 && quiet_ms <= 60_000.0) {
                return Err(format!(
                    "--quiet-ms: {quiet_ms} is out of range (above 0, up to 60000)"
                ));
            }
            let quiet = Some(quiet_ms / 1000.0);
            if master.is_some()
                && (master.as_deref() == Some("-") || file.as_deref().is_none_or(|f| f == "-"))
            {
                return Err(
                    "--master: give both sides as files (standard input is one stream)".into(),
                );
            }
            if master_analyzer.is_some() && input != decode::Input::SaleaeCsv {
                return Err(
                    "--master-analyzer reads a Saleae Logic 2 export: give --input saleae-csv"
                        .into(),
                );
            }
            let data = read_input(file.as_deref())?;
            let firmware = cli.firmware;
            if let Some(name) = master_analyzer {
                let (mut board, mut master) = decode::parse_saleae_sides(&data, &name)?;
                board.quiet_s = quiet;
                master.quiet_s = quiet;
                let decoded = decode::decode_both(&board, &master, firmware)?;
                return write_decoded(&decoded, format);
            }
            let mut capture = decode::read_capture(&data, input)?;
            capture.quiet_s = quiet;
            let decoded = match master {
                Some(path) => {
                    let mut master = decode::read_capture(&read_input(Some(&path))?, input)?;
                    master.quiet_s = quiet;
                    decode::decode_both(&capture, &master, firmware)?
                }
                None => decode::decode(&capture, uplink, firmware),
            };
            write_decoded(&decoded, format)
        }
        Cmd::Encode { frame } => {
            say!("{}", encode::hex(&encode::encode(&frame)?));
            Ok(())
        }
        Cmd::Detect => unreachable_in_run("detect"),
        Cmd::Get { register } => {
            let path = port(p)?;
            match connect::generation_or(path, cli.firmware, names_generation(&register))? {
                Firmware::V2020 => device::get(path, register_2020(&register)?),
                Firmware::V1_0_0 => v1cmd::get(path, &register),
            }
        }
        Cmd::Set {
            register,
            value,
            cutoff,
            yes,
        } => {
            let path = port(p)?;
            match connect::generation_or(path, cli.firmware, names_generation(&register))? {
                Firmware::V2020 => device::set(
                    path,
                    register_2020(&register)?,
                    &value,
                    cutoff.as_deref(),
                    yes,
                ),
                Firmware::V1_0_0 if cutoff.is_some() => Err(format!(
                    "set {register}: one value on v1.0.0 (the cut-off is battery-range's, a 2020 register)"
                )),
                Firmware::V1_0_0 => v1cmd::set(path, &register, &value),
            }
        }
        Cmd::Settings { save, restore } => {
            let path = port(p)?;
            match connect::generation(path, cli.firmware)? {
                Firmware::V2020 => device::settings(path, save.as_deref(), restore.as_deref()),
                Firmware::V1_0_0 => v1cmd::settings(path, save.as_deref(), restore.as_deref()),
            }
        }
        Cmd::Save => {
            let path = port(p)?;
            match connect::generation(path, cli.firmware)? {
                Firmware::V2020 => device::save(path),
                Firmware::V1_0_0 => Err(not_on_v1(
                    "save",
                    "v1.0.0 has no frame that stores settings in flash (settings last until power-off: `chassis settings --save FILE` keeps them in a file)",
                )),
            }
        }
        Cmd::CalibrateGyro => {
            let path = port(p)?;
            match connect::generation(path, cli.firmware)? {
                Firmware::V2020 => device::calibrate_gyro(path),
                Firmware::V1_0_0 => Err(not_on_v1(
                    "calibrate-gyro",
                    "v1.0.0 has no gyro calibration frame",
                )),
            }
        }
        Cmd::Stop => {
            let path = port(p)?;
            match connect::generation(path, cli.firmware)? {
                Firmware::V2020 => device::stop(path),
                Firmware::V1_0_0 => v1cmd::stop(path),
            }
        }
        Cmd::Drive {
            axes,
            vx,
            vy,
            wz,
            seconds,
        } => {
            let path = port(p)?;
            let si = vx.is_some() || vy.is_some() || wz.is_some();
            let raw = [&axes.x, &axes.y, &axes.z]
                .iter()
                .any(|v| v.as_str() != "0");
            let silent = if si {
                Firmware::V1_0_0
            } else {
                Firmware::V2020
            };
            match connect::generation_or(path, cli.firmware, silent)? {
                Firmware::V2020 if si => Err(
                    "drive: --vx/--vy/--wz are for the v1.0.0 firmware; this board runs the 2020 one: give --x --y --z (the board's raw units)".into(),
                ),
                Firmware::V2020 => {
                    let (x, y, z) = axes.values()?;
                    device::drive(path, chassis_protocol::Velocity::new(x, y, z), seconds)
                }
                Firmware::V1_0_0 if raw => Err(
                    "drive: --x/--y/--z are the 2020 firmware's raw units; this board runs v1.0.0: give --vx --vy (m/s) --wz (rad/s)".into(),
                ),
                Firmware::V1_0_0 => {
                    let velocity = chassis_protocol::v1::BodyVelocity::new(
                        v1cmd::milli(vx.unwrap_or(0.0), "vx", "m/s")?,
                        v1cmd::milli(vy.unwrap_or(0.0), "vy", "m/s")?,
                        v1cmd::milli(wz.unwrap_or(0.0), "wz", "rad/s")?,
                    );
                    v1cmd::drive(path, velocity, seconds)
                }
            }
        }
        Cmd::Turn { degrees } => {
            let path = port(p)?;
            match connect::generation(path, cli.firmware)? {
                Firmware::V2020 => device::turn(path, degrees),
                Firmware::V1_0_0 => Err(not_on_v1(
                    "turn",
                    "v1.0.0 has no turn by an angle (its protocol has none): `chassis drive --wz RAD/S --for SECONDS` turns at a rate",
                )),
            }
        }
        Cmd::Monitor { drive, speed } => {
            let path = port(p)?;
            match connect::generation(path, cli.firmware)? {
                Firmware::V2020 => {
                    let speed = value::parse_i32(&speed, "speed", 1, 65_535)?;
                    monitor::run(path, drive, speed)
                }
                Firmware::V1_0_0 => {
                    let speed = value::parse_i32(&speed, "speed", 1, 2_000)
                        .map_err(|e| format!("{e}: on v1.0.0 the speed is in mm/s"))?;
                    monitor::v1::run(path, drive, speed)
                }
            }
        }
        // Run from `main`: its exit status is the verdict.
        Cmd::Check { .. } => unreachable_in_run("check"),
        Cmd::Record { out, seconds } => record::record(port(p)?, &out, seconds),
        Cmd::Sim {
            pty,
            tcp,
            faults,
            seed,
        } => {
            let firmware = cli
                .firmware
                .unwrap_or(chassis_protocol::detect::Firmware::V2020);
            let faults = sim::faults(faults)?;
            match (pty, tcp) {
                (true, _) => sim::pty(firmware, seed, faults),
                (false, Some(addr)) => sim::tcp(&addr, firmware, seed, faults),
                (false, None) => Err("sim: give --pty or --tcp ADDR".into()),
            }
        }
    }
}
