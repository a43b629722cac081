//! [`DriverCore`] for the board's 2020 firmware (`FF FE` frames): every policy of the driver,
//! with no I/O and no clock.
//!
//! The shells ([`blocking`](super::blocking), [`asynch`](super::asynch)) only move bytes and
//! time between a UART and this core; everything that decides lives here, once:
//!
//! * **Frames out, whole and in order.** Every frame (motion, settings, a request's reads, the
//!   failsafe's stop) is put in the core's one-frame slot and handed out by
//!   [`DriverCore::transmit`]; the UART's progress comes back through
//!   [`DriverCore::transmitted`]. A write cut short leaves the rest in the slot, and nothing
//!   else goes out before it is finished. The wire-independent part of the policy (this slot,
//!   the failsafe, time, stall bounds) is `safety.rs`, generic over the wire format, and the
//!   pump's turn (bytes out, bytes in, time judged) is `pump.rs`, shared with v1.0.0's core.
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
//! comes back (the pause is then over: from there on, 100 ms of silence is a dead link). A read
//! counts once the board has answered it, even if the answer was damaged on the line (bytes
//! after the read that make no frame, then a quiet line): a board that answers no read is
//! silent, not paused. For a read, "comes back" counts only telemetry after the reply: the
//! board answers when it takes the read, so frames heard before the reply were on their way
//! before the pause began.
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

mod ghosts;
mod requests;
#[cfg(test)]
mod tests;

use super::latest::{Stamped, StreamInfo};
use super::pump::{Pump, Rules, core_impl, pump_api};
use super::safety::{FrameKind, Wire};
use super::{Config, CoreError};
use crate::bytes::FrameBytes;
use crate::command::{Action, Motors, Register, Setting, Turn, Velocity, Write};
use crate::parse::{DownlinkParser, DownlinkStats, Lock};
use crate::registers::Snapshot;
use crate::telemetry::{Battery, Downlink, Encoders, Imu, Reply, Stream};
use ghosts::Ghosts;
use requests::Job;

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
    pump: Pump<Ff, DownlinkParser>,
    job: Option<Job>,
    outcome: Option<Result<Outcome, CoreError>>,
    latest: Latest,
    turn: TurnState,
    /// The failsafe stopped the chassis with a turn outstanding: cancel it as soon as the board
    /// answers.
    cancel_wanted: bool,
    ghosts: Ghosts,
}

/// The latest frame of each stream, and each stream's figures.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Latest {
    imu: Option<Stamped<Imu>>,
    encoders: Option<Stamped<Encoders>>,
    battery: Option<Stamped<Battery>>,
    streams: [StreamInfo; 3],
}

// RAM budget of the core (the pump 480: the parser 228 bytes with its 96-byte window, the
// receive buffer 48, the frame being sent and the failsafe's timers; the request in progress
// 112, the unanswered reads 72, latest frames and stream figures 184): 896 bytes on 64-bit
// hosts.
const _: () = assert!(
    core::mem::size_of::<DriverCore>() <= 896,
    "DriverCore over its RAM budget"
);

impl DriverCore {
    /// A core that has heard nothing and sent nothing. Whether the board has a turn pending is
    /// [`TurnState::Unknown`] until the pending angle is read.
    #[must_use]
    pub const fn new(config: Config) -> Self {
        const STREAM: StreamInfo = StreamInfo::new();
        DriverCore {
            pump: Pump::new(config, DownlinkParser::new()),
            job: None,
            outcome: None,
            latest: Latest {
                imu: None,
                encoders: None,
                battery: None,
                streams: [STREAM; 3],
            },
            turn: TurnState::Unknown,
            cancel_wanted: false,
            ghosts: Ghosts::new(),
        }
    }

    /// Changes the configuration, keeping everything else: the turn guard, the frame being
    /// sent, the bytes read, the request in progress, the latest telemetry.
    pub fn set_config(&mut self, config: Config) {
        self.pump.set_config(config);
    }

