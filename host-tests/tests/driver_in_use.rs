//! The driver as users meet it (issue 8): a UART that reports errors, register reads while
//! driving, settings pauses from 0 to 500 ms, a control loop slower than 10 Hz, a USB-UART that
//! delivers bytes in bursts, a message from the network, a clock that stands still, a
//! transmitter that never drains. One test (or more) per bug of the issue; each failed on the
//! driver before it.

use chassis_protocol::driver::asynch::Driver as AsyncDriver;
use chassis_protocol::driver::blocking::Driver;
use chassis_protocol::driver::nb::{NbError, NbSerial};
use chassis_protocol::driver::{
    Config, CoreError, DriverCore, Error, Event, Outcome, Request, Snapshot, reg,
};
use chassis_protocol::sim::{
    Board, FACTORY, Faults, Motion, SimClock, SimConfig, SimDelay, SimUart,
};
use chassis_protocol::{Register, Stream, SystemMode, Velocity};
use core::cell::Cell;
use core::convert::Infallible;
use core::future::Future;
use core::pin::pin;
use core::task::{Context, Poll, Waker};
use embedded_hal_nb::{nb, serial};
use embedded_io::{Read, ReadReady, Write as _};

const STILL: Motion = Motion::Velocity { x: 0, y: 0, z: 0 };

/// An error a real UART reports: bytes were lost (RX overrun).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Overrun;

impl core::fmt::Display for Overrun {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("RX overrun")
    }
}

impl core::error::Error for Overrun {}

impl embedded_io::Error for Overrun {
    fn kind(&self) -> embedded_io::ErrorKind {
        embedded_io::ErrorKind::Other
    }
}

/// The simulated board behind a UART that fails on command.
struct Flaky<'t> {
    uart: SimUart<'t>,
    fail_writes: u32,
    fail_reads: u32,
}

impl<'t> Flaky<'t> {
    fn new(time: &'t Cell<u64>) -> Self {
        Flaky {
            uart: SimUart::new(Board::new(SimConfig::default()), time),
            fail_writes: 0,
            fail_reads: 0,
        }
    }
}

impl embedded_io::ErrorType for Flaky<'_> {
    type Error = Overrun;
}

impl Read for Flaky<'_> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Overrun> {
        if self.fail_reads > 0 {
            self.fail_reads -= 1;
            // The bytes in the receiver are lost with the overrun.
            let mut lost = [0u8; 64];
            let _ = self.uart.read(&mut lost);
            return Err(Overrun);
        }
        Ok(self.uart.read(buf).unwrap())
    }
}

impl ReadReady for Flaky<'_> {
    fn read_ready(&mut self) -> Result<bool, Overrun> {
        Ok(self.fail_reads > 0 || self.uart.read_ready().unwrap())
    }
}

impl embedded_io::Write for Flaky<'_> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Overrun> {
        if self.fail_writes > 0 {
            self.fail_writes -= 1;
            return Err(Overrun);
        }
        Ok(self.uart.write(buf).unwrap())
    }

    fn flush(&mut self) -> Result<(), Overrun> {
        Ok(())
    }
}

fn sim_driver(time: &Cell<u64>, sim: SimConfig) -> Driver<SimUart<'_>, SimClock<'_>> {
    Driver::new(
        SimUart::new(Board::new(sim), time),
        SimClock(time),
        Config::DEFAULT,
    )
}

/// Polls until the simulated time reaches `until`.
fn poll_until<U, C>(d: &mut Driver<U, C>, time: &Cell<u64>, until: u64)
where
    U: Read + ReadReady + embedded_io::Write,
    U::Error: core::fmt::Debug,
    C: chassis_protocol::driver::Clock,
{
    while time.get() < until {
        d.poll().unwrap();
    }
}

// ----- Bug 1: one transport error left the driver busy for good -----

