//! `chassis check`: the firmware's bring-up ([`chassis_bringup::v2020::bring_up`], the same code the
//! boards under `mcu-example/boards/` run) from a PC, through the host driver: a progress line
//! per check, a verdict on one screen, the exit status the verdict (0, or the failed check's
//! code: the QEMU firmware's). `--no-motion` runs only what neither moves the chassis nor
//! writes to the board. Before anything moves, a warning and a question (`--yes` answers it).
//! SIGINT, SIGTERM and SIGHUP stop the chassis (a turn cancelled) and end the check.

use super::open;
use crate::check::{Session, Steps, driver_words, timing};
use chassis_bringup::link::Common;
use chassis_bringup::v2020::{Link, Plan, Report, Why, bring_up};
use chassis_bringup::{Check, LinkError, Skip};
use chassis_protocol::driver::host::Heard;
use chassis_protocol::driver::{DriverCore, Event};
use chassis_protocol::registers::Snapshot;
use chassis_protocol::{DriveType, Register, Stream, Turn, Velocity, Write};

/// What the check does to a chassis, said before it starts.
const MOTION: &str = "the chassis will move: forward and sideways for 0.4 s each at speed 300, one 90° turn, then 1.5 s forward at 150. Give it about a metre of clear floor, or lift it so its wheels turn freely";

/// What the 2020 check says of itself: its nine checks, by their own names.
impl Steps for DriverCore {
    type Report = Report;
    const PASS_NOTE: &str = "";

    fn checks() -> impl Iterator<Item = Check> {
        Check::ALL.into_iter()
    }

    fn name(check: Check) -> &'static str {
        check.name()
    }

    fn telemetry(event: &Event) -> bool {
        matches!(event, Event::Telemetry(_))
    }

    fn detail(session: &Checker, check: Check, seconds: f64) -> String {
        let core = Common::core(session);
        match check {
            Check::Link => {
                let frames = |s: Stream| core.stream(s).frames;
                format!(
                    "{} IMU, {} encoder, {} battery frames in {seconds:.1} s",
                    frames(Stream::Imu),
                    frames(Stream::Encoders),
                    frames(Stream::Battery)
                )
            }
            Check::Battery => core.battery().map_or_else(String::new, |b| {
                format!(
                    "{}.{:02} V, {} %",
                    b.value.centivolts / 100,
                    b.value.centivolts % 100,
                    b.value.percent
                )
            }),
            _ => String::new(),
        }
    }

    fn skipped(why: Skip) -> &'static str {
        match why {
            Skip::NoMotion => "--no-motion",
            Skip::DriveTypeKept => "the board's own kept: --drive-type sets one",
            Skip::NoSideways => "a differential chassis does not move sideways",
            Skip::NoEncoders => "no encoders on an open-loop differential chassis",
        }
    }

    fn found(check: Check, said: &str, report: &Report) -> String {
        passed_detail(check, said, report)
    }

    fn counted(report: &Report) -> String {
        format!("telemetry frames missed: {}", report.missed)
    }
}

/// The check's [`Link`]: the host driver, with a progress line per check and an ending (a
/// signal, the terminal or input gone: [`crate::ending`]) turned into an error at the next
/// call (the bring-up then stops the chassis itself).
type Checker = Session<DriverCore>;

impl Link for Checker {
    fn set_velocity(&mut self, velocity: Velocity) -> Result<(), LinkError> {
        self.go_on()?;
        self.inner.set_velocity(velocity)
    }
    fn turn(&mut self, turn: Turn) -> Result<(), LinkError> {
        self.go_on()?;
        self.inner.turn(turn)
    }
    fn turn_remaining(&mut self) -> Result<i32, LinkError> {
        self.go_on()?;
        self.inner.turn_remaining()
    }
    fn read_settings(&mut self) -> Result<Snapshot, LinkError> {
        self.go_on()?;
        self.inner.read_settings()
    }
    fn read_verified(&mut self, register: Register) -> Result<u32, LinkError> {
        self.go_on()?;
        self.inner.read_verified(register)
    }
    fn write(&mut self, write: Write) -> Result<(), LinkError> {
        self.go_on()?;
        self.inner.write(write)
    }
}

