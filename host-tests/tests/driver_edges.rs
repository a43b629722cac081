//! The driver where an executor, a HAL's clock or the user's own code touch it: a clock that
//! stands still while telemetry flows, a board that answers late, a `u32` millisecond counter
//! that wraps, a driver released and rebuilt, a turn outstanding when the link dies. Each test
//! is one case of the driver-safety issue, through the public API against the simulator.
//! (Cancelled futures and cut writes: `tests/cancellation.rs`.)

use chassis_protocol::driver::asynch::{self, Driver as AsyncDriver};
use chassis_protocol::driver::blocking::{self, Driver};
use chassis_protocol::driver::{Config, CoreError, Error, TurnState, reg};
use chassis_protocol::sim::{
    Board, FACTORY, Faults, Motion, SimClock, SimConfig, SimDelay, SimUart,
};
use chassis_protocol::{Register, Stream, Velocity};
use core::cell::Cell;
use core::convert::Infallible;
use embedded_io::{Read, ReadReady};

fn board(config: SimConfig, time: &Cell<u64>) -> SimUart<'_> {
    SimUart::new(Board::new(config), time)
}

// ----- Case 2: a clock that stands still, telemetry flowing -----

/// The simulated board, its time moved on by the UART itself (1 ms every `polls_per_ms` polls),
/// handing over at most `max_read` bytes a read: the board streams while the driver's clock
/// stands still.
struct Streaming<'t> {
    uart: SimUart<'t>,
    time: &'t Cell<u64>,
    polls: u64,
    polls_per_ms: u64,
    max_read: usize,
}

impl embedded_io::ErrorType for Streaming<'_> {
    type Error = Infallible;
}

impl ReadReady for Streaming<'_> {
    fn read_ready(&mut self) -> Result<bool, Infallible> {
        self.polls += 1;
        if self.polls.is_multiple_of(self.polls_per_ms) {
            self.time.set(self.time.get() + 1);
        }
        self.uart.read_ready()
    }
}

impl Read for Streaming<'_> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        let n = buf.len().min(self.max_read);
        self.uart.read(&mut buf[..n])
    }
}

impl embedded_io::Write for Streaming<'_> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        self.uart.write(buf)
    }

    fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

#[test]
fn case2_a_stuck_clock_ends_a_read_in_stated_polls_while_telemetry_flows() {
    for max_read in [32, 1] {
        let time = Cell::new(0);
        let mut uart = board(SimConfig::default(), &time);
        uart.board_mut().set_faults(Faults {
            replies_stopped: true,
            ..Faults::default()
        });
        let uart = Streaming {
            uart,
            time: &time,
            polls: 0,
            polls_per_ms: 10,
            max_read,
        };
        let mut d = Driver::new(uart, || 7u64, Config::DEFAULT);
        assert_eq!(
            d.read(reg::MaxSpeed),
            Err(Error::Core(CoreError::ClockStalled)),
            "{max_read}-byte reads"
        );
        assert!(d.core().imu().is_some(), "telemetry flowed meanwhile");
        // Each poll of the driver asks `read_ready` at least once: the bound is in polls.
        let polls = d.uart().polls;
        eprintln!(
            "stuck clock, {max_read}-byte reads: ClockStalled after {polls} read_ready calls"
        );
        let bound = u64::from(blocking::STALL_POLLS) * (32 / max_read as u64 + 2);
        assert!(
            polls <= bound,
            "{polls} read_ready calls ({max_read}-byte reads)"
        );
        assert!(!d.core().busy());
    }
}

#[test]
fn case2_a_stuck_clock_ends_an_async_read_while_telemetry_flows() {
    let time = Cell::new(0);
    let mut uart = board(SimConfig::default(), &time);
    uart.board_mut().set_faults(Faults {
        replies_stopped: true,
        ..Faults::default()
    });
    // The delay moves the board's time on; the driver's clock never moves.
    let mut d = AsyncDriver::new(uart, || 7u64, SimDelay(&time), Config::DEFAULT);
    let result = embassy_futures::block_on(d.read(reg::MaxSpeed));
    assert_eq!(result, Err(Error::Core(CoreError::ClockStalled)));
    assert!(d.core().imu().is_some(), "telemetry flowed meanwhile");
    eprintln!(
        "stuck clock, async: ClockStalled after {} ms of delays",
        time.get()
    );
    // At most STALL_WAITS pump turns of at most MAX_WAIT_MS each.
    assert!(
        time.get() <= u64::from(asynch::STALL_WAITS) * asynch::MAX_WAIT_MS + 100,
        "{} ms",
        time.get()
    );
}

