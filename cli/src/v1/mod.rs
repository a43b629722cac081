//! The commands on a board running the v1.0.0 firmware (`7B … BCC 7D` frames), through the
//! host driver: its settings ([`settings`]: `get` / `set` over the five readbacks and the three
//! settings frames, `settings` saving or restoring the three), its motion ([`motion`]: `stop`,
//! the forced stop; `drive --vx --vy --wz`), `check` and `monitor`. The driver is the same as the
//! 2020 board's, its core the v1.0.0 one: the same failsafe (it sends the forced stop), the same
//! whole-frame guarantee. What v1.0.0 has no frame for (a turn by an angle, storing in flash, a
//! gyro calibration) is refused in one line.

pub mod check;
pub mod monitor;
mod motion;
mod settings;

use crate::generation::{CheckArgs, DriveArgs, Generation, SetArgs};
use crate::port::BoardV1;
use crate::stopping;
use chassis_protocol::driver::Error;
use chassis_protocol::driver::host::SerialError;
use chassis_protocol::v1::BodyVelocity;

/// A driver error as one line, in the CLI's words.
pub(crate) fn explain(driver: &BoardV1, e: Error<SerialError>) -> String {
    stopping::explain(driver, e)
}

/// The line for a command v1.0.0 has no frame for: nothing was sent.
fn not_here(command: &str, why: &str) -> String {
    format!("{command}: this board runs the v1.0.0 firmware, and {why}")
}

/// The v1.0.0 firmware (`7B … BCC 7D` frames): the commands as it does them.
pub struct V1;

impl Generation for V1 {
    fn get(&self, path: &str, name: &str) -> Result<(), String> {
        settings::get(path, name)
    }

    fn set(&self, path: &str, args: &SetArgs) -> Result<(), String> {
        if args.cutoff.is_some() {
            return Err(format!(
                "set {}: one value on v1.0.0 (the cut-off is battery-range's, a 2020 register)",
                args.register
            ));
        }
        settings::set(path, &args.register, &args.value)
    }

    fn settings(
        &self,
        path: &str,
        save: Option<&str>,
        restore: Option<&str>,
    ) -> Result<(), String> {
        settings::settings(path, save, restore)
    }

    fn save(&self, _path: &str) -> Result<(), String> {
        Err(not_here(
            "save",
            "v1.0.0 has no frame that stores settings in flash (settings last until power-off: `chassis settings --save FILE` keeps them in a file)",
        ))
    }

    fn calibrate_gyro(&self, _path: &str) -> Result<(), String> {
        Err(not_here(
            "calibrate-gyro",
            "v1.0.0 has no gyro calibration frame",
        ))
    }

    fn stop(&self, path: &str) -> Result<(), String> {
        motion::stop(path)
    }

    fn drive(&self, path: &str, args: &DriveArgs) -> Result<(), String> {
        if args.raw() {
            return Err("drive: --x/--y/--z are the 2020 firmware's raw units; this board runs v1.0.0: give --vx --vy (m/s) --wz (rad/s)".into());
        }
        let velocity = BodyVelocity::new(
            motion::milli(args.vx.unwrap_or(0.0), "vx", "m/s")?,
            motion::milli(args.vy.unwrap_or(0.0), "vy", "m/s")?,
            motion::milli(args.wz.unwrap_or(0.0), "wz", "rad/s")?,
        );
        motion::drive(path, velocity, args.seconds)
    }

    fn turn(&self, _path: &str, _degrees: f64) -> Result<(), String> {
        Err(not_here(
            "turn",
            "v1.0.0 has no turn by an angle (its protocol has none): `chassis drive --wz RAD/S --for SECONDS` turns at a rate",
        ))
    }

    fn monitor(&self, path: &str, drive: bool, speed: &str) -> Result<(), String> {
        let speed = crate::value::parse_i32(speed, "speed", 1, 2_000)
            .map_err(|e| format!("{e}: on v1.0.0 the speed is in mm/s"))?;
        monitor::run(path, drive, speed)
    }

    fn check(&self, path: &str, args: &CheckArgs) -> Result<(), (String, u8)> {
        if args.drive_type.is_some() {
            return Err((
                not_here(
                    "check --drive-type",
                    "it has no drive-type register (each velocity frame carries the vendor's type byte): run `chassis check` without it",
                ),
                1,
            ));
        }
        check::check(path, args.no_motion, args.yes)
    }

    fn heard(&self, heard: &chassis_protocol::detect::Heard, seconds: f64) -> String {
        format!(
            "{} frames in {seconds:.1} s, each with its BCC right{}{}",
            heard.frames_v1,
            match heard.bad_checksum_v1 {
                0 => String::new(),
                n => format!(" ({n} more with a wrong BCC: a noisy line?)"),
            },
            match heard.replies_v1 {
                0 => String::new(),
                _ => ", among them the answer to a readback".into(),
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
            || crate::sim::board_v1(seed, faults),
            chassis_protocol::sim::v1::Board::total_commands,
            "firmware v1.0.0, 7B … 7D frames",
        )
    }
}
