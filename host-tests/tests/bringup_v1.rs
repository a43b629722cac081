//! The v1.0.0 bring-up (`chassis_bringup::v1`, blocking) against the simulated v1.0.0 board,
//! in simulated time (every clock reading moves it on by 1 ms): what it sends, what it judges,
//! how it fails. The same bring-up runs in QEMU against the board served over TCP
//! (`tests/qemu.rs`, the `v1_` tests).

use chassis_bringup::link::Common;
use chassis_bringup::v1::{Blocking, Link, Plan, Why, bring_up};
use chassis_bringup::{Check, LinkError, Note, Skip, Timing};
use chassis_protocol::driver::Config;
use chassis_protocol::driver::v1::{DriverCore, Event};
use chassis_protocol::sim::v1::{Board, SimConfig};
use chassis_protocol::sim::{Faults, SimClock, SimUart};
use chassis_protocol::v1::{BodyVelocity, Command, Readback, Reply};
use core::cell::Cell;

/// The forced stop as PROTOCOL-V1.md gives it: `0x25`, ten `00`, BCC `7B ^ 25 = 5E`.
const FORCED_STOP: [u8; 14] = [0x7B, 0x25, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x5E, 0x7D];

type Inner<'t> = Blocking<SimUart<'t, Board>, SimClock<'t>>;

/// The blocking v1.0.0 link over the simulated board, which notes what the bring-up says and
/// can silence the board when a check starts.
struct Recording<'t> {
    inner: Inner<'t>,
    notes: Vec<Note>,
    silence_at: Option<Check>,
}

impl Common for Recording<'_> {
    type Core = DriverCore;
    type Event = Event;
    fn now_ms(&mut self) -> u64 {
        self.inner.now_ms()
    }
    fn core(&self) -> &DriverCore {
        self.inner.core()
    }
    fn poll(&mut self) -> Result<Option<Event>, LinkError> {
        self.inner.poll()
    }
    fn stop(&mut self) -> Result<(), LinkError> {
        self.inner.stop()
    }
    fn note(&mut self, note: Note) {
        if matches!(note, Note::Start(c) if Some(c) == self.silence_at) {
            self.inner
                .driver()
                .uart_mut()
                .board_mut()
                .set_faults(Faults {
                    telemetry_stopped: true,
                    replies_stopped: true,
                    ..Faults::default()
                });
        }
        self.notes.push(note);
    }
}

impl Link for Recording<'_> {
    fn set_velocity(&mut self, velocity: BodyVelocity) -> Result<(), LinkError> {
        self.inner.set_velocity(velocity)
    }
    fn readback(&mut self, readback: Readback) -> Result<Reply, LinkError> {
        self.inner.readback(readback)
    }
}

fn link(time: &Cell<u64>, silence_at: Option<Check>) -> Recording<'_> {
    let board = Board::new(SimConfig::default());
    Recording {
        inner: Blocking::new(SimUart::new(board, time), SimClock(time), Config::DEFAULT),
        notes: Vec::new(),
        silence_at,
    }
}

fn board<'a>(link: &'a mut Recording<'_>) -> &'a Board {
    link.inner.driver().uart().board()
}

fn is_motion(command: &Command) -> bool {
    matches!(
        command,
        Command::BodyVelocity(_) | Command::MotorVelocity(_)
    )
}

