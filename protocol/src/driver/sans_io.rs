//! [`DriverCore`]: every policy of the driver, with no I/O and no clock.
//!
//! The shells ([`blocking`](super::blocking), [`asynch`](super::asynch)) only move bytes and
//! time between a UART and this core; everything that decides lives here, once:
//!
//! * **Frames out, whole and in order.** Every frame (motion, settings, a request's reads, the
//!   failsafe's stop) is put in the core's one-frame slot and handed out by
//!   [`DriverCore::transmit`]; the UART's progress comes back through
//!   [`DriverCore::transmitted`]. A write cut short leaves the rest in the slot, and nothing
//!   else goes out before it is finished. The wire-independent part of the policy (this slot,
//!   the failsafe, time, stall bounds) is `safety.rs`, generic over the wire format.
//! * **Requests** that need replies ([`Request`]) run as a state machine: the core queues their
//!   frames, matches replies as they come ([`DriverCore::receive`]), times out and retries
//!   ([`DriverCore::tick`]), and leaves one [`Outcome`] or [`CoreError`] to take
//!   ([`DriverCore::take_outcome`]). One request at a time; [`DriverCore::abort`] ends one early
//!   (a transport error, a dropped future).
//! * **Late replies never answer a later read.** A read that went unanswered leaves a *ghost*:
//!   its reply may still come. Until it does, or [`Config::late_reply_ms`] has passed, a read of
//!   the same register is not sent (the two replies could not be told apart), and a reply
//!   carrying the ghost's code is taken as the late one. A late reply teaches the core the
//!   board's real latency: later reads wait that long (at most [`Config::late_reply_ms`] more).
//! * **The failsafe**, the quiet-line detection, reply timeouts and the turn guard are judged in
//!   [`DriverCore::tick`], which a shell calls once it has read everything the UART holds.
//!
//! # The failsafe in one sentence
//!
//! While the driver has the chassis moving, it sends STOP when it has heard **no frame** from
//! the board (telemetry or reply) for [`Config::failsafe_ms`] (100 ms), except that after a
//! settings frame the board may stay silent for [`Config::settings_pause_ms`] (600 ms), since it
//! pauses telemetry while settings are made (A13: up to at least 500 ms), until its telemetry
//! comes back (the pause is then over: from there on, 100 ms of silence is a dead link). For a
//! read, "comes back" counts only telemetry after the reply: the board answers when it takes the
//! read, so frames heard before the reply were on their way before the pause began.
//!
//! It is judged on the input already read: a shell calls [`DriverCore::tick`] only after taking
//! in every byte the UART holds, so a slow loop never mistakes its own slowness for a dead link.
//!
//! # A turn when the link dies
//!
//! The board adds angles up and turns until what it was told is done; a stop frame does not end
//! a turn, and only the opposite angle cancels it, which needs the angle still pending. When the
//! failsafe stops the chassis with a turn outstanding, the core keeps asking for the pending
//! angle ([`Request::CancelTurn`], in the background: a request the user starts takes
//! precedence) until a reply comes, and then sends the opposite of what is left. So the chassis
//! turns **at most the angle it was told**, and stops turning at the first reply after the link
//! is back; the turn guard holds until the board says the turn is over.

use super::safety::{FrameKind, Safety, Wire};
use super::{Config, CoreError};
use crate::bytes::FrameBytes;
use crate::command::{Action, Motors, Register, Setting, Turn, Velocity, Write};
use crate::parse::{DownlinkParser, DownlinkStats, Lock};
use crate::registers::{self, Snapshot};
use crate::telemetry::{Battery, Downlink, Encoders, Imu, Reply, Stream};

/// The bytes of one command frame (10 or 12 bytes).
pub type Outgoing = FrameBytes<12>;

/// The 2020 firmware's wire format (`FF FE` frames) for the wire-independent policy.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) enum Ff {}

impl Wire for Ff {
    type Frame = Outgoing;

    fn stop() -> Outgoing {
        Outgoing::new(&Velocity::STOP.encode())
    }
}

/// A value and the time the driver received it.
///
/// The time is when the bytes reached the core, on the core's clock ([`DriverCore::now_ms`]:
/// your clock's readings while it runs forward, and monotonic whatever it does): the arrival
/// time when a runner or an interrupt feeds the core as bytes come, the time of the read when a
/// slow loop reads a batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stamped<T> {
    /// The value.
    pub value: T,
    /// When it was received, in ms.
    pub at_ms: u64,
}

/// What the driver knows of one telemetry stream.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StreamInfo {
    /// Frames received.
    pub frames: u32,
    /// Frames missing according to the count bytes.
    pub missed: u32,
    /// Frames per second over the last window of at least [`StreamInfo::WINDOW_MS`], in
    /// thousandths (0 until a window has closed).
    pub rate_millihertz: u32,
    window_start_ms: Option<u64>,
    window_frames: u32,
}

impl StreamInfo {
    /// The rate is counted over windows at least this long, so that frames read in batches (a
    /// slow loop, a USB-UART) still give the stream's real rate.
    pub const WINDOW_MS: u64 = 1_000;

    /// Frames per second (rounded down; 0 until a window has closed).
    #[must_use]
    pub const fn rate_hz(&self) -> u32 {
        self.rate_millihertz / 1_000
    }

    /// Nothing received yet.
    pub(crate) const fn new() -> Self {
        StreamInfo {
            frames: 0,
            missed: 0,
            rate_millihertz: 0,
            window_start_ms: None,
            window_frames: 0,
        }
    }

    pub(crate) fn arrived(&mut self, at_ms: u64, missed: u32) {
        self.frames = self.frames.wrapping_add(1);
        self.missed = missed;
        let Some(start) = self.window_start_ms else {
            self.window_start_ms = Some(at_ms);
            return;
        };
        self.window_frames = self.window_frames.saturating_add(1);
        let span = at_ms.saturating_sub(start);
        if span >= Self::WINDOW_MS {
            // In 32 bits (a Cortex-M divides those in hardware; 64-bit division is a library
            // routine): a window closes at its first frame after a second, so it never holds
            // the 4 295 frames that would saturate.
            let span = u32::try_from(span).unwrap_or(u32::MAX);
            self.rate_millihertz = self
                .window_frames
                .saturating_mul(1_000_000)
                .checked_div(span)
                .unwrap_or(0);
            self.window_start_ms = Some(at_ms);
            self.window_frames = 0;
        }
    }
}

/// A frame the user sends without a request ([`DriverCore::user_frame`]).
#[derive(Clone, Copy, Debug)]
pub(crate) enum UserFrame {
    /// [`DriverCore::velocity`].
    Velocity(Velocity),
    /// [`DriverCore::motors`].
    Motors(Motors),
    /// [`DriverCore::write`].
    Write(Write),
    /// [`DriverCore::action`].
    Action(Action),
}

/// Something the core saw on the line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// A telemetry frame (also kept as the latest of its stream).
    Telemetry(Downlink),
    /// A reply that the request in progress was waiting for.
    Reply(Reply),
    /// A reply nobody waits for (a late one, or a damaged one).
    StrayReply(Reply),
}

/// Something to do that needs the board's replies: started with [`DriverCore::start`], finished
/// with an [`Outcome`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Request {
    /// One read, one reply: [`Outcome::Value`]. A reply of another register is
    /// [`CoreError::WrongReply`]; none in time, [`CoreError::Timeout`].
    Read(Register),
    /// Reads until two replies agree ([`Config::read_tries`] reads at most), retrying after a
    /// timeout or a wrong reply; a reply whose value cannot be the register's is not counted.
    /// There is no checksum: a changed byte changes a reply unseen, and this is how a value
    /// that matters is read. [`Outcome::Value`], or [`CoreError::Unconfirmed`].
    ReadVerified(Register),
    /// Every register of a [`Snapshot`], each read verified: [`Outcome::Snapshot`].
    ReadSettings,
    /// Writes a snapshot back (all but the calibration value: [`Snapshot::writes`]). The
    /// system mode's gyro-compensation bit (3) is left as the board has it (read first):
    /// switching it on starts a 30 s calibration, which a restore must never do by surprise.
    /// [`Outcome::Done`].
    RestoreSettings(Snapshot),
    /// Cancels a turn in progress: reads the angle still pending and sends the opposite turn,
    /// then releases the turn guard. [`Outcome::Done`].
    CancelTurn,
}

/// How a [`Request`] ended well.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Outcome {
    /// A register's raw value (see [`crate::registers::Readable`] for its type).
    Value(u32),
    /// A whole snapshot.
    Snapshot(Snapshot),
    /// Done: nothing to return.
    Done,
}