    pump_api!(Event, Outcome);

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
        self.pump.safety.queue_stop();
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
        let now = self.pump.safety.advance(now_ms);
        match self.turn {
            TurnState::Unknown => return Err(CoreError::TurnStateUnknown),
            TurnState::Turning { .. } => return Err(CoreError::TurnInProgress),
            TurnState::Idle => {}
        }
        let deci_degrees = turn.deci_degrees;
        self.queue_frame(now, Outgoing::new(&turn.encode()), FrameKind::Motion)?;
        self.turn = TurnState::Turning { deci_degrees };
        self.pump.safety.set_moving(true, now);
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
        let now = self.pump.safety.advance(now_ms);
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
            self.pump.safety.set_moving(moving || self.turning(), now);
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
        self.pump.safety.reset_stall();
    }

    // ----- state -----

    /// The latest IMU frame and when it came.
    #[must_use]
    pub const fn imu(&self) -> Option<Stamped<Imu>> {
        self.latest.imu
    }

    /// The latest encoder frame and when it came.
    #[must_use]
    pub const fn encoders(&self) -> Option<Stamped<Encoders>> {
        self.latest.encoders
    }

    /// The latest battery frame and when it came.
    #[must_use]
    pub const fn battery(&self) -> Option<Stamped<Battery>> {
        self.latest.battery
    }

    /// Rate and drops of one stream.
    #[must_use]
    pub fn stream(&self, stream: Stream) -> StreamInfo {
        self.latest
            .streams
            .get(stream.index())
            .copied()
            .unwrap_or_default()
    }

    /// The parser's counters.
    #[must_use]
    pub const fn parser_stats(&self) -> &DownlinkStats {
        self.pump.parser.stats()
    }

    /// How sure the parser is of the frame boundaries.
    #[must_use]
    pub const fn lock(&self) -> Lock {
        self.pump.parser.lock()
    }

    /// How long a read waits for its reply now: [`Config::reply_timeout_ms`], or longer once
    /// a timeout or a late reply has shown the board to be slower (at most
    /// [`Config::late_reply_ms`] more); replies in time bring it back.
    #[must_use]
    pub fn reply_timeout_ms(&self) -> u64 {
        self.ghosts.reply_timeout_ms(&self.pump.config)
    }
}

impl Rules for DriverCore {
    type Wire = Ff;
    type Parser = DownlinkParser;
    type Event = Event;
    type Outcome = Outcome;

    fn pump(&self) -> &Pump<Ff, DownlinkParser> {
        &self.pump
    }
    fn pump_mut(&mut self) -> &mut Pump<Ff, DownlinkParser> {
        &mut self.pump
    }

    fn quiet_ms(config: &Config) -> u64 {
        u64::from(config.idle_ms)
    }

    fn is_reply(frame: &Downlink) -> bool {
        matches!(frame, Downlink::Reply(_))
    }

    // It pauses its telemetry after a read it took (A13).
    const DAMAGED_REPLIES_PAUSE: bool = true;

    fn job_frame(&mut self, now: u64) -> Option<(Outgoing, FrameKind)> {
        self.next_job_frame(now)
    }

    fn sent(&mut self, kind: FrameKind, now: u64) {
        if kind == FrameKind::Read {
            self.read_sent(now);
        }
    }

    fn heard(&mut self, frame: Downlink, at: u64) -> Option<Event> {
        let stream = match frame {
            Downlink::Imu(value) => {
                self.latest.imu = Some(Stamped { value, at_ms: at });
                Stream::Imu
            }
            Downlink::Encoders(value) => {
                self.latest.encoders = Some(Stamped { value, at_ms: at });
                Stream::Encoders
            }
            Downlink::Battery(value) => {
                self.latest.battery = Some(Stamped { value, at_ms: at });
                Stream::Battery
            }
            Downlink::Reply(reply) => return Some(self.reply(reply, at)),
        };
        let missed = self.pump.parser.stats().missed_of(stream);
        if let Some(info) = self.latest.streams.get_mut(stream.index()) {
            info.arrived(at, missed);
        }
        Some(Event::Telemetry(frame))
    }

    fn timeouts(&mut self, now: u64) {
        self.ghosts.expire(now);
        self.check_reply_timeout(now);
    }

    fn failsafe_judged(&mut self, fired: bool) {
        // After the failsafe, the cancel of a turn left outstanding.
        if fired && self.turning() {
            self.cancel_wanted = true;
        }
        if !self.turning() {
            self.cancel_wanted = false;
        } else if self.cancel_wanted && self.job.is_none() {
            self.begin(Request::CancelTurn, true);
        }
    }

    fn job_deadline(&self) -> Option<u64> {
        self.reply_deadline()
    }

    fn busy_for_user(&self) -> bool {
        self.job.is_some_and(|j| !j.background)
    }

    fn take_outcome(&mut self) -> Option<Result<Outcome, CoreError>> {
        self.outcome.take()
    }

    fn abort(&mut self) {
        DriverCore::abort(self);
    }
}

core_impl!(DriverCore, Event, Request, Outcome);
