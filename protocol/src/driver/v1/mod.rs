//! [`DriverCore`] for the board's v1.0.0 firmware (`7B … BCC 7D` frames): the same shells
//! ([`blocking::Driver`](super::blocking::Driver), [`asynch::Driver`](super::asynch::Driver))
//! and the same wire-independent policy as the 2020 core (frames out whole and in order, the
//! failsafe, time, bounded waits: `driver/safety.rs`), over the v1.0.0 frames.
//!
//! What differs, and why:
//!
//! * **The failsafe sends the forced stop** (`0x25` with `ctl = 0` and all zeros): the v1.0.0
//!   board has no documented watchdog and keeps its last velocity until told otherwise.
//! * **The failsafe is at least [`MIN_FAILSAFE_MS`]**: the only frame the board sends unasked is
//!   its telemetry, every 42–50 ms, and it drops a few while it receives commands (about 6 % at
//!   20 commands a second). A [`Config::failsafe_ms`] below 300 ms (the 2020 defaults are 100
//!   and 200) would stop a healthy chassis at the second frame dropped in a row.
//! * **No turn by an angle**: the v1.0.0 protocol has none, and neither has this core nor
//!   `Driver<_, _, v1::DriverCore>`: a turn does not compile.
//! * **Settings are written only when asked** ([`Request::Write`]), each frame at least
//!   [`SETTINGS_GAP_MS`] after the previous settings frame (the vendor's start-up keeps 100 ms
//!   between them; one owner reports a board that never streams without these pauses), and
//!   **confirmed** by reading it back: the write ends [`Outcome::Done`] when the readback
//!   carries what was written, [`CoreError::ReadbackDiffers`] when it does not.
//! * **No frame spans a quiet line**: a line quiet for [`Config::idle_ms`] (at most
//!   [`QUIET_MAX_MS`]) is told to the
//!   parser, which throws away the start of a frame cut short there (a run of one frame's
//!   length lost across a boundary could otherwise join two frames under a matching BCC).
//! * **Replies carry their code**, so a reply is matched to its request by code, and one that
//!   nobody waits for is an [`Event::Reply`]. A reply that comes late answers the next read of
//!   the same code with the board's state a little earlier: a readback is state, not an event,
//!   so the 2020 core's ghosts are not needed.
//!
//! ```
//! # #[cfg(feature = "sim")] {
//! use chassis_protocol::driver::{Config, blocking::Driver, v1};
//! use chassis_protocol::sim::{SimClock, SimUart};
//! use chassis_protocol::sim::v1::{Board, SimConfig};
//! use chassis_protocol::v1::{BodyVelocity, Readback};
//! use core::cell::Cell;
//!
//! let time = Cell::new(0);
//! let uart = SimUart::new(Board::new(SimConfig::default()), &time);
//! let mut driver = Driver::new_v1(uart, SimClock(&time), Config::DEFAULT);
//! driver.set_velocity(BodyVelocity::new(0, 300, 0))?; // 0.3 m/s forward
//! let geometry = driver.geometry()?;                   // a readback, typed
//! assert_eq!(geometry.wheel_diameter_mm, 60);
//! driver.stop()?;                                      // the forced stop
//! # }
//! # Ok::<(), chassis_protocol::driver::Error<core::convert::Infallible>>(())
//! ```

#[cfg(test)]
mod tests;

use super::pump::{Pump, Rules, core_impl, pump_api};
use super::safety::{FrameKind, Wire};
use super::{Config, CoreError, Stamped, StreamInfo};
pub use crate::v1::Settings;
use crate::v1::{
    BodyVelocity, COMMAND_LEN, Command, Downlink, DownlinkParser, MotorVelocity, Readback, Reply,
    Stats, Telemetry,
};

/// The shortest failsafe on v1.0.0: six telemetry periods, so five frames dropped in a row
/// never stop a healthy chassis.
pub const MIN_FAILSAFE_MS: u32 = 300;

/// The longest quiet line the core waits for before it tells its parser: [`Config::idle_ms`] or
/// this, the shorter. v1.0.0 telemetry leaves 39–47 ms of idle line between frames (20–24 Hz), so
/// the host's 40 ms could miss it; 25 ms is still longer than a USB-UART adapter's latency timer
/// (16 ms), the longest gap inside a frame a PC sees.
pub const QUIET_MAX_MS: u32 = 25;

/// The least time between two settings frames (and between a settings frame and the readback
/// that confirms it).
pub const SETTINGS_GAP_MS: u64 = 100;

/// The bytes of one v1.0.0 command frame.
pub type Outgoing = [u8; COMMAND_LEN];

/// The v1.0.0 wire format for the wire-independent policy.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) enum V1 {}

impl Wire for V1 {
    type Frame = Outgoing;

    fn stop() -> Outgoing {
        Command::BodyVelocity(BodyVelocity::FORCED_STOP).encode()
    }
}

/// A request that needs replies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Request {
    /// One readback: sent again on a timeout, up to [`Config::read_tries`] times.
    Read(Readback),
    /// A settings frame, kept [`SETTINGS_GAP_MS`] from the previous one, then read back and
    /// compared.
    Write(Settings),
}