/// Why a check failed, in words.
fn why(why: Why, heard: Heard, port: &str) -> String {
    match why {
        Why::Driver(e) => driver_words(e, heard, port),
        Why::Rate(stream, per_10s) if heard == Heard::Nothing => format!(
            "no telemetry ({stream:?} {:.1} Hz): is the board powered, TX wired to RX and RX to TX, at 115200 bps?",
            f64::from(per_10s) / 10.0
        ),
        Why::Rate(stream, per_10s) => format!(
            "{stream:?} frames come at {:.1} Hz, {} Hz expected",
            f64::from(per_10s) / 10.0,
            stream.rate_hz()
        ),
        Why::EncodersStill => "the encoders did not count: motors powered (motor-voltage)? encoders plugged in? wheels free?".into(),
        Why::EncodersMoving => "the encoders kept counting after the stop".into(),
        Why::GyroStill => "the gyro saw no rotation during the turn".into(),
        Why::TurnPending(left) => format!(
            "the turn was not done in time ({:.1}° still pending)",
            f64::from(left) / 10.0
        ),
        Why::DriveTypeNotSet(read) => format!("the drive type reads back {read:?}"),
        Why::LowBattery(centivolts, limit) => format!(
            "the battery is at {:.2} V, its cut-off {:.2} V: charge it",
            f64::from(centivolts) / 100.0,
            f64::from(limit) / 100.0
        ),
        Why::NoBattery => "no battery frame came".into(),
        Why::NoEncoderFrames => {
            "no encoder frame came during the drive: the board went quiet".into()
        }
        Why::FailsafeStop => {
            "the board went quiet: the driver's failsafe stopped the chassis".into()
        }
    }
}

/// What a passed check found, for its line of the verdict (`frames`: what the link check
/// counted).
fn passed_detail(check: Check, frames: &str, report: &Report) -> String {
    let s = &report.snapshot;
    match check {
        Check::Link => format!(
            "IMU {:.1} Hz, encoders {:.1} Hz ({frames})",
            f64::from(report.rates_per_10s[0]) / 10.0,
            f64::from(report.rates_per_10s[1]) / 10.0,
        ),
        Check::Settings => format!(
            "max-speed {}, kp {}, ki {}, system-mode 0x{:X} ({:?}), motor-voltage {:.2} V, pending angle {:.1}°",
            s.max_speed,
            s.speed_kp,
            s.speed_ki,
            s.system_mode.bits(),
            s.system_mode.drive_type(),
            f64::from(s.motor_centivolts) / 100.0,
            f64::from(report.pending_before) / 10.0
        ),
        Check::DriveType => "set".into(),
        Check::Forward => format!("encoders counted {} ticks", report.ticks[0]),
        Check::Strafe => format!("encoders counted {} ticks", report.ticks[1]),
        Check::Turn => format!("90° done, gyro Z peak {}", report.gyro_peak),
        Check::Stop => "encoders still".into(),
        Check::Battery => format!(
            "{:.2} V, {} %",
            f64::from(report.battery.0) / 100.0,
            report.battery.1
        ),
        Check::ControlLoop => format!(
            "{} verified reads while moving, no failsafe stop",
            report.loop_reads
        ),
    }
}

/// `chassis check [--no-motion] [--yes] [--drive-type TYPE]`.
pub fn check(
    path: &str,
    no_motion: bool,
    yes: bool,
    drive: Option<DriveType>,
) -> Result<(), (String, u8)> {
    let mut link = Checker::open(path, no_motion, yes, MOTION, open)?;
    say!(
        "chassis check on {path}: {}",
        if no_motion {
            "link, registers and battery (only reads are sent: nothing moves, nothing is written)"
        } else {
            "every check (the chassis moves)"
        }
    );
    let plan = Plan {
        timing: timing(no_motion),
        drive,
        ..Plan::DEFAULT
    };
    let result = bring_up(&mut link, &plan);
    link.conclude(result, no_motion, path, |reason, heard| {
        why(reason, heard, path)
    })
}