#[test]
fn bug1_an_error_on_the_write_of_a_read_leaves_the_driver_usable() {
    let time = Cell::new(0);
    let mut d = Driver::new(Flaky::new(&time), SimClock(&time), Config::DEFAULT);
    d.uart_mut().fail_writes = 1;
    assert_eq!(d.read(reg::MaxSpeed), Err(Error::Transport(Overrun)));
    assert!(!d.core().busy());
    assert_eq!(d.read(reg::MaxSpeed), Ok(FACTORY.max_speed));
}

#[test]
fn bug1_an_overrun_on_the_poll_that_carried_the_reply_leaves_the_turn_guard_working() {
    let time = Cell::new(0);
    let mut d = Driver::new(Flaky::new(&time), SimClock(&time), Config::DEFAULT);
    d.turn_by(90).unwrap();
    let t = time.get();
    poll_until(&mut d, &time, t + 300);
    d.uart_mut().fail_reads = 1;
    assert_eq!(d.turn_remaining(), Err(Error::Transport(Overrun)));
    // Before: `Busy` for ever, and `TurnInProgress` for ever with it.
    assert_eq!(d.turn_remaining(), Ok(0));
    assert!(!d.core().turning());
    d.turn_by(-90).unwrap();
}

#[test]
fn bug1_a_dropped_async_read_leaves_the_driver_usable() {
    let time = Cell::new(0);
    let uart = SimUart::new(Board::new(SimConfig::default()), &time);
    // Time moves only while the driver waits, as on a real executor.
    let mut d = AsyncDriver::new(uart, || time.get(), SimDelay(&time), Config::DEFAULT);
    embassy_futures::block_on(async {
        // A `select` with a timeout that fires first drops the read's future mid-wait.
        let raced =
            embassy_futures::select::select(d.read(reg::MaxSpeed), core::future::ready(())).await;
        assert!(matches!(raced, embassy_futures::select::Either::Second(())));
    });
    assert!(!d.core().busy(), "the dropped read ended with its future");
    let speed = embassy_futures::block_on(d.read(reg::MaxSpeed));
    assert_eq!(speed, Ok(FACTORY.max_speed));
}

// ----- Bug 2: the failsafe stopped a healthy robot -----

/// A 100 Hz control loop driving forward through 1 000 register reads and 100 turns (read while
/// the board pauses its telemetry for each settings frame, 0 to 500 ms): no stop, every turn
/// sent exactly once.
#[test]
fn bug2a_reads_and_turn_polls_while_driving_never_stop_the_robot() {
    for pause_ms in [0, 100, 250, 500] {
        let time = Cell::new(0);
        let sim = SimConfig {
            resume_after_ms: pause_ms,
            ..SimConfig::default()
        };
        let mut d = sim_driver(&time, sim);
        poll_until(&mut d, &time, 200);
        let (mut reads, mut turns, mut turned) = (0u32, 0u32, 0i64);
        let mut stops_seen = 0;
        while reads < 1_000 || turns < 100 {
            let period = time.get();
            d.set_velocity(Velocity::new(0, 200, 0)).unwrap();
            if turns < 100 {
                // Turning by 9° while going on forward.
                match d.turn(chassis_protocol::Turn::new(0, 200, 90)) {
                    Ok(()) => {
                        turns += 1;
                        turned += 90;
                    }
                    Err(Error::Core(CoreError::TurnInProgress)) => {}
                    Err(e) => panic!("turn: {e:?}"),
                }
            }
            if d.core().turning() {
                d.turn_remaining().unwrap();
            } else {
                assert_eq!(d.read(reg::MotorVoltage).unwrap(), 1_200);
            }
            reads += 1;
            poll_until(&mut d, &time, period + 10);
            if d.uart().board().motion() == STILL {
                stops_seen += 1;
            }
        }
        assert_eq!(d.core().failsafe_stops(), 0, "pause {pause_ms} ms");
        assert_eq!(stops_seen, 0, "pause {pause_ms} ms");
        assert_eq!(d.uart().board().total_turn_commanded(), turned);
        assert_eq!(turned, 100 * 90, "pause {pause_ms} ms");
    }
}