/// A UART that never runs dry (a flood of bytes): a poll still ends.
struct Flood;

impl embedded_io::ErrorType for Flood {
    type Error = Infallible;
}

impl ReadReady for Flood {
    fn read_ready(&mut self) -> Result<bool, Infallible> {
        Ok(true)
    }
}

impl Read for Flood {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        buf.fill(0x55);
        Ok(buf.len())
    }
}

impl embedded_io::Write for Flood {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        Ok(buf.len())
    }

    fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

#[test]
fn case2_a_uart_that_never_runs_dry_cannot_hang_a_poll_or_a_read() {
    let time = Cell::new(0);
    let mut d = Driver::new(Flood, SimClock(&time), Config::DEFAULT);
    assert_eq!(d.poll(), Ok(None));
    assert_eq!(
        d.read(reg::MaxSpeed),
        Err(Error::Core(CoreError::Timeout(Register::MaxSpeed)))
    );
}

// ----- Case 3: late replies -----

#[test]
fn case3_a_board_slower_than_the_timeout_fails_one_read_not_every_read() {
    for delay in [60, 120] {
        let time = Cell::new(0);
        let config = SimConfig {
            reply_delay_ms: delay,
            ..SimConfig::default()
        };
        let mut d = Driver::new(board(config, &time), SimClock(&time), Config::DEFAULT);
        let registers = [
            (Register::MaxSpeed, u32::from(FACTORY.max_speed)),
            (Register::SpeedKp, FACTORY.speed_kp),
            (Register::SpeedKi, FACTORY.speed_ki),
            (Register::MotorVoltage, u32::from(FACTORY.motor_centivolts)),
            (Register::GyroGain, FACTORY.gyro_gain),
            (Register::MaxSpeed, u32::from(FACTORY.max_speed)),
        ];
        let mut timeouts = 0;
        for (register, value) in registers {
            match d.read_raw(register) {
                Ok(got) => assert_eq!(got, value, "{register:?} at {delay} ms"),
                Err(Error::Core(CoreError::Timeout(r))) => {
                    assert_eq!(r, register);
                    timeouts += 1;
                }
                Err(e) => panic!("{register:?} at {delay} ms: {e:?}"),
            }
        }
        eprintln!("board answering in {delay} ms: {timeouts} timeouts in 6 reads");
        // Before: at 60 ms one Timeout, then five WrongReply.
        assert!(timeouts <= 1, "{timeouts} timeouts at {delay} ms");
        // Before: at 120 ms, Unconfirmed.
        assert_eq!(d.read_settings(), Ok(FACTORY), "at {delay} ms");
    }
}

#[test]
fn case3_a_stale_zero_never_releases_the_turn_guard() {
    let time = Cell::new(0);
    let config = SimConfig {
        reply_delay_ms: 60,
        ..SimConfig::default()
    };
    let mut d = Driver::new(board(config, &time), SimClock(&time), Config::DEFAULT);
    // The first read of the pending angle times out; its reply (0) comes 5 ms later.
    assert_eq!(
        d.turn_remaining(),
        Err(Error::Core(CoreError::Timeout(Register::PendingAngle)))
    );
    d.turn_by(900).unwrap();
    // Before: this read took the late 0, the guard let a second turn through (180° in all).
    let left = d.turn_remaining().unwrap();
    assert!(left > 800, "{left}");
    assert_eq!(d.turn_by(900), Err(Error::Core(CoreError::TurnInProgress)));
    assert_eq!(d.uart().board().total_turn_commanded(), 900);
}

// ----- Case 4: a u32 millisecond counter that wraps -----

/// Milliseconds as a 32-bit tick counter gives them, started `before_wrap` ms before it wraps.
fn wrapping(time: &Cell<u64>, before_wrap: u64) -> impl FnMut() -> u64 + '_ {
    move || {
        let now = time.get() + 1;
        time.set(now);
        u64::from((now + u64::from(u32::MAX) + 1 - before_wrap) as u32)
    }
}