/// How a request ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Outcome {
    /// The reply of a [`Request::Read`].
    Reply(Reply),
    /// A [`Request::Write`] read back as written.
    Done,
}

/// Something the core saw on the line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// A telemetry frame.
    Telemetry(Telemetry),
    /// A reply no request waited for.
    Reply(Reply),
}

/// Where a request stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Phase {
    /// The settings frame is to go (after the gap).
    Write,
    /// The readback is to go (after the gap).
    ToSend,
    /// The readback is in the slot.
    Sending,
    /// The readback has left; its reply is awaited until the deadline.
    Waiting { deadline_ms: u64 },
}

#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Job {
    request: Request,
    phase: Phase,
    tries: u8,
}

impl Job {
    const fn readback(&self) -> Readback {
        match &self.request {
            Request::Read(r) => *r,
            Request::Write(s) => s.readback(),
        }
    }
}

/// Every policy of the driver for a v1.0.0 board, with no I/O and no clock: the shells'
/// [`Core`](super::Core).
#[derive(Clone, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriverCore {
    pump: Pump<V1, DownlinkParser>,
    job: Option<Job>,
    outcome: Option<Result<Outcome, CoreError>>,
    telemetry: Option<Stamped<Telemetry>>,
    stream: StreamInfo,
    last_settings_ms: Option<u64>,
}

impl DriverCore {
    /// A core that has heard nothing and sent nothing. `config`'s failsafe is raised to
    /// [`MIN_FAILSAFE_MS`] if it is shorter.
    #[must_use]
    pub const fn new(config: Config) -> Self {
        const STREAM: StreamInfo = StreamInfo::new();
        let config = Self::floor(config);
        DriverCore {
            pump: Pump::new(config, DownlinkParser::new()),
            job: None,
            outcome: None,
            telemetry: None,
            stream: STREAM,
            last_settings_ms: None,
        }
    }

    const fn floor(mut config: Config) -> Config {
        if config.failsafe_ms < MIN_FAILSAFE_MS {
            config.failsafe_ms = MIN_FAILSAFE_MS;
        }
        config
    }

    /// Changes the configuration (the failsafe raised to [`MIN_FAILSAFE_MS`] if it is shorter),
    /// keeping everything else.
    pub fn set_config(&mut self, config: Config) {
        self.pump.set_config(Self::floor(config));
    }

    pump_api!(Event, Outcome);

    // ----- motion -----

    /// Queues a body velocity. A velocity of zero with `ctl = 0x02` holds the chassis still
    /// under control; [`stop`](Self::stop) sends the forced stop.
    pub fn velocity(&mut self, velocity: BodyVelocity, now_ms: u64) -> Result<(), CoreError> {
        let now = self.pump.safety.advance(now_ms);
        self.pump
            .safety
            .queue(Command::BodyVelocity(velocity).encode(), FrameKind::Motion)?;
        let still = velocity.vx_mm_s == 0 && velocity.vy_mm_s == 0 && velocity.wz_mrad_s == 0;
        self.pump.safety.set_moving(!still, now);
        Ok(())
    }

    /// Queues a per-motor velocity (`0x26`; its unit is the board's own, see
    /// [`MotorVelocity`]).
    pub fn motors(&mut self, motors: MotorVelocity, now_ms: u64) -> Result<(), CoreError> {
        let now = self.pump.safety.advance(now_ms);
        self.pump
            .safety
            .queue(Command::MotorVelocity(motors).encode(), FrameKind::Motion)?;
        self.pump.safety.set_moving(motors.speeds != [0; 4], now);
        Ok(())
    }

    /// Queues the forced stop ahead of everything not yet begun (a frame a cut write left half
    /// sent is finished first). A request in progress goes on.
    pub fn stop(&mut self) {
        self.pump.safety.queue_stop();
    }

    // ----- requests -----

    /// Starts a request ([`CoreError::Busy`] while another runs).
    pub fn start(&mut self, request: Request) -> Result<(), CoreError> {
        if self.job.is_some() {
            return Err(CoreError::Busy);
        }
        self.outcome = None;
        let phase = match request {
            Request::Read(_) => Phase::ToSend,
            Request::Write(_) => Phase::Write,
        };
        self.job = Some(Job {
            request,
            phase,
            tries: 0,
        });
        Ok(())
    }

    /// Ends the request in progress as if it had never started.
    pub fn abort(&mut self) {
        self.job = None;
        self.outcome = None;
        self.pump.safety.reset_stall();
    }

    // ----- state -----

    /// The latest telemetry frame and when it came.
    #[must_use]
    pub const fn telemetry(&self) -> Option<Stamped<Telemetry>> {
        self.telemetry
    }

    /// The telemetry stream's count and rate (`missed` stays 0: v1.0.0 frames carry no count).
    #[must_use]
    pub const fn stream(&self) -> StreamInfo {
        self.stream
    }

    /// The parser's counters: frames, bad BCCs, bytes discarded.
    #[must_use]
    pub const fn parser_stats(&self) -> Stats {
        self.pump.parser.stats()
    }