/// A 1 Hz loop (slower than the failsafe) with telemetry flowing: no stop, and the rates are the
/// board's. Then the board goes silent: stopped at the loop's first poll that reads nothing.
#[test]
fn bug2bc_a_one_hertz_loop_is_not_stopped_and_reads_true_rates() {
    let time = Cell::new(0);
    let uart = SimUart::new(Board::new(SimConfig::default()), &time);
    // A clock that only the test moves: each period takes exactly a second.
    let mut d = Driver::new(uart, || time.get(), Config::DEFAULT);
    for second in 1..=20u64 {
        d.set_velocity(Velocity::new(0, 300, 0)).unwrap();
        time.set(second * 1_000);
        while d.poll().unwrap().is_some() {}
        assert_ne!(d.uart().board().motion(), STILL, "stopped at {second} s");
    }
    assert_eq!(d.core().failsafe_stops(), 0);
    let imu = d.core().stream(Stream::Imu).rate_hz();
    let encoders = d.core().stream(Stream::Encoders).rate_hz();
    assert!((99..=101).contains(&imu), "IMU at {imu} Hz");
    assert!((24..=26).contains(&encoders), "encoders at {encoders} Hz");

    d.set_velocity(Velocity::new(0, 300, 0)).unwrap();
    d.uart_mut().board_mut().set_faults(Faults {
        telemetry_stopped: true,
        ..Faults::default()
    });
    // The poll at 21 s still reads the frames sent up to 20 s (the driver cannot tell when
    // bytes it reads in a batch arrived); the first poll that reads nothing stops the chassis.
    for second in 21..=22 {
        time.set(second * 1_000);
        while d.poll().unwrap().is_some() {}
    }
    assert_eq!(d.uart().board().motion(), STILL);
    assert_eq!(d.core().failsafe_stops(), 1);
}

/// A board that goes silent while a fast loop drives is stopped within the failsafe limit.
#[test]
fn bug2_a_silent_board_is_stopped_within_the_limit() {
    let time = Cell::new(0);
    let mut d = sim_driver(&time, SimConfig::default());
    poll_until(&mut d, &time, 200);
    d.set_velocity(Velocity::new(0, 300, 0)).unwrap();
    poll_until(&mut d, &time, 250);
    d.uart_mut().board_mut().set_faults(Faults {
        telemetry_stopped: true,
        ..Faults::default()
    });
    let silent_from = time.get();
    while d.uart().board().motion() != STILL {
        d.poll().unwrap();
        assert!(time.get() - silent_from < 1_000, "no stop");
    }
    let after = time.get() - silent_from;
    // The last IMU frame came up to 10 ms before the silence began, or ended up to 1.3 ms after
    // (it was on the wire); the simulated clock moves 1 ms per reading.
    let limit = u64::from(Config::DEFAULT.failsafe_ms);
    assert!(
        (limit - 10..=limit + 5).contains(&after),
        "stopped after {after} ms"
    );
}

// ----- Bug 3: serde opened the angle hazard -----

#[test]
fn bug3_a_velocity_from_the_network_can_never_turn() {
    // The old postcard form of `Velocity` carried its kept bits: x 0, y 100, z 0, then 0x10,
    // the angle-mode bit. Whatever a message carries, a `Velocity` encodes without it.
    let message = [0x00, 0xC8, 0x01, 0x00, 0x10];
    let velocity: Velocity = postcard::from_bytes(&message).unwrap();
    assert_eq!(velocity, Velocity::new(0, 100, 0));
    assert_eq!(velocity.encode()[9] & 0x10, 0);

    let time = Cell::new(0);
    let mut d = sim_driver(&time, SimConfig::default());
    for _ in 0..10 {
        d.set_velocity(velocity).unwrap();
        poll_until(&mut d, &time, time.get() + 10);
    }
    assert_eq!(d.uart().board().total_turn_commanded(), 0);
    assert!(!d.core().turning());

    // Reserved bits received on the wire are not carried through serde either.
    let received = [0xFF, 0xFE, 0x01, 0, 0, 0, 100, 0, 0, 0b1110_1000];
    let decoded = Velocity::decode(&received).unwrap();
    let mut buf = [0u8; 32];
    let back: Velocity =
        postcard::from_bytes(postcard::to_slice(&decoded, &mut buf).unwrap()).unwrap();
    assert_eq!(back.encode()[9], 0);
}