/// What the driver knows of a turn: the board adds angles up, so a new turn is sent only when
/// the board is known to have none pending.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TurnState {
    /// Not known yet: a new core has not read the pending angle (an earlier program, or an
    /// earlier driver, may have left the board turning). The shells read it before the first
    /// turn.
    Unknown,
    /// No turn pending: a turn may be sent.
    Idle,
    /// A turn is outstanding.
    Turning {
        /// The angle it was sent with (or, found pending, the angle read), in 0.1°.
        deci_degrees: i32,
    },
}

/// Bytes read from the UART but not yet through the core: kept in the core, so that nothing is
/// dropped when an event comes out mid-read, and nothing is lost when a driver is rebuilt.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct RxBuffer {
    bytes: [u8; RxBuffer::LEN],
    start: usize,
    end: usize,
}

impl RxBuffer {
    /// Bytes read from the UART at a time.
    pub(crate) const LEN: usize = 32;

    pub(crate) const fn new() -> Self {
        RxBuffer {
            bytes: [0; Self::LEN],
            start: 0,
            end: 0,
        }
    }

    pub(crate) const fn is_empty(&self) -> bool {
        self.start >= self.end
    }

    /// Where the UART is read into.
    pub(crate) fn space(&mut self) -> &mut [u8] {
        &mut self.bytes
    }

    /// `n` bytes were read into [`space`](Self::space).
    pub(crate) fn filled(&mut self, n: usize) {
        self.start = 0;
        self.end = n.min(Self::LEN);
    }

    /// The bytes read and not yet consumed.
    pub(crate) fn pending(&self) -> &[u8] {
        self.bytes.get(self.start..self.end).unwrap_or(&[])
    }

    /// Of the pending bytes, `rest` are left.
    pub(crate) fn left(&mut self, rest: usize) {
        self.start = self.end.saturating_sub(rest);
    }
}

/// How a read's replies are judged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Check {
    /// One reply, taken as it is (a wrong or unfitting one is an error).
    Once,
    /// Two replies that agree.
    Agree,
    /// One reply that can be the answer: the pending angle of a turn being cancelled, which
    /// changes while it is read (so two reads cannot agree) but must lie between 0 and the turn.
    Plausible,
}

/// Where a read is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Phase {
    /// Still to send.
    ToSend,
    /// In the slot: its bytes are going out.
    Sending,
    /// Its last byte left at `sent_ms`; its reply is awaited until `deadline_ms`.
    Waiting { sent_ms: u64, deadline_ms: u64 },
}

/// The read in flight, if any.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Read {
    register: Register,
    check: Check,
    phase: Phase,
    /// Reads sent so far.
    tries: u8,
    /// Values seen so far (verified reads), most recent first.
    seen: [Option<u32>; 2],
}

impl Read {
    const fn new(register: Register, check: Check) -> Self {
        Read {
            register,
            check,
            phase: Phase::ToSend,
            tries: 0,
            seen: [None, None],
        }
    }
}

/// A read that went unanswered: its reply may still come, until `until_ms`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Ghost {
    register: Register,
    sent_ms: u64,
    until_ms: u64,
}

/// Unanswered reads remembered at once.
const GHOSTS: usize = 4;

/// What a request is doing now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Step {
    /// A read (sent or to send).
    Read(Read),
    /// A write to send (restore), then the next step.
    Write(Write),
    /// The opposite turn to send (cancel), in 0.1°.
    CounterTurn(i32),
}

/// The request in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Job {
    request: Request,
    step: Step,
    /// Which step of the request's sequence this is.
    index: u8,
    /// Registers read so far (ReadSettings).
    settings: Snapshot,
    /// Started by the core itself (the failsafe's turn cancel): nobody takes its outcome, and
    /// a request the user starts ends it.
    background: bool,
}

/// The driver's logic: frames out, telemetry in, requests and their replies, timeouts and
/// retries, the failsafe and the one-shot turn guard. No I/O, no clock: bytes and the time in ms
/// come in as arguments, bytes to send come out.
///
/// ```
/// use chassis_protocol::driver::{Config, DriverCore, Outcome, Request};
/// use chassis_protocol::{Register, Reply};
///
/// let mut core = DriverCore::new(Config::DEFAULT);
/// core.start(Request::Read(Register::MotorVoltage))?;
/// let frame = core.transmit(0).unwrap(); // the read, to write to the UART
/// assert_eq!(frame, [0xFF, 0xFE, 0x80, 0x80, 0x1B, 0, 0, 0, 0, 0]);
/// core.transmitted(10, 0); // the UART took all ten bytes
/// // The reply comes; the line goes quiet, which ends it.
/// let _ = core.receive(&[0x23, 0x0B, 0x00, 0x00, 0x04, 0xB0], 3);
/// while core.tick(10).is_some() {}
/// assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(1_200))));
/// # Ok::<(), chassis_protocol::driver::CoreError>(())
/// ```
#[derive(Clone, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriverCore {
    config: Config,
    parser: DownlinkParser,
    safety: Safety<Ff>,
    rx: RxBuffer,
    job: Option<Job>,
    outcome: Option<Result<Outcome, CoreError>>,
    imu: Option<Stamped<Imu>>,
    encoders: Option<Stamped<Encoders>>,
    battery: Option<Stamped<Battery>>,
    streams: [StreamInfo; 3],
    last_byte_ms: Option<u64>,
    /// Quiet time has been reported to the parser up to this time.
    quiet_reported_ms: Option<u64>,
    turn: TurnState,
    /// The failsafe stopped the chassis with a turn outstanding: cancel it as soon as the board
    /// answers.
    cancel_wanted: bool,
    ghosts: [Option<Ghost>; GHOSTS],
    /// The longest round trip of a late reply: later reads wait for it.
    late_rtt_ms: u32,
}

// RAM budget of the core (the parser 220 bytes with its 96-byte window, the request in
// progress 104, the receive buffer 48, the frame being sent and the failsafe's timers, the
// unanswered reads 96, latest frames, stream figures): 912 bytes on 64-bit hosts.
const _: () = assert!(
    core::mem::size_of::<DriverCore>() <= 912,
    "DriverCore over its RAM budget"
);

impl DriverCore {
    /// A core that has heard nothing and sent nothing. Whether the board has a turn pending is
    /// [`TurnState::Unknown`] until the pending angle is read.
    #[must_use]
    pub const fn new(config: Config) -> Self {
        const STREAM: StreamInfo = StreamInfo {
            frames: 0,
            missed: 0,
            rate_millihertz: 0,
            window_start_ms: None,
            window_frames: 0,
        };
        DriverCore {
            config,
            parser: DownlinkParser::new(),
            safety: Safety::new(&config),
            rx: RxBuffer::new(),
            job: None,
            outcome: None,
            imu: None,
            encoders: None,
            battery: None,
            streams: [STREAM; 3],
            last_byte_ms: None,
            quiet_reported_ms: None,
            turn: TurnState::Unknown,
            cancel_wanted: false,
            ghosts: [None; GHOSTS],
            late_rtt_ms: 0,
        }
    }

    /// The configuration.
    #[must_use]
    pub const fn config(&self) -> &Config {
        &self.config
    }

    /// Changes the configuration, keeping everything else: the turn guard, the frame being
    /// sent, the bytes read, the request in progress, the latest telemetry.
    pub fn set_config(&mut self, config: Config) {
        self.config = config;
        self.safety.set_config(&config);
    }

    /// The core's time: the latest clock reading it was given, made monotonic (see
    /// [`crate::driver`], "Time"). Every time the core reports ([`Stamped`], rates) is on it.
    #[must_use]
    pub const fn now_ms(&self) -> u64 {
        self.safety.now()
    }

    // ----- motion: frames into the slot -----

    /// Queues a body-velocity frame (safe to send again and again). [`CoreError::FramePending`]
    /// while another frame is still to go out ([`transmit`](Self::transmit) it first).
    pub fn velocity(&mut self, velocity: Velocity, now_ms: u64) -> Result<(), CoreError> {
        self.user_frame(UserFrame::Velocity(velocity), now_ms)
    }

    /// Queues a per-motor frame; as [`velocity`](Self::velocity).
    pub fn motors(&mut self, motors: Motors, now_ms: u64) -> Result<(), CoreError> {
        self.user_frame(UserFrame::Motors(motors), now_ms)
    }

    /// Queues the stop frame (all velocities 0), ahead of anything not yet begun (a frame
    /// already going out is finished first). If a turn is outstanding it is cancelled too: a
    /// [`Request::CancelTurn`] starts (ending any other request in progress, which then gives
    /// [`CoreError::Aborted`]), and its frames come out of [`transmit`](Self::transmit) after
    /// the stop.
    pub fn stop(&mut self) {
        self.safety.queue_stop();
        if !self.turning() {
            return;
        }
        match self.job.as_mut() {
            Some(job) if job.request == Request::CancelTurn => job.background = false,
            Some(_) => {
                self.end_job(Err(CoreError::Aborted));
                self.begin(Request::CancelTurn, false);
            }
            None => self.begin(Request::CancelTurn, false),
        }
    }

