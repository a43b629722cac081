//! Every public async call of the driver (for both firmware generations) cut at every await
//! point, and every blocking call cut
//! by a transport error after every byte count, checked on the simulated board's side: every
//! byte it received belongs to a whole frame the user asked for, in order; no turn was sent
//! twice or lost; a write either reached the board whole or not at all; and the driver's next
//! calls (`stop()`, then a read) work.
//!
//! The frames the board may receive are written here by hand from the spec's tables, and the
//! board's byte stream is cut into frames by a framer written here from the spec (header, mode,
//! length), not by the crate's parsers.

use chassis_protocol::driver::asynch::Driver as AsyncDriver;
use chassis_protocol::driver::blocking::Driver;
use chassis_protocol::driver::{Config, Core, DriverCore, Error, TurnState, reg};
use chassis_protocol::sim::{Board, FACTORY, SimClock, SimConfig, SimDelay, SimUart, Simulated};
use chassis_protocol::{Action, Motors, Velocity, Write};
use core::cell::Cell;
use core::future::Future;
use core::pin::Pin;
use core::task::{Context, Waker};
use embedded_io::ReadReady;

// ----- the frames the board may receive, by hand from the spec -----

/// 1A: velocity y = 300 (0x012C), all directions forward.
const VELOCITY: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x01, 0x2C, 0x00, 0x00, 0x00];
/// 1A: all velocities 0.
const STOP: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00];
/// 1A, angle mode (dir bit 4): +90.0° (900 = 0x0384).
const TURN: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0x00, 0x03, 0x84, 0x10];
/// 1D: motors 100, −100, 100, −100: MOTO2 (dir bit 1) and MOTO4 (bit 3) reverse.
const MOTORS: [u8; 12] = [
    0xFF, 0xFE, 0x02, 0x00, 0x64, 0x00, 0x64, 0x00, 0x64, 0x00, 0x64, 0x0A,
];
/// 2B-1: max speed 800 (0x0320).
const WRITE: [u8; 10] = [0xFF, 0xFE, 0x80, 0x80, 0x01, 0x00, 0x00, 0x03, 0x20, 0x00];
/// 2A: store (save) = action 3.
const STORE: [u8; 10] = [0xFF, 0xFE, 0x80, 0x80, 0x00, 0x80, 0x00, 0x00, 0x03, 0x00];
/// 2B: the factory settings written back by a restore (max speed 1 000, KP 300, KI 20, gyro
/// gain 50 000, system mode mecanum (1), motor 12.00 V, battery range 0x7FFF / 0x7FFF).
const RESTORE_WRITES: [[u8; 10]; 7] = [
    [0xFF, 0xFE, 0x80, 0x80, 0x01, 0x00, 0x00, 0x03, 0xE8, 0x00],
    [0xFF, 0xFE, 0x80, 0x80, 0x06, 0x00, 0x00, 0x01, 0x2C, 0x00],
    [0xFF, 0xFE, 0x80, 0x80, 0x07, 0x00, 0x00, 0x00, 0x14, 0x00],
    [0xFF, 0xFE, 0x80, 0x80, 0x08, 0x00, 0x00, 0xC3, 0x50, 0x00],
    [0xFF, 0xFE, 0x80, 0x80, 0x09, 0x00, 0x00, 0x00, 0x01, 0x00],
    [0xFF, 0xFE, 0x80, 0x80, 0x0B, 0x00, 0x00, 0x04, 0xB0, 0x00],
    [0xFF, 0xFE, 0x80, 0x80, 0x0C, 0x7F, 0xFF, 0x7F, 0xFF, 0x00],
];
/// 2C / 2D read codes: every register of a snapshot, and the pending angle.
const READ_CODES: [u8; 9] = [0x11, 0x16, 0x17, 0x18, 0x19, 0x1A, 0x1B, 0x1C, 0x20];

/// A frame the board received, as the spec's tables frame it.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Frame {
    Velocity,
    Stop,
    Turn,
    /// The opposite of what was pending, in 0.1° (angle mode, Z reverse).
    CounterTurn(u16),
    Motors,
    Write,
    Store,
    Restore(usize),
    Read(u8),
}