#[test]
fn case4_rates_and_the_link_hold_across_the_wrap() {
    let time = Cell::new(0);
    let mut d = Driver::new(
        board(SimConfig::default(), &time),
        wrapping(&time, 500),
        Config::DEFAULT,
    );
    while time.get() < 4_000 {
        d.poll().unwrap();
    }
    let now = u64::from((time.get() + u64::from(u32::MAX) + 1 - 500) as u32);
    assert!(now < 4_000, "the clock wrapped");
    assert!(d.core().link_alive(now), "before: the link was called dead");
    let rate = d.core().stream(Stream::Imu).rate_hz();
    assert!((95..=105).contains(&rate), "IMU {rate} Hz (before: 0)");
}

#[test]
fn case4_the_failsafe_stops_across_the_wrap() {
    let time = Cell::new(0);
    let mut d = Driver::new(
        board(SimConfig::default(), &time),
        wrapping(&time, 1_000),
        Config::DEFAULT,
    );
    d.set_velocity(Velocity::new(0, 300, 0)).unwrap();
    while time.get() < 950 {
        d.set_velocity(Velocity::new(0, 300, 0)).unwrap();
        d.poll().unwrap();
    }
    // The board goes silent 50 ms before the wrap.
    d.uart_mut().board_mut().set_faults(Faults {
        telemetry_stopped: true,
        replies_stopped: true,
        ..Faults::default()
    });
    let silent_from = time.get();
    while d.uart().board().motion() != (Motion::Velocity { x: 0, y: 0, z: 0 }) {
        d.poll().unwrap();
        assert!(
            time.get() < silent_from + 5_000,
            "no stop in 5 s (before: none)"
        );
    }
    let stopped_after = time.get() - silent_from;
    eprintln!("silent across the wrap: stopped {stopped_after} ms after");
    assert!(stopped_after <= 130, "stopped {stopped_after} ms after");
    assert_eq!(d.core().failsafe_stops(), 1);
}

#[test]
fn case4_a_read_in_flight_across_the_wrap_ends() {
    let time = Cell::new(0);
    let mut uart = board(SimConfig::default(), &time);
    uart.board_mut().set_faults(Faults {
        replies_stopped: true,
        ..Faults::default()
    });
    let mut d = Driver::new(uart, wrapping(&time, 20), Config::DEFAULT);
    assert_eq!(
        d.read(reg::MaxSpeed),
        Err(Error::Core(CoreError::Timeout(Register::MaxSpeed)))
    );
    assert!(
        time.get() < 200,
        "ended at {} ms (before: never)",
        time.get()
    );
}

// ----- Case 5: a driver released, rebuilt, reconfigured -----

#[test]
fn case5_the_turn_guard_survives_release_and_a_new_driver() {
    let time = Cell::new(0);
    let mut d = Driver::new(
        board(SimConfig::default(), &time),
        SimClock(&time),
        Config::DEFAULT,
    );
    d.turn_by(900).unwrap();
    // Released and taken up again with its core.
    let (uart, clock, core) = d.release();
    let mut d = Driver::from_core(uart, clock, core);
    assert_eq!(d.turn_by(900), Err(Error::Core(CoreError::TurnInProgress)));
    // Released, the core thrown away, a new driver: it asks the board before a turn.
    let (uart, clock, _) = d.release();
    let mut d = Driver::new(uart, clock, Config::DEFAULT);
    assert_eq!(d.core().turn_state(), TurnState::Unknown);
    assert_eq!(d.turn_by(900), Err(Error::Core(CoreError::TurnInProgress)));
    assert!(d.core().turning());
    assert_eq!(d.uart().board().total_turn_commanded(), 900, "before: 1800");
}

#[test]
fn case5_a_cloned_turn_is_refused_while_the_first_runs() {
    let time = Cell::new(0);
    let mut d = Driver::new(
        board(SimConfig::default(), &time),
        SimClock(&time),
        Config::DEFAULT,
    );
    let turn = chassis_protocol::Turn::by_deci_degrees(900);
    let again = turn.clone();
    d.turn(turn).unwrap();
    assert_eq!(d.turn(again), Err(Error::Core(CoreError::TurnInProgress)));
    assert_eq!(d.uart().board().total_turn_commanded(), 900);
}