    /// Queues a turn, **once**: refused with [`CoreError::TurnInProgress`] while an earlier
    /// turn is outstanding, and with [`CoreError::TurnStateUnknown`] until the pending angle
    /// has been read once (the shells read it for you). The turn is taken by value and
    /// consumed: a [`Turn`] cannot be sent twice. The guard is released when a read of the
    /// pending angle comes back within [`Config::turn_done_deci_degrees`] of 0, by
    /// [`Request::CancelTurn`], or by [`abandon_turn`](Self::abandon_turn).
    pub fn turn(&mut self, turn: Turn, now_ms: u64) -> Result<(), CoreError> {
        let now = self.safety.advance(now_ms);
        match self.turn {
            TurnState::Unknown => return Err(CoreError::TurnStateUnknown),
            TurnState::Turning { .. } => return Err(CoreError::TurnInProgress),
            TurnState::Idle => {}
        }
        let deci_degrees = turn.deci_degrees;
        self.queue_frame(now, Outgoing::new(&turn.encode()), FrameKind::Motion)?;
        self.turn = TurnState::Turning { deci_degrees };
        self.safety.set_moving(true, now);
        Ok(())
    }

    /// Whether a turn is outstanding.
    #[must_use]
    pub const fn turning(&self) -> bool {
        matches!(self.turn, TurnState::Turning { .. })
    }

    /// What the core knows of a turn.
    #[must_use]
    pub const fn turn_state(&self) -> TurnState {
        self.turn
    }

    /// Forgets an outstanding turn without asking the board (after a board reset, say). The next
    /// [`turn`](DriverCore::turn) is then sent even if the board is still turning, and adds up.
    pub fn abandon_turn(&mut self) {
        self.turn = TurnState::Idle;
        self.cancel_wanted = false;
        if self.job.is_some_and(|j| j.background) {
            self.end_job(Err(CoreError::Aborted));
        }
    }

    // ----- settings without a reply -----

    /// Queues a register write. The board pauses its telemetry while settings are made; the
    /// failsafe allows for it (see the module docs). As [`velocity`](Self::velocity).
    pub fn write(&mut self, write: Write, now_ms: u64) -> Result<(), CoreError> {
        self.user_frame(UserFrame::Write(write), now_ms)
    }

    /// Queues an action (2A). As [`write`](Self::write).
    pub fn action(&mut self, action: Action, now_ms: u64) -> Result<(), CoreError> {
        self.user_frame(UserFrame::Action(action), now_ms)
    }

    /// Queues a frame the user sends without a request (motion or a setting): what
    /// [`velocity`](Self::velocity), [`motors`](Self::motors), [`write`](Self::write) and
    /// [`action`](Self::action) do, in one body the shells share.
    pub(crate) fn user_frame(&mut self, frame: UserFrame, now_ms: u64) -> Result<(), CoreError> {
        let now = self.safety.advance(now_ms);
        let (bytes, kind, moving) = match frame {
            UserFrame::Velocity(v) => (
                Outgoing::new(&v.encode()),
                FrameKind::Motion,
                Some(v.x != 0 || v.y != 0 || v.z != 0),
            ),
            UserFrame::Motors(m) => (
                Outgoing::new(&m.encode()),
                FrameKind::Motion,
                Some(m.values.iter().any(|v| *v != 0)),
            ),
            UserFrame::Write(w) => (
                Outgoing::new(&Setting::Write(w).encode()),
                FrameKind::Settings,
                None,
            ),
            UserFrame::Action(a) => (
                Outgoing::new(&Setting::Action(a).encode()),
                FrameKind::Settings,
                None,
            ),
        };
        self.queue_frame(now, bytes, kind)?;
        if let Some(moving) = moving {
            self.safety.set_moving(moving || self.turning(), now);
        }
        Ok(())
    }

    // ----- requests -----

    /// Starts a request; its frames come out of [`transmit`](Self::transmit), its end out of
    /// [`take_outcome`](Self::take_outcome). [`CoreError::Busy`] while another runs (one the
    /// core started itself, the failsafe's turn cancel, gives way).
    pub fn start(&mut self, request: Request) -> Result<(), CoreError> {
        match self.job {
            Some(job) if job.background => self.end_job(Err(CoreError::Aborted)),
            Some(_) => return Err(CoreError::Busy),
            None => {}
        }
        self.outcome = None;
        self.begin(request, false);
        Ok(())
    }

    /// Ends the request in progress, if any, as if it had never started (no outcome). A reply
    /// that comes later is a stray one. Shells call it when a transport error or a dropped
    /// future cuts a request short, so no error leaves the driver busy. A frame already going
    /// out is still finished ([`transmit`](Self::transmit)).
    // Out of line: the shells call it on every error path (`size_driver`: 12 B).
    #[inline(never)]
    pub fn abort(&mut self) {
        self.end_job(Ok(Outcome::Done));
        self.outcome = None;
        self.safety.reset_stall();
    }

    /// Whether a request is in progress (the core's own turn cancel included).
    #[must_use]
    pub const fn busy(&self) -> bool {
        self.job.is_some()
    }

    /// Whether a request the user started is in progress.
    #[must_use]
    pub fn busy_for_user(&self) -> bool {
        self.job.is_some_and(|j| !j.background)
    }

    /// The register whose reply is awaited, if any.
    #[must_use]
    pub fn waiting_for(&self) -> Option<Register> {
        match self.job {
            Some(Job {
                step:
                    Step::Read(Read {
                        register,
                        phase: Phase::Waiting { .. },
                        ..
                    }),
                ..
            }) => Some(register),
            _ => None,
        }
    }

    /// How the last request ended, once it has (taken once).
    pub fn take_outcome(&mut self) -> Option<Result<Outcome, CoreError>> {
        self.outcome.take()
    }

    /// What a shell asks after each turn of its pump while a request runs: the request's end,
    /// if it has ended, or [`CoreError::ClockStalled`] once `limit` turns in a row saw the clock
    /// stand still, whatever bytes came meanwhile: time will never end the wait. A stalled
    /// request is aborted.
    pub fn settle(&mut self, now_ms: u64, limit: u32) -> Option<Result<Outcome, CoreError>> {
        let now = self.safety.advance(now_ms);
        if let Some(outcome) = self.outcome.take() {
            self.safety.reset_stall();
            return Some(outcome);
        }
        if !self.busy_for_user() {
            // Ended without an outcome: the core's own request took its place.
            self.safety.reset_stall();
            return Some(Err(CoreError::Aborted));
        }
        if self.safety.stalled(now, limit) {
            self.abort();
            return Some(Err(CoreError::ClockStalled));
        }
        None
    }

    // ----- the pump: what the shells call -----

    /// The bytes to write to the UART now, if any: the rest of a frame already going out, else
    /// the next frame (a stop first, then the request's frames, each put in the slot whole).
    /// Tell the core how many the UART took with [`transmitted`](Self::transmitted); until
    /// then the same bytes come out again.
    pub fn transmit(&mut self, now_ms: u64) -> Option<&[u8]> {
        let now = self.safety.advance(now_ms);
        if self.safety.slot_free() && !self.safety.load_stop() {
            if let Some((frame, kind)) = self.next_job_frame(now) {
                self.safety.load(frame, kind);
            }
        }
        self.safety.pending()
    }

    /// The UART took `n` of the bytes [`transmit`](Self::transmit) gave. A read's reply
    /// timeout starts when its last byte has left.
    pub fn transmitted(&mut self, n: usize, now_ms: u64) {
        let now = self.safety.advance(now_ms);
        if self.safety.transmitted(n) != Some(FrameKind::Read) {
            return;
        }
        let timeout = self.reply_timeout_ms();
        if let Some(Job {
            step: Step::Read(read),
            ..
        }) = self.job.as_mut()
        {
            if read.phase == Phase::Sending {
                read.phase = Phase::Waiting {
                    sent_ms: now,
                    deadline_ms: now.saturating_add(timeout),
                };
            }
        }
    }

