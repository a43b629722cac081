//! The commands on a board running the 2020 firmware (`FF FE` frames), through the host driver:
//! its registers and settings ([`settings`]: get, set, settings, save, calibrate-gyro), its
//! motion ([`motion`]: stop, drive, turn), `check` and `monitor`.
//!
//! Every command that moves the chassis stops it on its way out, whatever ends it: done, an
//! error, a board gone quiet, SIGINT / SIGTERM / SIGHUP, its terminal or input gone
//! ([`crate::ending`]); a turn in progress is cancelled (the angle still pending is read and
//! the opposite turn sent). What it says of the chassis comes from what was sent and what came
//! back ([`crate::stopping`]).

pub mod check;
pub mod monitor;
mod motion;
mod settings;

use crate::generation::{CheckArgs, DriveArgs, Generation, SetArgs};
use crate::names::RegisterName;
use crate::port::{self, Board};
use crate::stopping;
use chassis_protocol::Velocity;
use chassis_protocol::driver::Error;
use chassis_protocol::driver::host::SerialError;

/// Opens the board's serial port with the host defaults.
pub fn open(port: &str) -> Result<Board, String> {
    port::open(port, None)
}

/// A driver error as one line, in the CLI's words. "Is it powered?" only when nothing at all
/// came from the board.
pub fn explain(driver: &Board, e: Error<SerialError>) -> String {
    stopping::explain(driver, e)
}

/// A 2020 register by its name on the command line.
fn register(name: &str) -> Result<RegisterName, String> {
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

/// The 2020 firmware (`FF FE` frames): the commands as it does them.
pub struct V2020;

impl Generation for V2020 {
    fn get(&self, path: &str, name: &str) -> Result<(), String> {
        settings::get(path, register(name)?)
    }

    fn set(&self, path: &str, set_args: &SetArgs) -> Result<(), String> {
        settings::set(
            path,
            register(&set_args.register)?,
            &set_args.value,
            set_args.cutoff.as_deref(),
            set_args.yes,
        )
    }

    fn settings(
        &self,
        path: &str,
        save: Option<&str>,
        restore: Option<&str>,
    ) -> Result<(), String> {
        settings::settings(path, save, restore)
    }

    fn save(&self, path: &str) -> Result<(), String> {
        settings::save(path)
    }

    fn calibrate_gyro(&self, path: &str) -> Result<(), String> {
        settings::calibrate_gyro(path)
    }

    fn stop(&self, path: &str) -> Result<(), String> {
        motion::stop(path)
    }

    fn drive(&self, path: &str, args: &DriveArgs) -> Result<(), String> {
        if args.si() {
            return Err("drive: --vx/--vy/--wz are for the v1.0.0 firmware; this board runs the 2020 one: give --x --y --z (the board's raw units)".into());
        }
        let (x, y, z) = args.axes.values()?;
        motion::drive(path, Velocity::new(x, y, z), args.seconds)
    }

    fn turn(&self, path: &str, degrees: f64) -> Result<(), String> {
        motion::turn(path, degrees)
    }

    fn monitor(&self, path: &str, drive: bool, speed: &str) -> Result<(), String> {
        let speed = crate::value::parse_i32(speed, "speed", 1, 65_535)?;
        monitor::run(path, drive, speed)
    }

    fn check(&self, path: &str, args: &CheckArgs) -> Result<(), (String, u8)> {
        check::check(
            path,
            args.no_motion,
            args.yes,
            args.drive_type
                .map(crate::generation::DriveTypeName::drive_type),
        )
    }

    fn heard(&self, heard: &chassis_protocol::detect::Heard, seconds: f64) -> String {
        format!(
            "{} frames in {seconds:.1} s{}",
            heard.frames_2020,
            match heard.replies_2020 {
                0 => String::new(),
                _ => ", among them the answer to a register read".into(),
            }
        )
    }

    fn simulate(
        &self,
        place: &crate::sim::Place<'_>,
        seed: u64,
        faults: chassis_protocol::sim::Faults,
    ) -> Result<(), String> {
        place.serve(
            || crate::sim::board(seed, faults),
            chassis_protocol::sim::Board::commands,
            "try `chassis --port {path} settings`",
        )
    }
}