/// Three seconds of a turn and telemetry through 8 ms bursts; with `reconfigure`, the config
/// changed every 7 ms, in place or through release and rebuild. IMU frames received.
fn imu_frames_through_reconfiguration(reconfigure: bool) -> u32 {
    let time = Cell::new(0);
    let uart = board(SimConfig::default(), &time).with_bursts(8);
    let mut d = Driver::new(uart, SimClock(&time), Config::DEFAULT);
    d.turn_by(900).unwrap();
    let mut failsafe_ms = 100;
    while time.get() < 3_000 {
        d.poll().unwrap();
        if reconfigure && time.get().is_multiple_of(7) {
            failsafe_ms = if failsafe_ms == 100 { 150 } else { 100 };
            let config = Config {
                failsafe_ms,
                ..Config::DEFAULT
            };
            if time.get().is_multiple_of(2) {
                d.set_config(config);
            } else {
                let (uart, clock, mut core) = d.release();
                core.set_config(config);
                d = Driver::from_core(uart, clock, core);
            }
        }
    }
    assert_eq!(d.turn_by(900), Err(Error::Core(CoreError::TurnInProgress)));
    assert_eq!(d.core().parser_stats().missed_of(Stream::Imu), 0);
    d.core().stream(Stream::Imu).frames
}

#[test]
fn case5_changing_the_config_keeps_the_guard_and_every_byte_read() {
    // Before: up to 32 bytes dropped at each release.
    assert_eq!(
        imu_frames_through_reconfiguration(true),
        imu_frames_through_reconfiguration(false)
    );
}

// ----- Case 6: a turn outstanding when the link dies -----

#[test]
fn case6_a_turn_outstanding_when_the_link_dies_is_cancelled_at_the_first_reply() {
    let time = Cell::new(0);
    let mut d = Driver::new(
        board(SimConfig::default(), &time),
        SimClock(&time),
        Config::DEFAULT,
    );
    d.turn_by(1_800).unwrap();
    let sent = time.get();
    while time.get() < sent + 300 {
        d.poll().unwrap();
    }
    // The board stops talking (it still listens): the failsafe stops, the turn runs on.
    let dead = Faults {
        telemetry_stopped: true,
        replies_stopped: true,
        ..Faults::default()
    };
    d.uart_mut().board_mut().set_faults(dead);
    while time.get() < sent + 800 {
        d.poll().unwrap();
    }
    assert_eq!(d.core().failsafe_stops(), 1);
    assert!(d.core().turning(), "the guard holds while nothing is known");
    let pending = d.uart().board().pending_deci_degrees();
    assert!(pending > 0, "still turning: {pending}");
    // stop() with its replies lost says the turn may still run, and keeps the guard; it ends
    // within its stated bound (four reads, each waited for and its late reply allowed for).
    let asked = time.get();
    assert_eq!(
        d.stop(),
        Err(Error::Core(CoreError::Unconfirmed(Register::PendingAngle)))
    );
    let took = time.get() - asked;
    eprintln!("stop() with the replies lost: Unconfirmed after {took} ms");
    assert!(took <= 4 * (205 + 150) + 50, "stop() took {took} ms");
    assert!(d.core().turning());
    // The link comes back: at the first reply, the rest of the turn is cancelled.
    d.uart_mut().board_mut().set_faults(Faults::default());
    let back = time.get();
    while d.uart().board().pending_deci_degrees() != 0 {
        d.poll().unwrap();
        assert!(
            time.get() < back + 500,
            "not cancelled 500 ms after the link came back"
        );
    }
    let cancelled_after = time.get() - back;
    eprintln!(
        "turn cancelled {cancelled_after} ms after the link came back; {} of 1800 turned",
        d.uart().board().total_turn_commanded()
    );
    assert!(
        cancelled_after <= 200,
        "cancelled {cancelled_after} ms after"
    );
    // Turned less than asked: it stopped turning when the board answered again.
    let turned = d.uart().board().total_turn_commanded();
    assert!((0..1_800).contains(&turned), "{turned} in all");
    assert!(!d.core().turning());
}