    /// Feeds received bytes; returns the first event they complete and the bytes not yet
    /// consumed (feed them again: nothing is dropped).
    pub fn receive<'a>(&mut self, bytes: &'a [u8], now_ms: u64) -> (Option<Event>, &'a [u8]) {
        let now = self.safety.advance(now_ms);
        if !bytes.is_empty() {
            self.last_byte_ms = Some(now);
        }
        let (frame, rest) = self.parser.push_slice(bytes);
        (frame.map(|frame| self.frame(frame, now)), rest)
    }

    /// Where a shell reads the UART into (call only when [`rx_empty`](Self::rx_empty)), then
    /// [`rx_filled`](Self::rx_filled) with the count read. The bytes are the core's: they
    /// survive a dropped future, an error and a rebuilt driver.
    pub fn rx_space(&mut self) -> &mut [u8] {
        self.rx.space()
    }

    /// Records that `n` bytes were read into [`rx_space`](Self::rx_space).
    pub fn rx_filled(&mut self, n: usize) {
        self.rx.filled(n);
    }

    /// Whether every byte read into [`rx_space`](Self::rx_space) has gone through the parser.
    #[must_use]
    pub const fn rx_empty(&self) -> bool {
        self.rx.is_empty()
    }

    /// Feeds the bytes read into [`rx_space`](Self::rx_space) to the parser until one
    /// completes an event.
    // Out of line: the parser it runs stays one function, not a copy inlined into a shell's
    // pump (`size_driver`: 88 B).
    #[inline(never)]
    pub fn drain(&mut self, now_ms: u64) -> Option<Event> {
        if self.rx.is_empty() {
            return None;
        }
        let now = self.safety.advance(now_ms);
        self.last_byte_ms = Some(now);
        let (frame, rest) = self.parser.push_slice(self.rx.pending());
        let rest = rest.len();
        self.rx.left(rest);
        frame.map(|frame| self.frame(frame, now))
    }

    /// Judges time: a quiet line (a frame that waited for one comes out: call until `None`),
    /// the reply timeout (retry or error), the failsafe (a stop queued for
    /// [`transmit`](Self::transmit)) and, after it, the cancel of a turn left outstanding. Call
    /// it once every byte the UART holds has gone through [`receive`](Self::receive).
    pub fn tick(&mut self, now_ms: u64) -> Option<Event> {
        let now = self.safety.advance(now_ms);
        let mut event = None;
        if let Some(last) = self.last_byte_ms {
            if now.saturating_sub(last) >= u64::from(self.config.idle_ms) {
                // Report each stretch of quiet once: the time since the last byte, or since the
                // last report.
                let from = self.quiet_reported_ms.map_or(last, |t| t.max(last));
                let ms = u32::try_from(now.saturating_sub(from)).unwrap_or(u32::MAX);
                self.quiet_reported_ms = Some(now);
                if let Some(frame) = self.parser.quiet(ms) {
                    // Judged now, but heard when its last byte came: the failsafe counts
                    // silence from there.
                    event = Some(self.frame(frame, last));
                }
            }
        }
        // A frame the quiet let out is taken in first (it may be the awaited reply); time is
        // judged either way, so frames held in the parser never delay the failsafe.
        self.expire_ghosts(now);
        self.check_reply_timeout(now);
        if self.safety.check_failsafe(now) && self.turning() {
            self.cancel_wanted = true;
        }
        if !self.turning() {
            self.cancel_wanted = false;
        } else if self.cancel_wanted && self.job.is_none() {
            self.begin(Request::CancelTurn, true);
        }
        event
    }

    /// The next time [`tick`](Self::tick) or [`transmit`](Self::transmit) may have something
    /// to do (a reply deadline, a held read's ghost ending, the failsafe, a quiet line), on the
    /// core's clock ([`now_ms`](Self::now_ms)).
    #[must_use]
    pub fn next_deadline(&self) -> Option<u64> {
        let reply = match self.job {
            Some(Job {
                step: Step::Read(read),
                ..
            }) => match read.phase {
                Phase::Waiting { deadline_ms, .. } => Some(deadline_ms.saturating_add(1)),
                Phase::ToSend => self
                    .ghost_of(read.register)
                    .map(|g| g.until_ms.saturating_add(1)),
                Phase::Sending => None,
            },
            _ => None,
        };
        let failsafe = self.safety.failsafe_deadline().map(|d| d.saturating_add(1));
        let quiet = match (self.last_byte_ms, self.parser.buffered()) {
            (Some(t), 1..) => Some(t.saturating_add(u64::from(self.config.idle_ms))),
            _ => None,
        };
        [reply, failsafe, quiet].into_iter().flatten().min()
    }

    /// How long from the clock reading `now_ms` until [`next_deadline`](Self::next_deadline),
    /// in ms (0 if it has passed), for a shell that sleeps until then.
    #[must_use]
    pub fn wait_ms(&self, now_ms: u64) -> Option<u64> {
        let now = self.safety.peek(now_ms);
        self.next_deadline().map(|due| due.saturating_sub(now))
    }

    // ----- state -----

    /// Times the failsafe has stopped the chassis.
    #[must_use]
    pub const fn failsafe_stops(&self) -> u32 {
        self.safety.failsafe_stops()
    }

    /// Whether the board has been heard (a frame of any kind) within [`Config::failsafe_ms`]
    /// of the clock reading `now_ms`.
    #[must_use]
    pub fn link_alive(&self, now_ms: u64) -> bool {
        self.safety.link_alive(self.safety.peek(now_ms))
    }

    /// Whether the driver last told the chassis to move (a turn outstanding counts), and the
    /// failsafe has not stopped it since.
    #[must_use]
    pub const fn moving(&self) -> bool {
        self.safety.moving()
    }

    /// The latest IMU frame and when it came.
    #[must_use]
    pub const fn imu(&self) -> Option<Stamped<Imu>> {
        self.imu
    }

    /// The latest encoder frame and when it came.
    #[must_use]
    pub const fn encoders(&self) -> Option<Stamped<Encoders>> {
        self.encoders
    }

    /// The latest battery frame and when it came.
    #[must_use]
    pub const fn battery(&self) -> Option<Stamped<Battery>> {
        self.battery
    }

    /// When the last telemetry frame came.
    #[must_use]
    pub const fn last_telemetry_ms(&self) -> Option<u64> {
        self.safety.last_telemetry_ms()
    }

    /// When the last frame of any kind (telemetry or reply) came.
    #[must_use]
    pub const fn last_heard_ms(&self) -> Option<u64> {
        self.safety.last_heard_ms()
    }

    /// Rate and drops of one stream.
    #[must_use]
    pub fn stream(&self, stream: Stream) -> StreamInfo {
        self.streams
            .get(stream.index())
            .copied()
            .unwrap_or_default()
    }

    /// The parser's counters.
    #[must_use]
    pub const fn parser_stats(&self) -> &DownlinkStats {
        self.parser.stats()
    }

    /// How sure the parser is of the frame boundaries.
    #[must_use]
    pub const fn lock(&self) -> Lock {
        self.parser.lock()
    }

    /// How long a read waits for its reply now: [`Config::reply_timeout_ms`], or longer once
    /// a timeout or a late reply has shown the board to be slower (at most
    /// [`Config::late_reply_ms`] more); replies in time bring it back.
    #[must_use]
    pub fn reply_timeout_ms(&self) -> u64 {
        let base = u64::from(self.config.reply_timeout_ms());
        let rtt = u64::from(self.late_rtt_ms);
        let learnt = rtt
            .saturating_add(rtt / 4)
            .saturating_add(u64::from(self.config.idle_ms));
        base.max(learnt)
            .min(base.saturating_add(u64::from(self.config.late_reply_ms)))
    }

    // ----- inside -----

    /// Puts a frame the user asked for in the slot, once nothing else is to go out before it
    /// ([`ready_for_frame`](Self::ready_for_frame)).
    // Out of line: one copy for the five frames a user sends without a request.
    #[inline(never)]
    fn queue_frame(&mut self, now: u64, frame: Outgoing, kind: FrameKind) -> Result<(), CoreError> {
        self.ready_for_frame(now)?;
        self.safety.queue(frame, kind)
    }

    /// [`CoreError::FramePending`] while anything is still to go out: the frame in the slot, a
    /// queued stop, or a frame of the request in progress.
    fn ready_for_frame(&self, now: u64) -> Result<(), CoreError> {
        let job_frame = match self.job {
            Some(Job {
                step: Step::Read(read),
                ..
            }) => read.phase == Phase::ToSend && self.live_ghost(read.register, now).is_none(),
            Some(_) => true,
            None => false,
        };
        if self.safety.output_pending() || job_frame {
            return Err(CoreError::FramePending);
        }
        Ok(())
    }

    /// The request's next frame, if it has one to send now.
    fn next_job_frame(&mut self, now: u64) -> Option<(Outgoing, FrameKind)> {
        self.expire_ghosts(now);
        let mut job = self.job?;
        match job.step {
            Step::Read(mut read) if read.phase == Phase::ToSend => {
                if self.live_ghost(read.register, now).is_some() {
                    // Its reply and the ghost's could not be told apart: wait.
                    return None;
                }
                read.phase = Phase::Sending;
                read.tries = read.tries.saturating_add(1);
                job.step = Step::Read(read);
                self.job = Some(job);
                // The master knows when it asked: the parser takes the awaited reply on less
                // evidence, and any other reply on more.
                self.parser.expect_reply(Some(read.register));
                let frame = Setting::Read(read.register).encode();
                Some((Outgoing::new(&frame), FrameKind::Read))
            }
            Step::Read(_) => None,
            Step::Write(write) => {
                self.advance(None);
                Some((
                    Outgoing::new(&Setting::Write(write).encode()),
                    FrameKind::Settings,
                ))
            }
            Step::CounterTurn(deci_degrees) => {
                // In the slot it will go out whole: the turn is over once it has.
                self.turn = TurnState::Idle;
                self.advance(None);
                Some((
                    Outgoing::new(&Turn::by_deci_degrees(deci_degrees).encode()),
                    FrameKind::Motion,
                ))
            }
        }
    }

    // Out of line: `start`, `stop` and the failsafe's turn cancel share it (`size_driver`: 20 B).
    #[inline(never)]
    fn begin(&mut self, request: Request, background: bool) {
        let step = match request {
            Request::Read(register) => Step::Read(Read::new(register, Check::Once)),
            Request::ReadVerified(register) => Step::Read(Read::new(register, Check::Agree)),
            Request::ReadSettings => match Snapshot::REGISTERS.first() {
                Some(register) => Step::Read(Read::new(*register, Check::Agree)),
                None => Step::Read(Read::new(Register::MaxSpeed, Check::Agree)),
            },
            Request::RestoreSettings(_) => {
                Step::Read(Read::new(Register::SystemMode, Check::Agree))
            }
            Request::CancelTurn => Step::Read(Read::new(Register::PendingAngle, Check::Plausible)),
        };
        self.job = Some(Job {
            request,
            step,
            index: 0,
            settings: Snapshot::default(),
            background,
        });
    }

    /// Ends the request in progress with `outcome` (kept for the user unless the core started
    /// it). A read already sent and not answered leaves a ghost.
    fn end_job(&mut self, outcome: Result<Outcome, CoreError>) {
        let Some(job) = self.job.take() else {
            return;
        };
        if let Step::Read(read) = job.step {
            self.unanswered(&read);
        }
        if !job.background {
            self.outcome = Some(outcome);
        }
    }

    /// A read sent and not answered: remember it until its reply can no longer come.
    fn unanswered(&mut self, read: &Read) {
        let now = self.safety.now();
        let sent_ms = match read.phase {
            Phase::ToSend => return,
            Phase::Sending => now,
            Phase::Waiting { sent_ms, .. } => sent_ms,
        };
        let until_ms = now
            .max(sent_ms.saturating_add(self.reply_timeout_ms()))
            .saturating_add(u64::from(self.config.late_reply_ms));
        let ghost = Ghost {
            register: read.register,
            sent_ms,
            until_ms,
        };
        // A free place, or the one that ends first (the first of those that end first).
        let mut place = 0;
        let mut first_end = u64::MAX;
        for (i, slot) in self.ghosts.iter().enumerate() {
            let Some(g) = slot else {
                place = i;
                break;
            };
            if g.until_ms < first_end {
                first_end = g.until_ms;
                place = i;
            }
        }
        if let Some(slot) = self.ghosts.get_mut(place) {
            *slot = Some(ghost);
        }
    }

    fn expire_ghosts(&mut self, now: u64) {
        for g in &mut self.ghosts {
            if g.is_some_and(|g| now > g.until_ms) {
                *g = None;
            }
        }
    }

    fn live_ghost(&self, register: Register, now: u64) -> Option<Ghost> {
        self.ghost_of(register).filter(|g| now <= g.until_ms)
    }

    fn ghost_of(&self, register: Register) -> Option<Ghost> {
        self.ghosts
            .iter()
            .flatten()
            .find(|g| g.register == register)
            .copied()
    }

    /// A reply with `code` came: if it is a ghost's, that read is answered at last (late), and
    /// its round trip teaches the core how slow the board is.
    fn take_ghost(&mut self, code: u8, now: u64) -> bool {
        for g in &mut self.ghosts {
            if let Some(ghost) = *g {
                if ghost.register.reply_code() == code && now <= ghost.until_ms {
                    *g = None;
                    let rtt = u32::try_from(now.saturating_sub(ghost.sent_ms)).unwrap_or(u32::MAX);
                    self.late_rtt_ms = self.late_rtt_ms.max(rtt);
                    return true;
                }
            }
        }
        false
    }

    /// The current step is done (`value`: what a read gave): the request's next step, or its
    /// outcome.
    fn advance(&mut self, value: Option<u32>) {
        let Some(mut job) = self.job else {
            return;
        };
        if let (Some(raw), Step::Read(read)) = (value, job.step) {
            if read.register == Register::PendingAngle {
                self.pending_angle_read(raw as i32);
            }
        }
        job.index = job.index.saturating_add(1);
        let next = match (job.request, value) {
            (Request::Read(_) | Request::ReadVerified(_), Some(raw)) => {
                return self.finish(Ok(Outcome::Value(raw)));
            }
            (Request::ReadSettings, Some(raw)) => {
                if let Step::Read(read) = job.step {
                    if let Some(write) = Write::from_value(read.register, raw) {
                        job.settings.set(write);
                    }
                }
                match Snapshot::REGISTERS.get(usize::from(job.index)) {
                    Some(register) => Step::Read(Read::new(*register, Check::Agree)),
                    None => return self.finish(Ok(Outcome::Snapshot(job.settings))),
                }
            }
            (Request::RestoreSettings(mut settings), value) => {
                if let Some(raw) = value {
                    // The board's own compensation bit goes back unchanged.
                    let live = crate::command::SystemMode::from_bits(raw).gyro_compensation();
                    settings.system_mode = settings.system_mode.with_gyro_compensation(live);
                    job.request = Request::RestoreSettings(settings);
                }
                let writes = settings.writes();
                match writes.get(usize::from(job.index).saturating_sub(1)) {
                    Some(write) => Step::Write(*write),
                    None => return self.finish(Ok(Outcome::Done)),
                }
            }
            (Request::CancelTurn, Some(raw)) => {
                let pending = raw as i32;
                if pending.unsigned_abs() <= u32::from(self.config.turn_done_deci_degrees) {
                    return self.finish(Ok(Outcome::Done));
                }
                Step::CounterTurn(pending.saturating_neg())
            }
            (Request::CancelTurn, None) => return self.finish(Ok(Outcome::Done)),
            (Request::Read(_) | Request::ReadVerified(_) | Request::ReadSettings, None) => {
                return self.finish(Ok(Outcome::Done));
            }
        };
        job.step = next;
        self.job = Some(job);
    }

    /// A reply to a read of the pending angle: the turn guard learns from it.
    fn pending_angle_read(&mut self, pending: i32) {
        if pending.unsigned_abs() <= u32::from(self.config.turn_done_deci_degrees) {
            self.turn = TurnState::Idle;
        } else if self.turn == TurnState::Unknown {
            self.turn = TurnState::Turning {
                deci_degrees: pending,
            };
        }
    }

    /// The request ended (a read answered for the last time, an error).
    // Out of line: ten callers, each copying an outcome that may hold a whole snapshot
    // (`size_driver`: 112 B).
    #[inline(never)]
    fn finish(&mut self, outcome: Result<Outcome, CoreError>) {
        if let Some(job) = self.job.take() {
            if !job.background {
                self.outcome = Some(outcome);
            }
        }
        self.safety.reset_stall();
    }

    /// A reply came: does the read in flight take it?
    fn reply(&mut self, reply: Reply, now: u64) -> Event {
        self.expire_ghosts(now);
        let read = match self.job {
            Some(Job {
                step: Step::Read(read),
                ..
            }) if matches!(read.phase, Phase::Waiting { .. }) => read,
            _ => {
                let _ = self.take_ghost(reply.code, now);
                return Event::StrayReply(reply);
            }
        };
        let matches = read.register.reply_code() == reply.code;
        if matches {
            // Answered in time: the learnt round trip moves back towards what the board does.
            if let Phase::Waiting { sent_ms, .. } = read.phase {
                let rtt = u32::try_from(now.saturating_sub(sent_ms)).unwrap_or(u32::MAX);
                let decayed = self.late_rtt_ms.saturating_sub(self.late_rtt_ms / 8);
                self.late_rtt_ms = decayed.max(rtt.min(self.late_rtt_ms));
            }
        }
        if !matches && self.take_ghost(reply.code, now) {
            // The late reply to an earlier read: the read in flight waits on.
            return Event::StrayReply(reply);
        }
        let fits = registers::fits(read.register, reply.value);
        let event = if matches {
            Event::Reply(reply)
        } else {
            Event::StrayReply(reply)
        };
        match read.check {
            Check::Once if !matches => {
                self.unanswered(&read);
                self.finish(Err(CoreError::WrongReply {
                    expected: read.register,
                    got: reply.code,
                }));
            }
            Check::Once if !fits => self.finish(Err(CoreError::Invalid {
                register: read.register,
                value: reply.value,
            })),
            Check::Once => self.advance(Some(reply.value)),
            Check::Agree if matches && fits && read.seen.contains(&Some(reply.value)) => {
                self.advance(Some(reply.value));
            }
            Check::Agree => {
                let mut read = read;
                if matches && fits {
                    let [latest, _] = read.seen;
                    read.seen = [Some(reply.value), latest];
                } else if !matches {
                    self.unanswered(&read);
                }
                self.retry(read);
            }
            Check::Plausible if matches && self.within_turn(reply.value) => {
                self.advance(Some(reply.value));
            }
            Check::Plausible => {
                if !matches {
                    self.unanswered(&read);
                }
                self.retry(read);
            }
        }
        event
    }

    /// Whether a pending angle can be what is left of the outstanding turn: between 0 and the
    /// turn's angle (give or take the tolerance). With no turn known, any angle can be.
    fn within_turn(&self, raw: u32) -> bool {
        let TurnState::Turning { deci_degrees } = self.turn else {
            return true;
        };
        let pending = i64::from(raw as i32);
        let turn = i64::from(deci_degrees);
        let slack = i64::from(self.config.turn_done_deci_degrees);
        let (low, high) = if turn >= 0 { (0, turn) } else { (turn, 0) };
        (low.saturating_sub(slack)..=high.saturating_add(slack)).contains(&pending)
    }

    /// The read in flight gave nothing usable: send it again, or give up.
    fn retry(&mut self, mut read: Read) {
        if read.tries >= self.config.read_tries {
            let error = match read.check {
                Check::Once => CoreError::Timeout(read.register),
                Check::Agree | Check::Plausible => CoreError::Unconfirmed(read.register),
            };
            return self.finish(Err(error));
        }
        read.phase = Phase::ToSend;
        if let Some(job) = self.job.as_mut() {
            job.step = Step::Read(read);
        }
    }

    fn check_reply_timeout(&mut self, now: u64) {
        let Some(Job {
            step: Step::Read(read),
            ..
        }) = self.job
        else {
            return;
        };
        match read.phase {
            Phase::Waiting {
                sent_ms,
                deadline_ms,
            } if now > deadline_ms => {
                // No answer in the time given: the board may be slower than that. Reads from
                // now on wait twice as long (at most `late_reply_ms` more than configured)
                // until replies show otherwise.
                let waited = u32::try_from(deadline_ms.saturating_sub(sent_ms)).unwrap_or(u32::MAX);
                self.late_rtt_ms = self.late_rtt_ms.max(waited.saturating_mul(2));
                self.unanswered(&read);
                // A board that answers nothing is silent, not paused.
                self.safety.read_unanswered();
                match read.check {
                    Check::Once => self.finish(Err(CoreError::Timeout(read.register))),
                    Check::Agree | Check::Plausible => self.retry(read),
                }
            }
            _ => {}
        }
    }

    fn frame(&mut self, frame: Downlink, now_ms: u64) -> Event {
        let stream = match frame {
            Downlink::Imu(value) => {
                self.imu = Some(Stamped {
                    value,
                    at_ms: now_ms,
                });
                Stream::Imu
            }
            Downlink::Encoders(value) => {
                self.encoders = Some(Stamped {
                    value,
                    at_ms: now_ms,
                });
                Stream::Encoders
            }
            Downlink::Battery(value) => {
                self.battery = Some(Stamped {
                    value,
                    at_ms: now_ms,
                });
                Stream::Battery
            }
            Downlink::Reply(reply) => {
                self.safety.reply_heard(now_ms);
                return self.reply(reply, now_ms);
            }
        };
        self.safety.telemetry(now_ms);
        let missed = self.parser.stats().missed_of(stream);
        if let Some(info) = self.streams.get_mut(stream.index()) {
            info.arrived(now_ms, missed);
        }
        Event::Telemetry(frame)
    }
}

