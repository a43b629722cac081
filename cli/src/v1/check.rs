//! `chassis check` on a board running the v1.0.0 firmware: its bring-up
//! ([`chassis_bringup::v1::bring_up`], the code the QEMU firmware runs against a v1.0.0
//! board) from a PC, through the host driver. The same shape as the 2020 check: a progress line
//! per check, a verdict on one screen, the exit status the failed check's code (the QEMU
//! firmware's), a question before anything moves, and SIGINT, SIGTERM and SIGHUP ending the
//! check with the forced stop sent.
//!
//! Nothing is written to the board: the settings are read back, never sent (the settings
//! frames would overwrite what the owner tuned). v1.0.0 has no drive-type register and no turn
//! by an angle: its checks are eight, the turn a rotation at a rate.

use crate::check::{Session, Steps, driver_words, timing};
use crate::port;
use chassis_bringup::link::Common;
use chassis_bringup::v1::{Link, Plan, Report, Why, bring_up};
use chassis_bringup::{Check, LinkError, Skip};
use chassis_protocol::driver::host::Heard;
use chassis_protocol::driver::v1::{DriverCore, Event};
use chassis_protocol::v1::{BodyVelocity, Readback, Reply};

/// What the check does to a v1.0.0 chassis, said before it starts.
const MOTION: &str = "the chassis will move: forward and sideways at 0.3 m/s for 0.4 s each, a rotation at 1 rad/s for 1.2 s (about 70°), then 1.5 s forward at 0.15 m/s. Give it about a metre of clear floor, or lift it so its wheels turn freely";

/// What the v1.0.0 check says of itself: eight checks, the 2020 ones but the drive type (no
/// register holds one); its turn is a rotation at a rate.
impl Steps for DriverCore {
    type Report = Report;
    const PASS_NOTE: &str = " (firmware v1.0.0)";

    fn checks() -> impl Iterator<Item = Check> {
        Check::ALL.into_iter().filter(|c| *c != Check::DriveType)
    }

    fn name(check: Check) -> &'static str {
        match check {
            Check::Turn => "rotation",
            other => other.name(),
        }
    }

    fn telemetry(event: &Event) -> bool {
        matches!(event, Event::Telemetry(_))
    }

    fn detail(session: &Checker, check: Check, seconds: f64) -> String {
        match check {
            Check::Link => format!("{} telemetry frames in {seconds:.1} s", session.frames),
            Check::Battery => Common::core(session)
                .telemetry()
                .map_or_else(String::new, |t| {
                    format!("{:.2} V", units(t.value.battery_mv.into()))
                }),
            _ => String::new(),
        }
    }

    fn skipped(why: Skip) -> &'static str {
        match why {
            Skip::NoMotion => "--no-motion",
            Skip::DriveTypeKept | Skip::NoSideways | Skip::NoEncoders => "not on v1.0.0",
        }
    }

    fn found(check: Check, _said: &str, report: &Report) -> String {
        passed_detail(check, report)
    }

    fn counted(report: &Report) -> String {
        format!("frames refused by the parser: {}", report.bad_frames)
    }
}

/// The check's [`Link`]: the host driver, with a progress line per check and an ending (a
/// signal, the terminal or input gone: [`crate::ending`]) turned into an error at the next
/// call (the bring-up then sends the forced stop itself).
type Checker = Session<DriverCore>;

impl Link for Checker {
    fn set_velocity(&mut self, velocity: BodyVelocity) -> Result<(), LinkError> {
        self.go_on()?;
        self.inner.set_velocity(velocity)
    }
    fn readback(&mut self, readback: Readback) -> Result<Reply, LinkError> {
        self.go_on()?;
        self.inner.readback(readback)
    }
}

/// Milli-units as units with two decimals.
fn units(milli: i32) -> f64 {
    f64::from(milli) / 1000.0
}