// ----- Bug 4: settings reads were unverified -----

#[test]
fn bug4_settings_read_on_a_noisy_line_are_right_or_an_error() {
    let time = Cell::new(0);
    let mut d = sim_driver(&time, SimConfig::default());
    d.uart_mut().board_mut().set_faults(Faults {
        corrupt_per_million: 20_000,
        ..Faults::default()
    });
    let (mut right, mut failed) = (0, 0);
    for _ in 0..40 {
        match d.read_settings() {
            Ok(settings) => {
                assert_eq!(&settings, d.uart().board().registers());
                right += 1;
            }
            Err(Error::Core(CoreError::Unconfirmed(_))) => failed += 1,
            Err(e) => panic!("{e:?}"),
        }
        assert!(!d.core().busy());
    }
    assert!(right >= 30, "{right} right, {failed} unconfirmed");
}

#[test]
fn bug4_a_reply_that_does_not_fit_its_register_is_an_error() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::Read(Register::MaxSpeed)).unwrap();
    assert!(core.transmit(0).is_some());
    core.transmitted(10, 0);
    // Max speed is 16 bits: a reply with its high half set is damaged.
    let _ = core.receive(&[0x23, 0x01, 0x00, 0x01, 0x00, 0x00], 1);
    while core.tick(10).is_some() {}
    assert_eq!(
        core.take_outcome(),
        Some(Err(CoreError::Invalid {
            register: Register::MaxSpeed,
            value: 0x0001_0000
        }))
    );
}

// ----- Bug 5: a restore started a 30 s gyro calibration -----

#[test]
fn bug5_restoring_settings_never_starts_a_calibration() {
    let time = Cell::new(0);
    let mut d = sim_driver(&time, SimConfig::default());
    let mut snapshot: Snapshot = FACTORY;
    snapshot.max_speed = 777;
    snapshot.system_mode =
        SystemMode::new(chassis_protocol::DriveType::Omni).with_gyro_compensation(true);
    d.restore_settings(&snapshot).unwrap();
    poll_until(&mut d, &time, time.get() + 50);
    let board = d.uart().board();
    assert!(!board.calibrating());
    assert_eq!(board.registers().max_speed, 777);
    let mode = board.registers().system_mode;
    assert_eq!(mode.drive_type(), chassis_protocol::DriveType::Omni);
    assert!(!mode.gyro_compensation(), "bit 3 left as the board had it");
}

// ----- Bug 6: on a host, the defaults lost frames -----

/// IMU frames received in 5 s with the board's bytes handed over every `burst_ms` (a USB-UART)
/// and the driver reading every `read_every_ms`.
fn imu_frames_through_bursts(config: Config, burst_ms: u64, read_every_ms: u64) -> u32 {
    let time = Cell::new(0);
    let uart = SimUart::new(Board::new(SimConfig::default()), &time).with_bursts(burst_ms);
    let mut d = Driver::new(uart, || time.get(), config);
    let mut now = 0;
    while now < 5_000 {
        now += read_every_ms;
        time.set(now);
        while d.poll().unwrap().is_some() {}
    }
    d.core().stream(Stream::Imu).frames
}