impl super::Core for DriverCore {
    type Event = Event;
    type Request = Request;
    type Outcome = Outcome;

    fn set_config(&mut self, config: Config) {
        DriverCore::set_config(self, config);
    }
    fn start(&mut self, request: Request) -> Result<(), CoreError> {
        DriverCore::start(self, request)
    }
    fn stop(&mut self) {
        DriverCore::stop(self);
    }
    fn abort(&mut self) {
        DriverCore::abort(self);
    }
    fn busy_for_user(&self) -> bool {
        DriverCore::busy_for_user(self)
    }
    fn settle(&mut self, now_ms: u64, limit: u32) -> Option<Result<Outcome, CoreError>> {
        DriverCore::settle(self, now_ms, limit)
    }
    fn transmit(&mut self, now_ms: u64) -> Option<&[u8]> {
        DriverCore::transmit(self, now_ms)
    }
    fn transmitted(&mut self, n: usize, now_ms: u64) {
        DriverCore::transmitted(self, n, now_ms);
    }
    fn rx_space(&mut self) -> &mut [u8] {
        DriverCore::rx_space(self)
    }
    fn rx_filled(&mut self, n: usize) {
        DriverCore::rx_filled(self, n);
    }
    fn drain(&mut self, now_ms: u64) -> Option<Event> {
        DriverCore::drain(self, now_ms)
    }
    fn tick(&mut self, now_ms: u64) -> Option<Event> {
        DriverCore::tick(self, now_ms)
    }
    fn wait_ms(&self, now_ms: u64) -> Option<u64> {
        DriverCore::wait_ms(self, now_ms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Everything the core has to send now, each frame taken whole by the UART.
    fn out(core: &mut DriverCore, now: u64) -> Option<Vec<u8>> {
        let bytes = core.transmit(now)?.to_vec();
        core.transmitted(bytes.len(), now);
        Some(bytes)
    }

    fn reply(core: &mut DriverCore, register: Register, value: u32, now: u64) {
        let _ = core.receive(&Reply::new(register, value).encode(), now);
        while core.tick(now.saturating_add(5)).is_some() {}
    }

    /// A core that has read the pending angle (0): turns may be sent.
    fn idle_core() -> DriverCore {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::Read(Register::PendingAngle)).unwrap();
        assert!(out(&mut core, 0).is_some());
        reply(&mut core, Register::PendingAngle, 0, 1);
        assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(0))));
        assert_eq!(core.turn_state(), TurnState::Idle);
        core
    }

    const STOP: [u8; 10] = [0xFF, 0xFE, 0x01, 0, 0, 0, 0, 0, 0, 0];

    #[test]
    fn reply_timeout_follows_the_baud_rate() {
        assert_eq!(Config::DEFAULT.reply_timeout_ms(), 3 + 50 + 2);
        assert_eq!(
            Config::HOST.reply_timeout_ms(),
            133,
            "as the driver docs say"
        );
        assert_eq!(Config::HOST.failsafe_ms, 200, "as the driver docs say");
        let slow = Config {
            baud: 9_600,
            board_latency_ms: 0,
            idle_ms: 0,
            ..Config::DEFAULT
        };
        assert_eq!(slow.reply_timeout_ms(), 33);
    }

    #[test]
    fn a_new_core_does_not_turn_before_it_knows_no_turn_is_pending() {
        let mut core = DriverCore::new(Config::DEFAULT);
        assert_eq!(core.turn_state(), TurnState::Unknown);
        assert_eq!(
            core.turn(Turn::by_deci_degrees(900), 0),
            Err(CoreError::TurnStateUnknown)
        );
        // The board still has 45.0° to go from an earlier program: a turn is outstanding.
        core.start(Request::Read(Register::PendingAngle)).unwrap();
        assert!(out(&mut core, 0).is_some());
        reply(&mut core, Register::PendingAngle, 450, 1);
        assert_eq!(core.turn_state(), TurnState::Turning { deci_degrees: 450 });
        assert_eq!(
            core.turn(Turn::by_deci_degrees(900), 10),
            Err(CoreError::TurnInProgress)
        );
    }

    #[test]
    fn a_second_turn_is_refused_until_the_pending_angle_reads_near_zero() {
        let mut core = idle_core();
        assert!(core.turn(Turn::by_deci_degrees(900), 10).is_ok());
        assert!(out(&mut core, 10).is_some());
        assert_eq!(
            core.turn(Turn::by_deci_degrees(900), 11),
            Err(CoreError::TurnInProgress)
        );
        core.start(Request::Read(Register::PendingAngle)).unwrap();
        assert!(out(&mut core, 12).is_some());
        reply(&mut core, Register::PendingAngle, 450, 13);
        assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(450))));
        assert!(core.turning(), "still 45.0° to go");
        core.start(Request::Read(Register::PendingAngle)).unwrap();
        assert!(out(&mut core, 30).is_some());
        // A board that leaves a fraction of a degree still ends the turn.
        reply(&mut core, Register::PendingAngle, (-3i32) as u32, 31);
        assert!(!core.turning());
        assert!(core.turn(Turn::by_deci_degrees(-900), 41).is_ok());
    }

    #[test]
    fn a_frame_goes_out_whole_before_any_other() {
        let mut core = idle_core();
        core.velocity(Velocity::new(0, 300, 0), 10).unwrap();
        let first = core.transmit(10).unwrap().to_vec();
        assert_eq!(first, [0xFF, 0xFE, 0x01, 0, 0, 0x01, 0x2C, 0, 0, 0]);
        core.transmitted(3, 10);
        // Nothing new is accepted while the rest waits; a stop waits behind it.
        assert_eq!(
            core.velocity(Velocity::new(0, 100, 0), 11),
            Err(CoreError::FramePending)
        );
        assert_eq!(
            core.turn(Turn::by_deci_degrees(900), 11),
            Err(CoreError::FramePending)
        );
        core.stop();
        assert_eq!(core.transmit(12), Some(&first[3..]));
        core.transmitted(7, 12);
        assert_eq!(out(&mut core, 12).as_deref(), Some(&STOP[..]));
        assert_eq!(core.transmit(13), None);
    }

    #[test]
    fn reads_time_out_and_a_second_request_is_busy() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::Read(Register::SpeedKp)).unwrap();
        assert_eq!(
            core.start(Request::Read(Register::SpeedKi)),
            Err(CoreError::Busy)
        );
        assert!(out(&mut core, 0).is_some());
        assert_eq!(core.waiting_for(), Some(Register::SpeedKp));
        let _ = core.tick(55);
        assert_eq!(core.take_outcome(), None);
        let _ = core.tick(56);
        assert_eq!(
            core.take_outcome(),
            Some(Err(CoreError::Timeout(Register::SpeedKp)))
        );
        assert_eq!(core.waiting_for(), None);
        assert!(core.start(Request::Read(Register::SpeedKi)).is_ok());
    }

    #[test]
    fn the_reply_timeout_starts_when_the_last_byte_has_left() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::Read(Register::SpeedKp)).unwrap();
        assert!(core.transmit(0).is_some());
        core.transmitted(4, 0);
        // The rest goes out 500 ms later (a future dropped, the next call finishing it).
        let _ = core.tick(500);
        assert_eq!(core.take_outcome(), None, "not sent yet: no timeout");
        assert!(core.transmit(500).is_some());
        core.transmitted(6, 500);
        let _ = core.tick(555);
        assert_eq!(core.take_outcome(), None);
        let _ = core.tick(556);
        assert_eq!(
            core.take_outcome(),
            Some(Err(CoreError::Timeout(Register::SpeedKp)))
        );
    }

    #[test]
    fn abort_leaves_the_core_usable() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::ReadSettings).unwrap();
        assert!(out(&mut core, 0).is_some());
        core.abort();
        assert!(!core.busy());
        assert_eq!(core.take_outcome(), None);
        // The late reply is a stray one.
        let _ = core.receive(&Reply::new(Register::MaxSpeed, 1).encode(), 1);
        assert!(matches!(core.tick(10), Some(Event::StrayReply(_))));
        assert!(core.start(Request::Read(Register::MaxSpeed)).is_ok());
    }

    #[test]
    fn a_late_reply_never_answers_a_later_read_of_its_register() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::Read(Register::PendingAngle)).unwrap();
        assert!(out(&mut core, 0).is_some());
        let _ = core.tick(56);
        assert_eq!(
            core.take_outcome(),
            Some(Err(CoreError::Timeout(Register::PendingAngle)))
        );
        // The next read of the same register waits for the late reply (or its time to pass).
        core.start(Request::Read(Register::PendingAngle)).unwrap();
        assert_eq!(core.transmit(57), None);
        reply(&mut core, Register::PendingAngle, 0, 60);
        assert_eq!(core.take_outcome(), None, "the late 0 answers nothing");
        assert_eq!(core.turn_state(), TurnState::Unknown);
        assert!(out(&mut core, 66).is_some(), "now the read goes");
        reply(&mut core, Register::PendingAngle, 300, 70);
        assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(300))));
        // The board took 60 ms: later reads wait that long.
        assert!(core.reply_timeout_ms() >= 60, "{}", core.reply_timeout_ms());
    }

    #[test]
    fn a_late_reply_of_another_register_is_passed_over() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::Read(Register::SpeedKp)).unwrap();
        assert!(out(&mut core, 0).is_some());
        let _ = core.tick(56);
        assert!(core.take_outcome().is_some());
        core.start(Request::Read(Register::SpeedKi)).unwrap();
        assert!(out(&mut core, 57).is_some());
        reply(&mut core, Register::SpeedKp, 5, 60);
        assert_eq!(core.take_outcome(), None, "not a wrong reply: a late one");
        reply(&mut core, Register::SpeedKi, 7, 70);
        assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(7))));
    }

    #[test]
    fn a_verified_read_needs_two_agreeing_replies_that_fit() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::ReadVerified(Register::MaxSpeed))
            .unwrap();
        let mut now = 0;
        // A damaged reply (high half set: no u16), then two good ones.
        for value in [0x0001_03E8, 1_000, 1_000] {
            assert!(out(&mut core, now).is_some(), "a read goes out");
            reply(&mut core, Register::MaxSpeed, value, now.saturating_add(1));
            now = now.saturating_add(10);
        }
        assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(1_000))));
    }

    #[test]
    fn a_verified_read_that_never_agrees_is_unconfirmed() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::ReadVerified(Register::SpeedKp))
            .unwrap();
        let mut now = 0;
        for value in [1, 2, 3, 4] {
            assert!(out(&mut core, now).is_some());
            reply(&mut core, Register::SpeedKp, value, now.saturating_add(1));
            now = now.saturating_add(10);
        }
        assert!(out(&mut core, now).is_none(), "four tries at most");
        assert_eq!(
            core.take_outcome(),
            Some(Err(CoreError::Unconfirmed(Register::SpeedKp)))
        );
    }

    #[test]
    fn the_failsafe_allows_the_settings_pause_but_not_a_dead_board() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.velocity(Velocity::new(0, 100, 0), 0).unwrap();
        assert!(out(&mut core, 0).is_some());
        let _ = core.tick(100);
        assert_eq!(out(&mut core, 100), None);
        let _ = core.tick(101);
        assert_eq!(out(&mut core, 101).as_deref(), Some(&STOP[..]));
        assert_eq!(core.failsafe_stops(), 1);
        // Moving again; a write makes the board pause: 600 ms allowed.
        core.velocity(Velocity::new(0, 100, 0), 1_000).unwrap();
        assert!(out(&mut core, 1_000).is_some());
        core.write(Write::MaxSpeed(10), 1_000).unwrap();
        assert!(out(&mut core, 1_000).is_some());
        let _ = core.tick(1_599);
        assert_eq!(out(&mut core, 1_599), None);
        let _ = core.tick(1_601);
        assert!(out(&mut core, 1_601).is_some());
        // Standing still, silence is no reason to stop.
        core.velocity(Velocity::STOP, 2_000).unwrap();
        assert!(out(&mut core, 2_000).is_some());
        let _ = core.tick(10_000);
        assert_eq!(out(&mut core, 10_000), None);
    }

    #[test]
    fn the_settings_pause_ends_when_telemetry_comes_back() {
        // Found by the emulator test of the bring-up: a read just before a motion gave a board
        // that went silent mid-motion 600 ms instead of 100.
        let mut core = DriverCore::new(Config::DEFAULT);
        core.velocity(Velocity::new(0, 100, 0), 0).unwrap();
        assert!(out(&mut core, 0).is_some());
        core.write(Write::MaxSpeed(10), 0).unwrap();
        assert!(out(&mut core, 0).is_some());
        let imu = crate::Imu {
            accel: [0; 3],
            gyro: [0; 3],
            seq: 1,
        };
        for (i, at) in (150..=180).step_by(10).enumerate() {
            let frame = crate::Imu {
                seq: imu.seq.wrapping_add(i as u8),
                ..imu
            }
            .encode();
            let mut rest = &frame[..];
            while !rest.is_empty() {
                rest = core.receive(rest, at).1;
            }
            let _ = core.tick(at);
        }
        assert!(core.last_telemetry_ms().is_some(), "telemetry is back");
        // Silent from 180: stopped after 100 ms, not 600 after the write.
        let _ = core.tick(280);
        assert_eq!(out(&mut core, 280), None);
        let _ = core.tick(281);
        assert_eq!(out(&mut core, 281).as_deref(), Some(&STOP[..]));
    }

    #[test]
    fn telemetry_on_its_way_before_a_reply_does_not_end_the_settings_pause() {
        // Found by the emulator's noisy bring-up (one run in a few): a register read while
        // moving, two IMU frames the board had sent before taking the read parsed right after
        // it, then the reply, then the board's pause: the failsafe stopped the chassis.
        let mut core = DriverCore::new(Config::DEFAULT);
        let imu = |core: &mut DriverCore, seq: u8, at: u64| {
            let frame = crate::Imu {
                accel: [0; 3],
                gyro: [0; 3],
                seq,
            }
            .encode();
            let mut rest = &frame[..];
            while !rest.is_empty() {
                rest = core.receive(rest, at).1;
            }
            let _ = core.tick(at);
        };
        // Telemetry streaming (the parser locked on it), then the read.
        for seq in 1..=5 {
            imu(&mut core, seq, 0);
        }
        assert!(core.last_telemetry_ms().is_some());
        core.velocity(Velocity::new(0, 100, 0), 0).unwrap();
        assert!(out(&mut core, 0).is_some());
        core.start(Request::Read(Register::MaxSpeed)).unwrap();
        assert!(out(&mut core, 0).is_some());
        imu(&mut core, 6, 1);
        imu(&mut core, 7, 2);
        reply(&mut core, Register::MaxSpeed, 0, 3);
        // The board pauses for 150 ms after the reply: no stop.
        let _ = core.tick(160);
        assert_eq!(out(&mut core, 160), None);
        assert_eq!(core.failsafe_stops(), 0);
    }

    #[test]
    fn reads_a_silent_board_leaves_unanswered_never_hold_the_failsafe_off() {
        // The pause idle_core's answered read allows (600 ms from 0) over, the board heard at
        // 700, moving, then silent; a read started again as soon as one gives up (another
        // thread's loop): the stop still comes failsafe_ms after the board was last heard.
        let mut core = idle_core();
        reply(&mut core, Register::MaxSpeed, 1_000, 700);
        // Moving from the core's time now (the reply was taken in at 705, on a quiet line).
        let heard = core.now_ms();
        let mut now = heard;
        core.velocity(Velocity::new(0, 100, 0), now).unwrap();
        assert!(out(&mut core, now).is_some());
        let mut stopped = None;
        while now < 2_000 && stopped.is_none() {
            if !core.busy() {
                core.start(Request::Read(Register::MotorVoltage)).unwrap();
            }
            for _ in 0..20 {
                now += 1;
                let _ = core.tick(now);
                while let Some(frame) = out(&mut core, now) {
                    if frame == STOP {
                        stopped = Some(now);
                    }
                }
            }
        }
        let stopped = stopped.expect("the failsafe never stopped the chassis");
        assert!(
            stopped <= heard + u64::from(Config::DEFAULT.failsafe_ms) + 2,
            "stopped {} ms after the board was last heard",
            stopped - heard
        );
        assert_eq!(core.failsafe_stops(), 1);
    }

    #[test]
    fn a_read_unanswered_ends_the_pause_an_answered_read_allowed() {
        // Moving, reads answered (each allows the board a telemetry pause, A13), then the board
        // goes silent: the next read goes unanswered, and the stop comes failsafe_ms after the
        // last frame heard, not settings_pause_ms after the last read answered.
        let mut core = idle_core();
        let mut now = 700;
        core.velocity(Velocity::new(0, 100, 0), now).unwrap();
        assert!(out(&mut core, now).is_some());
        core.start(Request::Read(Register::MaxSpeed)).unwrap();
        assert!(out(&mut core, now).is_some());
        reply(&mut core, Register::MaxSpeed, 1_000, now + 1);
        assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(1_000))));
        let heard = now + 1;
        now = core.now_ms();
        core.start(Request::Read(Register::MotorVoltage)).unwrap();
        assert!(out(&mut core, now).is_some());
        let mut stopped = None;
        while now < 2_000 && stopped.is_none() {
            now += 1;
            let _ = core.tick(now);
            if out(&mut core, now).as_deref() == Some(&STOP[..]) {
                stopped = Some(now);
            }
        }
        let stopped = stopped.expect("the failsafe never stopped the chassis");
        assert!(
            stopped <= heard + u64::from(Config::DEFAULT.failsafe_ms) + 2,
            "stopped {} ms after the board was last heard",
            stopped - heard
        );
    }

    #[test]
    fn stop_cancels_an_outstanding_turn() {
        let mut core = idle_core();
        core.turn(Turn::by_deci_degrees(900), 10).unwrap();
        assert!(out(&mut core, 10).is_some());
        core.stop();
        assert_eq!(out(&mut core, 100).as_deref(), Some(&STOP[..]));
        let read = out(&mut core, 100).unwrap();
        assert_eq!(read, [0xFF, 0xFE, 0x80, 0x80, 0x20, 0, 0, 0, 0, 0]);
        // A damaged reply (more than the turn) is not believed: read again.
        reply(&mut core, Register::PendingAngle, 8_100, 101);
        let again = out(&mut core, 106).unwrap();
        assert_eq!(again, read);
        reply(&mut core, Register::PendingAngle, 810, 107);
        let counter = out(&mut core, 112).unwrap();
        // −81.0°: angle mode (bit 4) and Z reverse (bit 0).
        assert_eq!(counter, [0xFF, 0xFE, 0x01, 0, 0, 0, 0, 0x03, 0x2A, 0x11]);
        assert_eq!(core.take_outcome(), Some(Ok(Outcome::Done)));
        assert!(!core.turning());
    }

    #[test]
    fn the_failsafe_cancels_a_turn_once_the_board_answers_again() {
        let mut core = idle_core();
        core.turn(Turn::by_deci_degrees(900), 10).unwrap();
        assert!(out(&mut core, 10).is_some());
        // Silent after the read of the pending angle (at 0: the settings pause allows 600 ms):
        // the stop at 601, then the pending angle asked for, again and again.
        let _ = core.tick(600);
        assert_eq!(out(&mut core, 600), None);
        let _ = core.tick(601);
        assert_eq!(out(&mut core, 601).as_deref(), Some(&STOP[..]));
        let mut reads = 0;
        let mut now = 601;
        while now < 1_600 {
            let _ = core.tick(now);
            if let Some(frame) = out(&mut core, now) {
                assert_eq!(frame, [0xFF, 0xFE, 0x80, 0x80, 0x20, 0, 0, 0, 0, 0]);
                reads += 1;
            }
            now += 1;
        }
        assert!(reads >= 3, "{reads} reads of the pending angle in 1 s");
        assert!(core.turning(), "the guard holds while nothing is known");
        // A user's read goes first; then the board answers the cancel's read.
        core.start(Request::Read(Register::MaxSpeed)).unwrap();
        loop {
            let _ = core.tick(now);
            if let Some(frame) = out(&mut core, now) {
                if frame[4] == 0x11 {
                    break;
                }
            }
            now += 1;
            assert!(now < 3_000, "the user's read never went");
        }
        reply(&mut core, Register::MaxSpeed, 1_000, now + 1);
        assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(1_000))));
        let mut now = now + 10;
        let read = loop {
            let _ = core.tick(now);
            if let Some(frame) = out(&mut core, now) {
                break frame;
            }
            now += 1;
            assert!(now < 5_000, "the cancel never came back");
        };
        assert_eq!(read[4], 0x20);
        reply(&mut core, Register::PendingAngle, 450, now + 1);
        let counter = out(&mut core, now + 6).unwrap();
        // −45.0°
        assert_eq!(counter, [0xFF, 0xFE, 0x01, 0, 0, 0, 0, 0x01, 0xC2, 0x11]);
        assert!(!core.turning());
        assert_eq!(
            core.take_outcome(),
            None,
            "nobody waits for the core's own cancel"
        );
    }

    #[test]
    fn time_from_a_wrapping_u32_counter_keeps_the_failsafe() {
        let mut core = DriverCore::new(Config::DEFAULT);
        let start = u64::from(u32::MAX) - 50;
        core.velocity(Velocity::new(0, 100, 0), start).unwrap();
        assert!(out(&mut core, start).is_some());
        let _ = core.tick(u64::from(u32::MAX));
        assert_eq!(out(&mut core, u64::from(u32::MAX)), None);
        // Across the wrap (u32::MAX → 0 is one millisecond): 100 ms after the last command,
        // not yet; 101 ms, stopped.
        let _ = core.tick(49);
        assert_eq!(out(&mut core, 49), None);
        let _ = core.tick(50);
        assert_eq!(out(&mut core, 50).as_deref(), Some(&STOP[..]));
    }

    #[test]
    fn rates_hold_for_frames_read_in_batches() {
        let mut info = StreamInfo::default();
        // A 1 Hz loop reading 100 frames a second, all stamped with the read's time.
        for second in 1..=3u64 {
            for _ in 0..100 {
                info.arrived(second * 1_000, 0);
            }
        }
        assert_eq!(info.rate_hz(), 100);
    }
}