/// Cuts the board's byte stream into frames: `FF FE`, then the mode fixes the length (1A–1C
/// 10 bytes, 1D/1E 12, settings 10). Every frame must be one of [`Frame`]'s; anything else
/// (a frame completed by another's bytes, a stray byte, a cut frame at the end) is an error.
fn frames(wire: &[u8]) -> Result<Vec<(usize, Frame)>, String> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < wire.len() {
        let rest = &wire[at..];
        let len = match rest {
            [0xFF, 0xFE, 0x01, ..] | [0xFF, 0xFE, 0x80, ..] => 10,
            [0xFF, 0xFE, 0x02 | 0x03, ..] => 12,
            _ => return Err(format!("no frame starts at byte {at}: {:02X?}", rest)),
        };
        let Some(frame) = rest.get(..len) else {
            return Err(format!(
                "a frame cut at the end, from byte {at}: {rest:02X?}"
            ));
        };
        let known = if frame == VELOCITY {
            Frame::Velocity
        } else if frame == STOP {
            Frame::Stop
        } else if frame == TURN {
            Frame::Turn
        } else if frame == MOTORS {
            Frame::Motors
        } else if frame == WRITE {
            Frame::Write
        } else if frame == STORE {
            Frame::Store
        } else if let Some(i) = RESTORE_WRITES.iter().position(|w| frame == w) {
            Frame::Restore(i)
        } else if let [0xFF, 0xFE, 0x80, 0x80, code, 0, 0, 0, 0, 0] = frame {
            if !READ_CODES.contains(code) {
                return Err(format!("a read of no register at byte {at}: {frame:02X?}"));
            }
            Frame::Read(*code)
        } else if let [0xFF, 0xFE, 0x01, 0, 0, 0, 0, hi, lo, 0x11] = frame {
            let angle = u16::from_be_bytes([*hi, *lo]);
            if angle == 0 || angle > 900 {
                return Err(format!("a counter-turn of {angle} at byte {at}"));
            }
            Frame::CounterTurn(angle)
        } else {
            return Err(format!(
                "a frame nobody asked for at byte {at}: {frame:02X?}"
            ));
        };
        out.push((at, known));
        at += len;
    }
    Ok(out)
}

// ----- the UART doubles -----

/// The simulated board behind a UART whose transmitter takes at most `chunk` bytes a write
/// (a full TX buffer, a DMA chunk), recording what the board received; the async write waits
/// once before it takes anything (the await point a `select` can cut), and its blocking write
/// fails once `fail_at` bytes have been taken (a transport error mid-frame).
struct Choppy<'t, B: Simulated = Board> {
    uart: SimUart<'t, B>,
    wire: Vec<u8>,
    chunk: usize,
    fail_at: Option<usize>,
}

impl<'t> Choppy<'t> {
    fn new(time: &'t Cell<u64>, chunk: usize) -> Self {
        Choppy::with(Board::new(SimConfig::default()), time, chunk)
    }
}

impl<'t, B: Simulated> Choppy<'t, B> {
    fn with(board: B, time: &'t Cell<u64>, chunk: usize) -> Self {
        Choppy {
            uart: SimUart::new(board, time),
            wire: Vec::new(),
            chunk,
            fail_at: None,
        }
    }

    fn take(&mut self, buf: &[u8]) -> usize {
        let mut n = buf.len().min(self.chunk);
        if let Some(at) = self.fail_at {
            n = n.min(at.saturating_sub(self.wire.len()));
        }
        embedded_io::Write::write(&mut self.uart, &buf[..n]).unwrap();
        self.wire.extend_from_slice(&buf[..n]);
        n
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Cut;

impl core::fmt::Display for Cut {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("the line was cut")
    }
}

impl core::error::Error for Cut {}

impl embedded_io::Error for Cut {
    fn kind(&self) -> embedded_io::ErrorKind {
        embedded_io::ErrorKind::BrokenPipe
    }
}

impl<B: Simulated> embedded_io::ErrorType for Choppy<'_, B> {
    type Error = Cut;
}

impl<B: Simulated> embedded_io::Read for Choppy<'_, B> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Cut> {
        Ok(embedded_io::Read::read(&mut self.uart, buf).unwrap())
    }
}

impl<B: Simulated> ReadReady for Choppy<'_, B> {
    fn read_ready(&mut self) -> Result<bool, Cut> {
        Ok(self.uart.read_ready().unwrap())
    }
}

impl<B: Simulated> embedded_io::Write for Choppy<'_, B> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Cut> {
        if self.fail_at.is_some_and(|at| self.wire.len() >= at) && !buf.is_empty() {
            self.fail_at = None;
            return Err(Cut);
        }
        Ok(self.take(buf))
    }

    fn flush(&mut self) -> Result<(), Cut> {
        Ok(())
    }
}