/// Why a check failed, in words.
fn why(why: Why, heard: Heard, port: &str) -> String {
    match why {
        Why::Driver(e) => driver_words(e, heard, port),
        Why::Rate(per_10s) if heard == Heard::Nothing => format!(
            "no telemetry ({:.1} Hz): is the board powered, TX wired to RX and RX to TX, at 115200 bps?",
            f64::from(per_10s) / 10.0
        ),
        Why::Rate(per_10s) => format!(
            "telemetry comes at {:.1} Hz, at least 14 Hz expected (the board sends 20-24 Hz)",
            f64::from(per_10s) / 10.0
        ),
        Why::NoTelemetry => {
            "no telemetry frame came when one was needed: the board went quiet".into()
        }
        Why::NotFollowed(commanded, measured) => format!(
            "the measured velocity did not follow the command: {:.3} m/s for {:.3} m/s commanded (motors powered? wheels free?)",
            units(measured.into()),
            units(commanded.into())
        ),
        Why::YawOff(expected, measured) => format!(
            "the yaw from the IMU turned {:.2} rad, {:.2} rad expected (is the chassis free to turn, the IMU fixed to it?)",
            units(measured),
            units(expected)
        ),
        Why::StillMoving([vx, vy, wz]) => format!(
            "still moving after the forced stop: |vx| {:.3} m/s, |vy| {:.3} m/s, |wz| {:.3} rad/s",
            units(vx.into()),
            units(vy.into()),
            units(wz.into())
        ),
        Why::LowBattery(mv, cutoff) => format!(
            "the battery is at {:.2} V, its cut-off {:.2} V: charge it",
            units(mv.into()),
            units(cutoff.into())
        ),
        Why::FailsafeStop => {
            "the board went quiet: the driver's failsafe sent the forced stop".into()
        }
    }
}

/// What a passed check found, for its line of the verdict.
fn passed_detail(check: Check, report: &Report) -> String {
    let (system, geometry, pid) = (&report.system, &report.geometry, &report.pid);
    match check {
        Check::Link => format!(
            "telemetry {:.1} Hz",
            f64::from(report.telemetry_per_10s) / 10.0
        ),
        Check::Settings => format!(
            "read back, nothing written: wheel diameter {} mm, wheel spacing {} mm, axle spacing {} mm, gear ratio {}, encoder {} PPR, PWM {}..{}, velocity PI {}/{}",
            geometry.wheel_diameter_mm,
            geometry.wheel_spacing_mm,
            geometry.axle_spacing_mm,
            geometry.gear_ratio,
            system.encoder_ppr,
            system.pwm_min,
            system.pwm_max,
            pid.velocity_kp,
            pid.velocity_ki
        ),
        Check::Forward => format!(
            "vy measured {:.3} m/s",
            units(report.measured_mm_s[0].into())
        ),
        Check::Strafe => format!(
            "vx measured {:.3} m/s",
            units(report.measured_mm_s[1].into())
        ),
        Check::Turn => format!(
            "yaw turned {:.2} rad ({:.2} expected), gyro z peak {} (raw)",
            units(report.yaw_measured_mrad),
            units(report.yaw_expected_mrad),
            report.gyro_z_peak
        ),
        Check::Stop => format!(
            "still after the forced stop (peaks |vx| {} |vy| {} mm/s, |wz| {} mrad/s)",
            report.still_peak[0], report.still_peak[1], report.still_peak[2]
        ),
        Check::Battery => format!("{:.2} V", units(report.battery_mv.into())),
        Check::ControlLoop => format!(
            "telemetry {:.1} Hz while commanded, no failsafe stop",
            f64::from(report.loop_per_10s) / 10.0
        ),
        Check::DriveType => "not on v1.0.0".into(),
    }
}

/// `chassis check [--no-motion] [--yes]` on a v1.0.0 board.
pub fn check(path: &str, no_motion: bool, yes: bool) -> Result<(), (String, u8)> {
    let mut link = Checker::open(path, no_motion, yes, MOTION, |path| {
        port::open_v1(path, None)
    })?;
    say!(
        "chassis check on {path} (firmware v1.0.0): {}",
        if no_motion {
            "link, settings and battery (only readbacks are sent: nothing moves, nothing is written)"
        } else {
            "every check (the chassis moves; nothing is written)"
        }
    );
    let plan = Plan {
        timing: timing(no_motion),
        ..Plan::DEFAULT
    };
    let result = bring_up(&mut link, &plan);
    link.conclude(result, no_motion, path, |reason, heard| {
        why(reason, heard, path)
    })
}