#[test]
fn bug6_host_defaults_lose_no_frame_behind_a_usb_uart() {
    // Burst periods that cut frames apart (an odd number of ms: the simulated board starts its
    // frames on whole, even milliseconds).
    for (burst, read_every) in [(13, 13), (13, 4), (7, 2), (1, 1), (15, 16)] {
        let got = imu_frames_through_bursts(Config::HOST, burst, read_every);
        assert!(
            got >= 495,
            "bursts {burst} ms, reads every {read_every} ms: {got} of 500"
        );
    }
    // What the microcontroller defaults (a 2 ms quiet line) do there: frames are cut apart.
    let cut = imu_frames_through_bursts(Config::DEFAULT, 13, 4);
    assert!(cut < 480, "{cut} of 500");
}

// ----- Bug 7: stop() did not stop a pending turn, nothing cancelled one -----

#[test]
fn bug7_stop_cancels_a_pending_turn() {
    let time = Cell::new(0);
    let mut d = sim_driver(&time, SimConfig::default());
    poll_until(&mut d, &time, 100);
    d.turn_by(900).unwrap();
    poll_until(&mut d, &time, 400);
    let before = d.uart().board().pending_deci_degrees();
    assert!((500..900).contains(&before), "{before}");
    d.stop().unwrap();
    poll_until(&mut d, &time, time.get() + 20);
    let left = d.uart().board().pending_deci_degrees();
    assert!(left.abs() <= 10, "still {left} to turn");
    assert!(!d.core().turning());
    d.turn_by(450).unwrap();
}

// ----- Bug 8: hangs -----

#[test]
fn bug8_a_clock_that_stands_still_cannot_hang_a_read() {
    let time = Cell::new(0);
    let mut uart = SimUart::new(Board::new(SimConfig::default()), &time);
    uart.board_mut().set_faults(Faults {
        replies_stopped: true,
        ..Faults::default()
    });
    let mut d = Driver::new(uart, || 0u64, Config::DEFAULT);
    assert_eq!(
        d.read(reg::MaxSpeed),
        Err(Error::Core(CoreError::ClockStalled))
    );
    assert!(!d.core().busy());
}

/// A serial port whose transmitter never takes a byte.
struct Jammed;

impl serial::ErrorType for Jammed {
    type Error = serial::ErrorKind;
}

impl serial::Read<u8> for Jammed {
    fn read(&mut self) -> nb::Result<u8, serial::ErrorKind> {
        Err(nb::Error::WouldBlock)
    }
}

impl serial::Write<u8> for Jammed {
    fn write(&mut self, _: u8) -> nb::Result<(), serial::ErrorKind> {
        Err(nb::Error::WouldBlock)
    }

    fn flush(&mut self) -> nb::Result<(), serial::ErrorKind> {
        Err(nb::Error::WouldBlock)
    }
}

#[test]
fn bug8_a_transmitter_that_never_drains_is_an_error_not_a_hang() {
    let time = Cell::new(0);
    let mut d = Driver::new(NbSerial::new(Jammed), SimClock(&time), Config::DEFAULT);
    assert_eq!(
        d.set_velocity(Velocity::new(0, 1, 0)),
        Err(Error::Transport(NbError::TxStalled))
    );
}

#[test]
fn bug8_the_async_poll_yields_while_nothing_has_come() {
    let time = Cell::new(0);
    let mut uart = SimUart::new(Board::new(SimConfig::default()), &time);
    uart.board_mut().set_faults(Faults {
        telemetry_stopped: true,
        ..Faults::default()
    });
    let mut d = AsyncDriver::new(uart, SimClock(&time), SimDelay(&time), Config::DEFAULT);
    let mut cx = Context::from_waker(Waker::noop());
    let mut pending = 0;
    for _ in 0..100 {
        let mut poll = pin!(d.poll());
        loop {
            match poll.as_mut().poll(&mut cx) {
                Poll::Pending => pending += 1,
                Poll::Ready(result) => {
                    assert_eq!(result, Ok(None));
                    break;
                }
            }
        }
    }
    // Before: 0 of 10 000 awaits yielded.
    assert!(pending >= 100, "{pending} yields in 100 polls");
}