    /// How long a readback waits for its reply: a request, a telemetry frame that may be on the
    /// wire first and the reply (60 bytes at 10 bits each), plus [`Config::board_latency_ms`].
    #[must_use]
    pub fn reply_timeout_ms(&self) -> u64 {
        const BITS: u64 = (14 + 32 + 14) * 10;
        let baud = u64::from(self.pump.config.baud.max(1));
        (BITS * 1_000)
            .div_ceil(baud)
            .saturating_add(u64::from(self.pump.config.board_latency_ms))
    }

    // ----- inside -----

    /// When the settings gap ends, if one is running.
    fn gap_until(&self) -> Option<u64> {
        self.last_settings_ms
            .map(|t| t.saturating_add(SETTINGS_GAP_MS))
    }

    fn next_job_frame(&mut self, now: u64) -> Option<(Outgoing, FrameKind)> {
        let mut job = self.job?;
        if self.gap_until().is_some_and(|until| now < until) {
            return None;
        }
        let out = match (job.phase, job.request) {
            (Phase::Write, Request::Write(settings)) => {
                job.phase = Phase::ToSend;
                (settings.command().encode(), FrameKind::Settings)
            }
            (Phase::ToSend, _) => {
                job.phase = Phase::Sending;
                job.tries = job.tries.saturating_add(1);
                (Command::Readback(job.readback()).encode(), FrameKind::Read)
            }
            _ => return None,
        };
        self.job = Some(job);
        Some(out)
    }

    fn finish(&mut self, outcome: Result<Outcome, CoreError>) {
        self.job = None;
        self.outcome = Some(outcome);
    }
}

impl Rules for DriverCore {
    type Wire = V1;
    type Parser = DownlinkParser;
    type Event = Event;
    type Outcome = Outcome;

    fn pump(&self) -> &Pump<V1, DownlinkParser> {
        &self.pump
    }
    fn pump_mut(&mut self) -> &mut Pump<V1, DownlinkParser> {
        &mut self.pump
    }

    fn quiet_ms(config: &Config) -> u64 {
        u64::from(config.idle_ms.min(QUIET_MAX_MS))
    }

    fn is_reply(frame: &Downlink) -> bool {
        matches!(frame, Downlink::Reply(_))
    }

    // It pauses for settings frames only, not for readbacks.
    const DAMAGED_REPLIES_PAUSE: bool = false;

    fn job_frame(&mut self, now: u64) -> Option<(Outgoing, FrameKind)> {
        self.next_job_frame(now)
    }

    fn sent(&mut self, kind: FrameKind, now: u64) {
        match kind {
            FrameKind::Settings => self.last_settings_ms = Some(now),
            FrameKind::Read => {
                let timeout = self.reply_timeout_ms();
                if let Some(job) = self.job.as_mut().filter(|j| j.phase == Phase::Sending) {
                    job.phase = Phase::Waiting {
                        deadline_ms: now.saturating_add(timeout),
                    };
                }
            }
            FrameKind::Motion => {}
        }
    }

    fn heard(&mut self, frame: Downlink, at: u64) -> Option<Event> {
        let reply = match frame {
            Downlink::Telemetry(value) => {
                self.telemetry = Some(Stamped { value, at_ms: at });
                self.stream.arrived(at, 0);
                return Some(Event::Telemetry(value));
            }
            Downlink::Reply(reply) => reply,
        };
        let awaited = self.job.filter(|job| {
            matches!(job.phase, Phase::Waiting { .. }) && job.readback() == reply.request
        });
        match awaited.map(|job| job.request) {
            Some(Request::Read(_)) => self.finish(Ok(Outcome::Reply(reply))),
            Some(Request::Write(settings)) => self.finish(if settings.shown_by(&reply) {
                Ok(Outcome::Done)
            } else {
                Err(CoreError::ReadbackDiffers(reply.request))
            }),
            None => return Some(Event::Reply(reply)),
        }
        None
    }

    fn timeouts(&mut self, now: u64) {
        let Some(mut job) = self.job else {
            return;
        };
        let Phase::Waiting { deadline_ms } = job.phase else {
            return;
        };
        if now > deadline_ms {
            // A board that answers nothing is silent, not paused.
            self.pump.safety.read_unanswered();
            if job.tries >= self.pump.config.read_tries.max(1) {
                self.finish(Err(CoreError::NoReadback(job.readback())));
            } else {
                job.phase = Phase::ToSend;
                self.job = Some(job);
            }
        }
    }

    fn failsafe_judged(&mut self, _fired: bool) {}

    fn job_deadline(&self) -> Option<u64> {
        self.job.and_then(|job| match job.phase {
            Phase::Waiting { deadline_ms } => Some(deadline_ms.saturating_add(1)),
            Phase::Write | Phase::ToSend => self.gap_until(),
            Phase::Sending => None,
        })
    }

    fn busy_for_user(&self) -> bool {
        self.job.is_some()
    }

    fn take_outcome(&mut self) -> Option<Result<Outcome, CoreError>> {
        self.outcome.take()
    }

    fn abort(&mut self) {
        DriverCore::abort(self);
    }
}

core_impl!(DriverCore, Event, Request, Outcome);