impl<B: Simulated> embedded_io_async::Read for Choppy<'_, B> {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Cut> {
        Ok(embedded_io_async::Read::read(&mut self.uart, buf)
            .await
            .unwrap())
    }
}

impl<B: Simulated> embedded_io_async::Write for Choppy<'_, B> {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Cut> {
        embassy_futures::yield_now().await;
        Ok(self.take(buf))
    }

    async fn flush(&mut self) -> Result<(), Cut> {
        Ok(())
    }
}

// ----- the calls, cut -----

type Boxed<'a> = Pin<Box<dyn Future<Output = Result<(), Error<Cut>>> + 'a>>;
/// `G`'s async driver over the choppy UART.
type AsyncOf<'t, G> = AsyncDriver<
    Choppy<'t, <G as Generation>::Board>,
    SimClock<'t>,
    SimDelay<'t>,
    <G as Generation>::Core,
>;
/// `G`'s blocking driver over the choppy UART.
type BlockingOf<'t, G> =
    Driver<Choppy<'t, <G as Generation>::Board>, SimClock<'t>, <G as Generation>::Core>;

/// A firmware generation as the cut tests drive it: its simulated board and driver core, the
/// calls under test, what is done before a call and after its cut, and the judge of what the
/// board received.
trait Generation: Sized {
    type Board: Simulated;
    type Core: Core;
    type Call: Copy + core::fmt::Debug + 'static;
    /// What the driver showed after the cut (its state, what it read back), for the judge.
    type Seen;
    /// Stands before the call's name in the messages.
    const PREFIX: &'static str;
    /// The calls under test.
    const CALLS: &'static [Self::Call];

