//! The one place the CLI turns a firmware generation into the code that serves it. Every
//! command that talks to a board is written once per generation ([`crate::v2020`],
//! [`crate::v1`]) behind [`Generation`]; [`of`] picks one, and nothing else in the CLI asks
//! which generation a board runs. What a generation cannot do (a turn by an angle on v1.0.0) is
//! refused by its own implementation, in one line, with nothing sent.

use crate::encode::Axes;
use crate::sim::Place;
use chassis_protocol::detect::{Firmware, Heard};
use chassis_protocol::sim::Faults;
use clap::Args;

/// `chassis set` (both generations).
#[derive(Debug, Args)]
pub struct SetArgs {
    /// The register.
    pub register: String,
    /// The value (decimal or 0x hex).
    #[arg(allow_hyphen_values = true)]
    pub value: String,
    /// battery-range only: the cut-off voltage.
    #[arg(allow_hyphen_values = true)]
    pub cutoff: Option<String>,
    /// Go ahead with a write that starts a 30 s gyro calibration (gyro-calibration 0xFFFF,
    /// system-mode switching bit 3 on).
    #[arg(long)]
    pub yes: bool,
}

/// `chassis drive` (2020: `--x --y --z`; v1.0.0: `--vx --vy --wz`).
#[derive(Debug, Args)]
pub struct DriveArgs {
    #[command(flatten)]
    pub axes: Axes,
    /// v1.0.0: sideways velocity, m/s.
    #[arg(long, value_name = "M/S", allow_hyphen_values = true)]
    pub vx: Option<f64>,
    /// v1.0.0: forward velocity, m/s.
    #[arg(long, value_name = "M/S", allow_hyphen_values = true)]
    pub vy: Option<f64>,
    /// v1.0.0: rotation, rad/s (counter-clockwise positive).
    #[arg(long, value_name = "RAD/S", allow_hyphen_values = true)]
    pub wz: Option<f64>,
    /// How long, in seconds.
    #[arg(long = "for", value_name = "SECONDS", allow_hyphen_values = true)]
    pub seconds: f64,
}

impl DriveArgs {
    /// Whether the SI axes (`--vx --vy --wz`, v1.0.0's) were given.
    pub fn si(&self) -> bool {
        self.vx.is_some() || self.vy.is_some() || self.wz.is_some()
    }

    /// Whether the raw axes (`--x --y --z`, the 2020 firmware's) were given.
    pub fn raw(&self) -> bool {
        [&self.axes.x, &self.axes.y, &self.axes.z]
            .iter()
            .any(|v| v.as_str() != "0")
    }
}

/// `chassis check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Only what neither moves the chassis nor writes to the board: link, registers,
    /// battery.
    #[arg(long)]
    pub no_motion: bool,
    /// Do not ask before the chassis moves.
    #[arg(long)]
    pub yes: bool,
    /// Set this drive type on the board (the board's own is kept if not given; 2020 only).
    #[arg(long, value_enum, value_name = "TYPE", conflicts_with = "no_motion")]
    pub drive_type: Option<DriveTypeName>,
}

/// A drive type, by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DriveTypeName {
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
    /// The protocol's drive type.
    pub const fn drive_type(self) -> chassis_protocol::DriveType {
        use chassis_protocol::DriveType;
        match self {
            DriveTypeName::Omni => DriveType::Omni,
            DriveTypeName::Mecanum => DriveType::Mecanum,
            DriveTypeName::Differential => DriveType::Differential,
            DriveTypeName::DifferentialOpenLoop => DriveType::DifferentialOpenLoop,
        }
    }
}

/// The commands that talk to a board, as one firmware generation does them. `path` is the
/// board's serial port.
pub trait Generation: Sync {
    /// `get NAME`: a register (2020) or a readback or one of its fields (v1.0.0).
    fn get(&self, path: &str, name: &str) -> Result<(), String>;
    /// `set`: a write, then a read back.
    fn set(&self, path: &str, set: &SetArgs) -> Result<(), String>;
    /// `settings [--save FILE | --restore FILE]`.
    fn settings(&self, path: &str, save: Option<&str>, restore: Option<&str>)
    -> Result<(), String>;
    /// `save`: the settings to the board's flash.
    fn save(&self, path: &str) -> Result<(), String>;
    /// `calibrate-gyro`.
    fn calibrate_gyro(&self, path: &str) -> Result<(), String>;
    /// `stop`: the stop, with the evidence that the board heard it.
    fn stop(&self, path: &str) -> Result<(), String>;
    /// `drive`: a velocity for a while, then the stop.
    fn drive(&self, path: &str, drive: &DriveArgs) -> Result<(), String>;
    /// `turn DEGREES`: one turn, sent once.
    fn turn(&self, path: &str, degrees: f64) -> Result<(), String>;
    /// `monitor [--drive] [--speed SPEED]`.
    fn monitor(&self, path: &str, drive: bool, speed: &str) -> Result<(), String>;
    /// `check`: the bring-up from the PC; `Err` carries the exit status.
    fn check(&self, path: &str, check: &CheckArgs) -> Result<(), (String, u8)>;
    /// What detection heard of this generation's frames in `seconds`, in words.
    fn heard(&self, heard: &Heard, seconds: f64) -> String;
    /// `sim`: serves this generation's simulated board at `place` until the process is stopped.
    fn simulate(&self, place: &Place<'_>, seed: u64, faults: Faults) -> Result<(), String>;
}

/// The code that serves `firmware`.
pub fn of(firmware: Firmware) -> &'static dyn Generation {
    match firmware {
        Firmware::V2020 => &crate::v2020::V2020,
        Firmware::V1_0_0 => &crate::v1::V1,
    }
}