// ----- Bug 9: NbSerial lost the serial error's kind -----

/// A serial port that reports an overrun once, then works as the simulated board.
struct Overrunning<'t> {
    uart: SimUart<'t>,
    overrun: bool,
}

impl serial::ErrorType for Overrunning<'_> {
    type Error = serial::ErrorKind;
}

impl serial::Read<u8> for Overrunning<'_> {
    fn read(&mut self) -> nb::Result<u8, serial::ErrorKind> {
        if std::mem::take(&mut self.overrun) {
            return Err(nb::Error::Other(serial::ErrorKind::Overrun));
        }
        let mut byte = [0u8];
        match self.uart.read_ready() {
            Ok(true) if self.uart.read(&mut byte) == Ok(1) => Ok(byte[0]),
            _ => Err(nb::Error::WouldBlock),
        }
    }
}

impl serial::Write<u8> for Overrunning<'_> {
    fn write(&mut self, word: u8) -> nb::Result<(), serial::ErrorKind> {
        self.uart
            .write(&[word])
            .map(|_| ())
            .map_err(|e: Infallible| match e {})
    }

    fn flush(&mut self) -> nb::Result<(), serial::ErrorKind> {
        Ok(())
    }
}

#[test]
fn bug9_serial_errors_keep_their_kind_and_the_driver_goes_on() {
    let time = Cell::new(0);
    let port = Overrunning {
        uart: SimUart::new(Board::new(SimConfig::default()), &time),
        overrun: false,
    };
    let mut d = Driver::new(NbSerial::new(port), SimClock(&time), Config::DEFAULT);
    poll_nb(&mut d, &time, 100);
    d.uart_mut().inner_mut().overrun = true;
    let err = loop {
        match d.poll() {
            Err(Error::Transport(e)) => break e,
            Ok(_) => {}
            Err(e) => panic!("{e:?}"),
        }
    };
    assert_eq!(err, NbError::Serial(serial::ErrorKind::Overrun));
    assert_eq!(err.serial_kind(), Some(serial::ErrorKind::Overrun));
    assert_eq!(d.read(reg::MotorVoltage), Ok(1_200));
}

fn poll_nb<S>(d: &mut Driver<NbSerial<S>, SimClock<'_>>, time: &Cell<u64>, until: u64)
where
    S: serial::Read<u8> + serial::Write<u8>,
    S::Error: core::fmt::Debug,
{
    while time.get() < until {
        let _ = d.poll();
    }
}

// ----- Bug 10: the simulator turned at 900°/s -----

#[test]
fn bug10_the_simulator_turns_at_ninety_degrees_a_second() {
    let mut board = Board::new(SimConfig::default());
    board.receive(&chassis_protocol::Turn::by_deci_degrees(900).encode());
    board.advance(500);
    let half = board.pending_deci_degrees();
    assert!((440..=460).contains(&half), "{half} left after 0.5 s");
    board.advance(1_010);
    assert_eq!(board.pending_deci_degrees(), 0);
}

// ----- Requests through the core, as a shell sees them -----

#[test]
fn every_request_ends_with_an_outcome_and_leaves_the_core_free() {
    let time = Cell::new(0);
    let mut d = sim_driver(&time, SimConfig::default());
    let settings = match d.run(Request::ReadSettings).unwrap() {
        Outcome::Snapshot(s) => s,
        other => panic!("{other:?}"),
    };
    assert_eq!(settings, FACTORY);
    assert_eq!(
        d.run(Request::ReadVerified(Register::MotorVoltage)),
        Ok(Outcome::Value(1_200))
    );
    assert_eq!(d.run(Request::RestoreSettings(settings)), Ok(Outcome::Done));
    assert_eq!(d.run(Request::CancelTurn), Ok(Outcome::Done));
    assert!(!d.core().busy());
    assert!(matches!(d.poll(), Ok(None | Some(Event::Telemetry(_)))));
}