    /// A board just powered up.
    fn board() -> Self::Board;
    /// A new driver core.
    fn core() -> Self::Core;
    /// What the async driver is put through before `call` (nothing unless said).
    fn prepare_async(_d: &mut AsyncOf<'_, Self>, _call: Self::Call) {}
    /// What the blocking driver is put through before `call` (nothing unless said).
    fn prepare_blocking(_d: &mut BlockingOf<'_, Self>, _call: Self::Call, _time: &Cell<u64>) {}
    /// `call`, as a future to cut.
    fn call_async<'a>(d: &'a mut AsyncOf<'_, Self>, call: Self::Call) -> Boxed<'a>;
    /// `call`, run to its end or to a transport error.
    fn call_blocking(d: &mut BlockingOf<'_, Self>, call: Self::Call) -> Result<(), Error<Cut>>;
    /// After the cut: what the driver had committed, then a stop and a read, which must work.
    fn follow_up_async(d: &mut AsyncOf<'_, Self>, what: &str) -> Self::Seen;
    /// The same on the blocking driver.
    fn follow_up_blocking(d: &mut BlockingOf<'_, Self>, what: &str, time: &Cell<u64>)
    -> Self::Seen;
    /// Judges what `uart`'s board received after `call` was cut and followed up; the call's
    /// bytes began at `before`.
    fn judge(
        call: Self::Call,
        what: &str,
        uart: &Choppy<'_, Self::Board>,
        before: usize,
        seen: Self::Seen,
    );
}

/// Runs `cut_at(n)` for n = 0, 1, 2, … (polls, or bytes taken) until the call it cuts ran to
/// its end before the cut (`cut_at` returns true): how many runs that took. `what` names the
/// call.
fn every_cut_point(what: &str, mut cut_at: impl FnMut(usize) -> bool) -> usize {
    let mut n = 0;
    loop {
        if cut_at(n) {
            return n + 1;
        }
        assert!(n < 20_000, "{what}: never finished");
        n += 1;
    }
}

/// Every call of `G`'s async driver cut at every await point (dropped after 0, 1, 2, … polls,
/// as a `select` that another branch won would), once for each UART in `chunks` (the bytes it
/// takes a write), each on a new board, followed up and judged: how many cut points.
fn cut_every_async_call<G: Generation>(chunks: [usize; 2]) -> usize {
    let mut cuts = 0;
    for chunk in chunks {
        for &call in G::CALLS {
            let name = format!("{}{call:?}", G::PREFIX);
            cuts += every_cut_point(&format!("{name}, {chunk}-byte writes"), |polls| {
                let time = Cell::new(0);
                let uart = Choppy::with(G::board(), &time, chunk);
                let mut d: AsyncOf<'_, G> =
                    AsyncDriver::from_core(uart, SimClock(&time), SimDelay(&time), G::core());
                G::prepare_async(&mut d, call);
                let before = d.uart().wire.len();
                let finished = {
                    let mut future = G::call_async(&mut d, call);
                    let mut cx = Context::from_waker(Waker::noop());
                    (0..polls).any(|_| future.as_mut().poll(&mut cx).is_ready())
                    // Dropped here, wherever it was.
                };
                let what = format!("{name} after {polls} polls, {chunk}-byte writes");
                let seen = G::follow_up_async(&mut d, &what);
                G::judge(call, &what, d.uart(), before, seen);
                finished
            });
        }
    }
    cuts
}

/// Every call of `G`'s blocking driver cut by a transport error after every byte count (the
/// UART takes 3 bytes a write and fails once the count is reached), each on a new board,
/// followed up and judged: how many cut points.
fn cut_every_blocking_call<G: Generation>() -> usize {
    let mut cuts = 0;
    for &call in G::CALLS {
        let name = format!("{}{call:?}", G::PREFIX);
        cuts += every_cut_point(&name, |at| {
            let time = Cell::new(0);
            let uart = Choppy::with(G::board(), &time, 3);
            let mut d: BlockingOf<'_, G> = Driver::from_core(uart, SimClock(&time), G::core());
            G::prepare_blocking(&mut d, call, &time);
            let before = d.uart().wire.len();
            d.uart_mut().fail_at = Some(before + at);
            let result = G::call_blocking(&mut d, call);
            let cut = d.uart().fail_at.is_none();
            d.uart_mut().fail_at = None;
            if cut {
                assert_eq!(result, Err(Error::Transport(Cut)), "{name} cut at {at}");
            }
            let what = format!("{name} cut at byte {at}");
            let seen = G::follow_up_blocking(&mut d, &what, &time);
            G::judge(call, &what, d.uart(), before, seen);
            !cut
        });
    }
    cuts
}

// ----- the 2020 board -----

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Call {
    SetVelocity,
    SetMotors,
    Turn,
    TurnOnANewDriver,
    StopWhileTurning,
    Read,
    ReadVerified,
    ReadRaw,
    TurnRemaining,
    Write,
    Action,
    ReadSettings,
    RestoreSettings,
    Poll,
}

type Async<'t> = AsyncOf<'t, V2020>;
type Blocking<'t> = BlockingOf<'t, V2020>;

/// The 2020 firmware, over `DriverCore`.
struct V2020;

/// What the 2020 driver showed after the cut.
struct Seen2020 {
    /// Whether the driver had committed the call's turn when it was cut.
    turn_committed: bool,
    /// Max speed, read after the stop.
    max_speed_read: u16,
}

/// Whether the driver had committed the call's turn (90.0°).
fn turn_committed(core: &DriverCore) -> bool {
    matches!(core.turn_state(), TurnState::Turning { deci_degrees: 900 })
}

impl Generation for V2020 {
    type Board = Board;
    type Core = DriverCore;
    type Call = Call;
    type Seen = Seen2020;
    const PREFIX: &'static str = "";
    const CALLS: &'static [Call] = &[
        Call::SetVelocity,
        Call::SetMotors,
        Call::Turn,
        Call::TurnOnANewDriver,
        Call::StopWhileTurning,
        Call::Read,
        Call::ReadVerified,
        Call::ReadRaw,
        Call::TurnRemaining,
        Call::Write,
        Call::Action,
        Call::ReadSettings,
        Call::RestoreSettings,
        Call::Poll,
    ];

    fn board() -> Board {
        Board::new(SimConfig::default())
    }

    fn core() -> DriverCore {
        DriverCore::new(Config::DEFAULT)
    }

    /// The pending angle read (so a turn may go), and for a stop, a turn to cancel.
    fn prepare_async(d: &mut Async<'_>, call: Call) {
        if call == Call::TurnOnANewDriver {
            return;
        }
        embassy_futures::block_on(d.turn_remaining()).unwrap();
        if call == Call::StopWhileTurning {
            embassy_futures::block_on(d.turn_by(900)).unwrap();
            embassy_futures::block_on(async {
                for _ in 0..30 {
                    d.poll().await.unwrap();
                }
            });
        }
    }

    fn prepare_blocking(d: &mut Blocking<'_>, call: Call, time: &Cell<u64>) {
        if call == Call::TurnOnANewDriver {
            return;
        }
        d.turn_remaining().unwrap();
        if call == Call::StopWhileTurning {
            d.turn_by(900).unwrap();
            let until = time.get() + 300;
            while time.get() < until {
                d.poll().unwrap();
            }
        }
    }

    fn call_async<'a>(d: &'a mut Async<'_>, call: Call) -> Boxed<'a> {
        match call {
            Call::SetVelocity => Box::pin(d.set_velocity(Velocity::new(0, 300, 0))),
            Call::SetMotors => Box::pin(d.set_motors(Motors::closed_loop([100, -100, 100, -100]))),
            Call::Turn | Call::TurnOnANewDriver => Box::pin(d.turn_by(900)),
            Call::StopWhileTurning => Box::pin(d.stop()),
            Call::Read => Box::pin(async { d.read(reg::MaxSpeed).await.map(|_| ()) }),
            Call::ReadVerified => {
                Box::pin(async { d.read_verified(reg::GyroGain).await.map(|_| ()) })
            }
            Call::ReadRaw => Box::pin(async {
                d.read_raw(chassis_protocol::Register::SpeedKp)
                    .await
                    .map(|_| ())
            }),
            Call::TurnRemaining => Box::pin(async { d.turn_remaining().await.map(|_| ()) }),
            Call::Write => Box::pin(d.write(Write::MaxSpeed(800))),
            Call::Action => Box::pin(d.action(Action::Store)),
            Call::ReadSettings => Box::pin(async { d.read_settings().await.map(|_| ()) }),
            Call::RestoreSettings => Box::pin(d.restore_settings(&FACTORY)),
            Call::Poll => Box::pin(async { d.poll().await.map(|_| ()) }),
        }
    }

    fn call_blocking(d: &mut Blocking<'_>, call: Call) -> Result<(), Error<Cut>> {
        match call {
            Call::SetVelocity => d.set_velocity(Velocity::new(0, 300, 0)),
            Call::SetMotors => d.set_motors(Motors::closed_loop([100, -100, 100, -100])),
            Call::Turn | Call::TurnOnANewDriver => d.turn_by(900),
            Call::StopWhileTurning => d.stop(),
            Call::Read => d.read(reg::MaxSpeed).map(|_| ()),
            Call::ReadVerified => d.read_verified(reg::GyroGain).map(|_| ()),
            Call::ReadRaw => d.read_raw(chassis_protocol::Register::SpeedKp).map(|_| ()),
            Call::TurnRemaining => d.turn_remaining().map(|_| ()),
            Call::Write => d.write(Write::MaxSpeed(800)),
            Call::Action => d.action(Action::Store),
            Call::ReadSettings => d.read_settings().map(|_| ()),
            Call::RestoreSettings => d.restore_settings(&FACTORY),
            Call::Poll => d.poll().map(|_| ()),
        }
    }

    fn follow_up_async(d: &mut Async<'_>, what: &str) -> Seen2020 {
        let turn_committed = turn_committed(d.core());
        embassy_futures::block_on(d.stop()).unwrap_or_else(|e| panic!("{what}: stop: {e:?}"));
        let max_speed_read = embassy_futures::block_on(d.read(reg::MaxSpeed))
            .unwrap_or_else(|e| panic!("{what}: read after: {e:?}"));
        // Let the board finish what it was told (a counter-turn's last degrees).
        embassy_futures::block_on(async {
            for _ in 0..200 {
                d.poll().await.unwrap();
            }
        });
        Seen2020 {
            turn_committed,
            max_speed_read,
        }
    }

    fn follow_up_blocking(d: &mut Blocking<'_>, what: &str, time: &Cell<u64>) -> Seen2020 {
        let turn_committed = turn_committed(d.core());
        d.stop().unwrap_or_else(|e| panic!("{what}: stop: {e:?}"));
        let max_speed_read = d
            .read(reg::MaxSpeed)
            .unwrap_or_else(|e| panic!("{what}: read after: {e:?}"));
        let until = time.get() + 300;
        while time.get() < until {
            d.poll().unwrap();
        }
        Seen2020 {
            turn_committed,
            max_speed_read,
        }
    }

    fn judge(call: Call, what: &str, uart: &Choppy<'_>, before: usize, seen: Seen2020) {
        Verdict {
            call,
            what,
            wire: &uart.wire,
            before,
            turn_committed: seen.turn_committed,
            board: uart.uart.board(),
            max_speed_read: seen.max_speed_read,
        }
        .check();
    }
}

/// What the board received and what the driver did, judged.
struct Verdict<'a> {
    call: Call,
    /// The call and where it was cut, for the messages.
    what: &'a str,
    wire: &'a [u8],
    /// Bytes on the wire before the call under test.
    before: usize,
    /// Whether the driver had committed the call's turn when it was cut.
    turn_committed: bool,
    board: &'a Board,
    max_speed_read: u16,
}

impl Verdict<'_> {
    fn check(&self) {
        let what = self.what;
        let frames = frames(self.wire).unwrap_or_else(|e| panic!("{what}: {e}"));
        let count = |f: &Frame| frames.iter().filter(|(_, g)| g == f).count();
        // Only whole frames: the board executed one command per frame, none made of two.
        assert_eq!(
            self.board.commands() as usize,
            frames.len(),
            "{what}: the board executed another count of commands than whole frames sent"
        );
        // A turn is sent once, and only if the driver took it; never lost once taken.
        let turns = count(&Frame::Turn);
        let expected_turns = match self.call {
            Call::StopWhileTurning => 1,
            Call::Turn | Call::TurnOnANewDriver => usize::from(self.turn_committed),
            _ => 0,
        };
        assert_eq!(turns, expected_turns, "{what}: turns sent");
        // A turn the board received is cancelled or done: never more than 90° in all.
        assert!(
            (0..=900).contains(&self.board.total_turn_commanded()),
            "{what}: {} turned in all",
            self.board.total_turn_commanded()
        );
        // A write reached the board whole or not at all, as the read after it shows.
        let wrote = count(&Frame::Write) == 1;
        assert_eq!(
            self.max_speed_read,
            if wrote { 800 } else { FACTORY.max_speed },
            "{what}: max speed read back"
        );
        // In order: the stop that follows the cut call comes after every frame the cut call
        // began, and the frames before the call are the preparation's.
        let last_stop = frames
            .iter()
            .rposition(|(_, f)| *f == Frame::Stop)
            .unwrap_or_else(|| panic!("{what}: no stop after the call"));
        for (at, f) in &frames[last_stop + 1..] {
            assert!(
                matches!(f, Frame::Read(_) | Frame::CounterTurn(_)),
                "{what}: {f:?} at byte {at} after the stop"
            );
        }
        assert!(
            frames.iter().any(|(at, _)| *at == self.before) || self.before == self.wire.len(),
            "{what}: the call's bytes do not start on a frame boundary"
        );
        // The chassis stands still at the end.
        assert_eq!(
            self.board.motion(),
            chassis_protocol::sim::Motion::Velocity { x: 0, y: 0, z: 0 },
            "{what}"
        );
    }
}

#[test]
fn every_async_call_cut_at_every_await_point_leaves_only_whole_frames_and_a_working_driver() {
    let cuts = cut_every_async_call::<V2020>([1, 3]);
    assert!(cuts > 600, "{cuts} cut points");
}

#[test]
fn every_blocking_call_cut_by_a_transport_error_after_every_byte_leaves_only_whole_frames() {
    let cuts = cut_every_blocking_call::<V2020>();
    assert!(cuts > 100, "{cuts} cut points");
}

/// The case: a half-sent turn, then `stop()`: before, `stop()` returned `Ok` and the
/// board spun at z = 65025.
#[test]
fn a_half_sent_turn_then_stop_never_spins_the_board() {
    let time = Cell::new(0);
    let mut d = Async::new(
        Choppy::new(&time, 3),
        SimClock(&time),
        SimDelay(&time),
        Config::DEFAULT,
    );
    embassy_futures::block_on(d.turn_remaining()).unwrap();
    let before = d.uart().wire.len();
    let mut cx = Context::from_waker(Waker::noop());
    {
        let mut turn = Box::pin(d.turn_by(900));
        // Two polls: one wait; three bytes taken and the next wait.
        for _ in 0..2 {
            assert!(turn.as_mut().poll(&mut cx).is_pending());
        }
    }
    assert_eq!(d.uart().wire.len() - before, 3, "cut after three bytes");
    embassy_futures::block_on(d.stop()).unwrap();
    let wire = &d.uart().wire[before..];
    assert_eq!(&wire[..10], TURN, "the turn finished whole");
    assert_eq!(&wire[10..20], STOP, "then the stop");
    let board = d.uart().uart.board();
    assert_eq!(
        board.motion(),
        chassis_protocol::sim::Motion::Velocity { x: 0, y: 0, z: 0 }
    );
}

// ----- the v1.0.0 board: the same shells over `driver::v1::DriverCore` -----

mod v1_board {
    use super::*;
    use chassis_protocol::driver::v1::{DriverCore, Settings};
    use chassis_protocol::sim::v1::{Board as V1Board, SimConfig as V1Config};
    use chassis_protocol::v1::{BodyVelocity, Geometry, MotorVelocity, Readback};

    // The frames a v1.0.0 board may receive, by hand from `docs/protocol-v1.md` (BCC = XOR of the
    // bytes before it, worked out by hand).

    /// `0x25`: vx 0, vy 300 mm/s (0x012C), wz 0, ctl 2, type 4.
    const VELOCITY: [u8; 14] = [
        0x7B, 0x25, 0x02, 0x04, 0x00, 0x00, 0x01, 0x2C, 0x00, 0x00, 0x00, 0x00, 0x75, 0x7D,
    ];
    /// `0x25` forced stop: ctl 0, all zeros.
    const FORCED_STOP: [u8; 14] = [
        0x7B, 0x25, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x5E, 0x7D,
    ];
    /// `0x26`: motors 100, −100, 100, −100 (FF9C), ctl 2, type 4.
    const MOTORS: [u8; 14] = [
        0x7B, 0x26, 0x02, 0x04, 0x00, 0x64, 0xFF, 0x9C, 0x00, 0x64, 0xFF, 0x9C, 0x5B, 0x7D,
    ];
    /// `0x24`: wheel spacing 120 (0x78), axle spacing 110 (0x6E), gear 55 (0x37), wheel 60
    /// (0x3C).
    const GEOMETRY: [u8; 14] = [
        0x7B, 0x24, 0x00, 0x78, 0x00, 0x6E, 0x00, 0x37, 0x00, 0x3C, 0x00, 0x00, 0x42, 0x7D,
    ];
    /// Readback requests and their BCC (`7B ^ code`).
    const READBACKS: [(u8, u8); 5] = [
        (0x33, 0x48),
        (0x34, 0x4F),
        (0x35, 0x4E),
        (0x36, 0x4D),
        (0x50, 0x2B),
    ];

    #[derive(Clone, Debug, PartialEq, Eq)]
    enum Frame {
        Velocity,
        Stop,
        Motors,
        Geometry,
        Readback(u8),
    }

    /// Cuts the board's byte stream into 14-byte frames; each must be one of [`Frame`]'s.
    fn frames(wire: &[u8]) -> Result<Vec<(usize, Frame)>, String> {
        let mut out = Vec::new();
        for (i, frame) in wire.chunks(14).enumerate() {
            let at = i * 14;
            let known = if frame == VELOCITY {
                Frame::Velocity
            } else if frame == FORCED_STOP {
                Frame::Stop
            } else if frame == MOTORS {
                Frame::Motors
            } else if frame == GEOMETRY {
                Frame::Geometry
            } else if let [0x7B, code, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, bcc, 0x7D] = frame {
                if !READBACKS.contains(&(*code, *bcc)) {
                    return Err(format!("no readback at byte {at}: {frame:02X?}"));
                }
                Frame::Readback(*code)
            } else {
                return Err(format!(
                    "a frame nobody asked for (or cut) at byte {at}: {frame:02X?}"
                ));
            };
            out.push((at, known));
        }
        Ok(out)
    }

    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    enum Call {
        SetVelocity,
        SetMotors,
        Readback,
        Geometry,
        WriteSettings,
        Stop,
        Poll,
    }

    const WIDER: Geometry = Geometry {
        wheel_spacing_mm: 120,
        axle_spacing_mm: 110,
        gear_ratio: 55,
        wheel_diameter_mm: 60,
    };

    /// The v1.0.0 firmware, over `driver::v1::DriverCore`.
    struct V1;

    impl Generation for V1 {
        type Board = V1Board;
        type Core = DriverCore;
        type Call = Call;
        /// The wheel spacing read back after the stop.
        type Seen = u16;
        const PREFIX: &'static str = "v1 ";
        const CALLS: &'static [Call] = &[
            Call::SetVelocity,
            Call::SetMotors,
            Call::Readback,
            Call::Geometry,
            Call::WriteSettings,
            Call::Stop,
            Call::Poll,
        ];

        fn board() -> V1Board {
            V1Board::new(V1Config::default())
        }

        fn core() -> DriverCore {
            DriverCore::new(Config::DEFAULT)
        }

        fn call_async<'a>(d: &'a mut AsyncOf<'_, V1>, call: Call) -> Boxed<'a> {
            match call {
                Call::SetVelocity => Box::pin(d.set_velocity(BodyVelocity::new(0, 300, 0))),
                Call::SetMotors => {
                    Box::pin(d.set_motors(MotorVelocity::new([100, -100, 100, -100])))
                }
                Call::Readback => {
                    Box::pin(async { d.readback(Readback::MotorSpeeds).await.map(|_| ()) })
                }
                Call::Geometry => {
                    Box::pin(async { d.readback(Readback::Geometry).await.map(|_| ()) })
                }
                Call::WriteSettings => Box::pin(d.write_settings(Settings::Geometry(WIDER))),
                Call::Stop => Box::pin(d.stop()),
                Call::Poll => Box::pin(async { d.poll().await.map(|_| ()) }),
            }
        }

        fn call_blocking(d: &mut BlockingOf<'_, V1>, call: Call) -> Result<(), Error<Cut>> {
            match call {
                Call::SetVelocity => d.set_velocity(BodyVelocity::new(0, 300, 0)),
                Call::SetMotors => d.set_motors(MotorVelocity::new([100, -100, 100, -100])),
                Call::Readback => d.readback(Readback::MotorSpeeds).map(|_| ()),
                Call::Geometry => d.geometry().map(|_| ()),
                Call::WriteSettings => d.write_settings(Settings::Geometry(WIDER)),
                Call::Stop => d.stop(),
                Call::Poll => d.poll().map(|_| ()),
            }
        }

        fn follow_up_async(d: &mut AsyncOf<'_, V1>, what: &str) -> u16 {
            embassy_futures::block_on(d.stop()).unwrap_or_else(|e| panic!("{what}: stop: {e:?}"));
            embassy_futures::block_on(d.readback(Readback::Geometry))
                .unwrap_or_else(|e| panic!("{what}: read after: {e:?}"))
                .geometry()
                .unwrap()
                .wheel_spacing_mm
        }

        fn follow_up_blocking(d: &mut BlockingOf<'_, V1>, what: &str, _time: &Cell<u64>) -> u16 {
            d.stop().unwrap_or_else(|e| panic!("{what}: stop: {e:?}"));
            d.geometry()
                .unwrap_or_else(|e| panic!("{what}: read after: {e:?}"))
                .wheel_spacing_mm
        }

        /// Judges what the board received: only whole frames, each one the board executed; the
        /// settings write reached it whole or not at all (the readback after says which); a
        /// forced stop after the call and only readbacks after it; the chassis still at the
        /// end.
        fn judge(
            _call: Call,
            what: &str,
            uart: &Choppy<'_, V1Board>,
            before: usize,
            wheel_spacing_read: u16,
        ) {
            let frames = frames(&uart.wire).unwrap_or_else(|e| panic!("{what}: {e}"));
            let board = uart.uart.board();
            assert_eq!(
                board.total_commands() as usize,
                frames.len(),
                "{what}: the board took another count of frames than whole frames sent"
            );
            let wrote = frames.iter().any(|(_, f)| *f == Frame::Geometry);
            assert_eq!(
                wheel_spacing_read,
                if wrote { 120 } else { 110 },
                "{what}: the geometry read back"
            );
            let last_stop = frames
                .iter()
                .rposition(|(_, f)| *f == Frame::Stop)
                .unwrap_or_else(|| panic!("{what}: no forced stop after the call"));
            for (at, f) in &frames[last_stop + 1..] {
                assert!(
                    matches!(f, Frame::Readback(_)),
                    "{what}: {f:?} at byte {at} after the stop"
                );
            }
            assert!(
                before.is_multiple_of(14),
                "{what}: the call's bytes do not start on a frame boundary"
            );
            assert_eq!(board.velocity(), BodyVelocity::FORCED_STOP, "{what}");
        }
    }

    #[test]
    fn every_v1_async_call_cut_at_every_await_point_leaves_only_whole_frames_and_a_working_driver()
    {
        let cuts = cut_every_async_call::<V1>([1, 5]);
        assert!(cuts > 100, "{cuts} cut points");
    }

    #[test]
    fn every_v1_blocking_call_cut_by_a_transport_error_after_every_byte_leaves_only_whole_frames() {
        let cuts = cut_every_blocking_call::<V1>();
        assert!(cuts > 50, "{cuts} cut points");
    }
}