#[test]
fn the_bring_up_passes_on_the_simulated_board_and_ends_with_the_forced_stop() {
    let time = Cell::new(0);
    let mut link = link(&time, None);
    let report = bring_up(&mut link, &Plan::DEFAULT).expect("every check passes");
    eprintln!("{report:?} in {} ms", time.get());

    assert!(report.telemetry_per_10s >= 200, "{report:?}");
    assert_eq!(
        report.geometry.wheel_diameter_mm, 60,
        "the factory geometry"
    );
    assert_eq!(
        report.measured_mm_s,
        [300, 300],
        "the board measures what it is told"
    );
    let off = (report.yaw_measured_mrad - report.yaw_expected_mrad).abs();
    assert!(
        report.yaw_expected_mrad > 700 && off <= 30,
        "the yaw turned by wz × t: {report:?}"
    );
    assert_eq!(report.still_peak, [0, 0, 0]);
    assert!(report.battery_mv > 11_000);
    assert_eq!(report.bad_frames, 0);

    let board = board(&mut link);
    for code in [0x23, 0x24, 0x40] {
        assert_eq!(
            board.received_count(code),
            0,
            "no settings frame {code:#04x}"
        );
    }
    for code in [0x33, 0x34, 0x50] {
        assert_eq!(board.received_count(code), 1, "readback {code:#04x} once");
    }
    let last = board.received().filter(|c| is_motion(c)).last().copied();
    assert_eq!(last.map(|c| c.encode()), Some(FORCED_STOP));
    assert_eq!(board.velocity(), BodyVelocity::FORCED_STOP);
    assert_eq!(board.measured_velocity(), [0, 0, 0]);
    assert_eq!(board.bad_frames(), 0);

    let passed: Vec<Check> = link
        .notes
        .iter()
        .filter_map(|n| match n {
            Note::Passed(c) => Some(*c),
            _ => None,
        })
        .collect();
    let expected: Vec<Check> = Check::ALL
        .into_iter()
        .filter(|c| *c != Check::DriveType)
        .collect();
    assert_eq!(passed, expected, "every check but the drive type, in order");
}

#[test]
fn a_board_silent_in_the_control_loop_is_stopped_by_the_failsafe() {
    let time = Cell::new(0);
    let mut link = link(&time, Some(Check::ControlLoop));
    let failure = bring_up(&mut link, &Plan::DEFAULT).expect_err("the loop fails");
    assert_eq!(failure.check, Check::ControlLoop);
    assert_eq!(failure.check.exit_code(), 18);
    assert_eq!(failure.why, Why::FailsafeStop);
    assert_eq!(link.core().failsafe_stops(), 1);
    let board = board(&mut link);
    assert_eq!(board.velocity(), BodyVelocity::FORCED_STOP);
    assert!(
        board.forced_stops() >= 2,
        "the failsafe's, then the bring-up's"
    );
}

#[test]
fn a_board_silent_while_driving_fails_the_forward_check() {
    let time = Cell::new(0);
    let mut link = link(&time, Some(Check::Forward));
    let failure = bring_up(&mut link, &Plan::DEFAULT).expect_err("forward fails");
    assert_eq!(failure.check, Check::Forward);
    assert!(
        matches!(failure.why, Why::FailsafeStop | Why::NoTelemetry),
        "{failure:?}"
    );
    assert_eq!(board(&mut link).velocity(), BodyVelocity::FORCED_STOP);
}

#[test]
fn a_low_battery_fails_its_check_and_the_chassis_is_stopped() {
    let time = Cell::new(0);
    let mut link = link(&time, None);
    let plan = Plan {
        min_millivolts: 12_500,
        ..Plan::DEFAULT
    };
    let failure = bring_up(&mut link, &plan).expect_err("the battery is below 12.5 V");
    assert_eq!(failure.check, Check::Battery);
    assert!(matches!(failure.why, Why::LowBattery(mv, 12_500) if mv <= 12_000));
    assert_eq!(board(&mut link).velocity(), BodyVelocity::FORCED_STOP);
}

#[test]
fn without_motion_only_readbacks_are_sent() {
    let time = Cell::new(0);
    let mut link = link(&time, None);
    let plan = Plan {
        timing: Timing {
            motion: false,
            ..Timing::DEFAULT
        },
        ..Plan::DEFAULT
    };
    bring_up(&mut link, &plan).expect("link, settings and battery pass");
    assert!(
        link.notes
            .contains(&Note::Skipped(Check::Forward, Skip::NoMotion))
    );
    let board = board(&mut link);
    assert!(
        board.received().all(|c| matches!(c, Command::Readback(_))),
        "{:?}",
        board.received().collect::<Vec<_>>()
    );
    assert_eq!(board.total_commands(), 3);
}
