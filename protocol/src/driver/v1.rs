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

use super::safety::{FrameKind, Safety, Wire};
use super::sans_io::RxBuffer;
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
    config: Config,
    parser: DownlinkParser,
    safety: Safety<V1>,
    rx: RxBuffer,
    job: Option<Job>,
    outcome: Option<Result<Outcome, CoreError>>,
    telemetry: Option<Stamped<Telemetry>>,
    stream: StreamInfo,
    last_settings_ms: Option<u64>,
    /// When the last byte came, and whether the quiet since has been told to the parser.
    last_byte_ms: Option<u64>,
    quiet_told: bool,
}

impl DriverCore {
    /// A core that has heard nothing and sent nothing. `config`'s failsafe is raised to
    /// [`MIN_FAILSAFE_MS`] if it is shorter.
    #[must_use]
    pub const fn new(config: Config) -> Self {
        const STREAM: StreamInfo = StreamInfo::new();
        let config = Self::floor(config);
        DriverCore {
            config,
            parser: DownlinkParser::new(),
            safety: Safety::new(&config),
            rx: RxBuffer::new(),
            job: None,
            outcome: None,
            telemetry: None,
            stream: STREAM,
            last_settings_ms: None,
            last_byte_ms: None,
            quiet_told: false,
        }
    }

    const fn floor(mut config: Config) -> Config {
        if config.failsafe_ms < MIN_FAILSAFE_MS {
            config.failsafe_ms = MIN_FAILSAFE_MS;
        }
        config
    }

    /// The configuration in force (the failsafe raised to [`MIN_FAILSAFE_MS`]).
    #[must_use]
    pub const fn config(&self) -> &Config {
        &self.config
    }

    /// The core's time (see [`crate::driver`], "Time").
    #[must_use]
    pub const fn now_ms(&self) -> u64 {
        self.safety.now()
    }

    // ----- motion -----

    /// Queues a body velocity. A velocity of zero with `ctl = 0x02` holds the chassis still
    /// under control; [`stop`](Self::stop) sends the forced stop.
    pub fn velocity(&mut self, velocity: BodyVelocity, now_ms: u64) -> Result<(), CoreError> {
        let now = self.safety.advance(now_ms);
        self.safety
            .queue(Command::BodyVelocity(velocity).encode(), FrameKind::Motion)?;
        let still = velocity.vx_mm_s == 0 && velocity.vy_mm_s == 0 && velocity.wz_mrad_s == 0;
        self.safety.set_moving(!still, now);
        Ok(())
    }

    /// Queues a per-motor velocity (`0x26`; its unit is the board's own, see
    /// [`MotorVelocity`]).
    pub fn motors(&mut self, motors: MotorVelocity, now_ms: u64) -> Result<(), CoreError> {
        let now = self.safety.advance(now_ms);
        self.safety
            .queue(Command::MotorVelocity(motors).encode(), FrameKind::Motion)?;
        self.safety.set_moving(motors.speeds != [0; 4], now);
        Ok(())
    }

    /// Queues the forced stop ahead of everything not yet begun (a frame a cut write left half
    /// sent is finished first). A request in progress goes on.
    pub fn stop(&mut self) {
        self.safety.queue_stop();
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
        self.safety.reset_stall();
    }

    /// Whether a request is in progress.
    #[must_use]
    pub const fn busy(&self) -> bool {
        self.job.is_some()
    }

    /// How the last request ended, once it has (taken once).
    pub fn take_outcome(&mut self) -> Option<Result<Outcome, CoreError>> {
        self.outcome.take()
    }

    /// The request's end, if it has ended, or [`CoreError::ClockStalled`] once `limit` calls in
    /// a row saw the clock stand still.
    pub fn settle(&mut self, now_ms: u64, limit: u32) -> Option<Result<Outcome, CoreError>> {
        let now = self.safety.advance(now_ms);
        if let Some(outcome) = self.outcome.take() {
            self.safety.reset_stall();
            return Some(outcome);
        }
        if self.job.is_none() {
            self.safety.reset_stall();
            return Some(Err(CoreError::Aborted));
        }
        if self.safety.stalled(now, limit) {
            self.abort();
            return Some(Err(CoreError::ClockStalled));
        }
        None
    }

    // ----- the pump -----

    /// The bytes to write now: the rest of a frame going out, else the next (a stop first, then
    /// the request's frame once its gap has passed).
    pub fn transmit(&mut self, now_ms: u64) -> Option<&[u8]> {
        let now = self.safety.advance(now_ms);
        if self.safety.slot_free() && !self.safety.load_stop() {
            if let Some((frame, kind)) = self.next_job_frame(now) {
                self.safety.load(frame, kind);
            }
        }
        self.safety.pending()
    }

    /// The UART took `n` of the bytes [`transmit`](Self::transmit) gave.
    pub fn transmitted(&mut self, n: usize, now_ms: u64) {
        let now = self.safety.advance(now_ms);
        match self.safety.transmitted(n) {
            Some(FrameKind::Settings) => self.last_settings_ms = Some(now),
            Some(FrameKind::Read) => {
                let timeout = self.reply_timeout_ms();
                if let Some(job) = self.job.as_mut().filter(|j| j.phase == Phase::Sending) {
                    job.phase = Phase::Waiting {
                        deadline_ms: now.saturating_add(timeout),
                    };
                }
            }
            _ => {}
        }
    }

    /// Feeds received bytes; the first event they complete and the bytes not yet consumed.
    pub fn receive<'a>(&mut self, bytes: &'a [u8], now_ms: u64) -> (Option<Event>, &'a [u8]) {
        let now = self.safety.advance(now_ms);
        if !bytes.is_empty() {
            self.byte_came(now);
        }
        let mut rest = bytes;
        while let Some((byte, tail)) = rest.split_first() {
            rest = tail;
            if let Some(frame) = self.parser.push(*byte) {
                return (self.frame(frame, now), rest);
            }
        }
        (None, rest)
    }

    /// Where a shell reads the UART into.
    pub fn rx_space(&mut self) -> &mut [u8] {
        self.rx.space()
    }

    /// `n` bytes were read into [`rx_space`](Self::rx_space).
    pub fn rx_filled(&mut self, n: usize) {
        self.rx.filled(n);
    }

    /// Feeds the bytes read until one completes an event. A frame found inside a damaged one
    /// comes out at the next call.
    pub fn drain(&mut self, now_ms: u64) -> Option<Event> {
        let now = self.safety.advance(now_ms);
        loop {
            if let Some(frame) = self.parser.poll() {
                if let Some(event) = self.frame(frame, now) {
                    return Some(event);
                }
                continue;
            }
            let (&byte, _) = self.rx.pending().split_first()?;
            self.byte_came(now);
            let left = self.rx.pending().len().saturating_sub(1);
            self.rx.left(left);
            if let Some(frame) = self.parser.push(byte) {
                if let Some(event) = self.frame(frame, now) {
                    return Some(event);
                }
            }
        }
    }

    /// Judges time: a quiet line (told to the parser: no frame spans one), the reply timeout
    /// (retry or error) and the failsafe (a forced stop queued). Call it once every byte the
    /// UART holds has gone through [`drain`](Self::drain).
    pub fn tick(&mut self, now_ms: u64) -> Option<Event> {
        let now = self.safety.advance(now_ms);
        if let Some(last) = self.last_byte_ms {
            if !self.quiet_told && now.saturating_sub(last) >= self.quiet_ms() {
                self.parser.quiet();
                self.quiet_told = true;
            }
        }
        if let Some(mut job) = self.job {
            if let Phase::Waiting { deadline_ms } = job.phase {
                if now > deadline_ms {
                    // A board that answers nothing is silent, not paused.
                    self.safety.read_unanswered();
                    if job.tries >= self.config.read_tries.max(1) {
                        self.finish(Err(CoreError::NoReadback(job.readback())));
                    } else {
                        job.phase = Phase::ToSend;
                        self.job = Some(job);
                    }
                }
            }
        }
        self.safety.check_failsafe(now);
        None
    }

    /// The next time [`tick`](Self::tick) or [`transmit`](Self::transmit) may have something
    /// to do (a reply deadline, a settings gap ending, the failsafe).
    #[must_use]
    pub fn next_deadline(&self) -> Option<u64> {
        let job = self.job.and_then(|job| match job.phase {
            Phase::Waiting { deadline_ms } => Some(deadline_ms.saturating_add(1)),
            Phase::Write | Phase::ToSend => self.gap_until(),
            Phase::Sending => None,
        });
        let failsafe = self.safety.failsafe_deadline().map(|d| d.saturating_add(1));
        let quiet = match (self.last_byte_ms, self.parser.buffered()) {
            (Some(t), 1..) if !self.quiet_told => Some(t.saturating_add(self.quiet_ms())),
            _ => None,
        };
        [job, failsafe, quiet].into_iter().flatten().min()
    }

    /// How long from the clock reading `now_ms` until [`next_deadline`](Self::next_deadline).
    #[must_use]
    pub fn wait_ms(&self, now_ms: u64) -> Option<u64> {
        let now = self.safety.peek(now_ms);
        self.next_deadline().map(|due| due.saturating_sub(now))
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
        self.parser.stats()
    }

    /// Times the failsafe has stopped the chassis.
    #[must_use]
    pub const fn failsafe_stops(&self) -> u32 {
        self.safety.failsafe_stops()
    }

    /// Whether the board was heard within the failsafe time of the clock reading `now_ms`.
    #[must_use]
    pub fn link_alive(&self, now_ms: u64) -> bool {
        self.safety.link_alive(self.safety.peek(now_ms))
    }

    /// Whether the driver last told the chassis to move, and the failsafe has not stopped it.
    #[must_use]
    pub const fn moving(&self) -> bool {
        self.safety.moving()
    }

    /// When the last frame of any kind came.
    #[must_use]
    pub const fn last_heard_ms(&self) -> Option<u64> {
        self.safety.last_heard_ms()
    }

    /// How long a readback waits for its reply: a request, a telemetry frame that may be on the
    /// wire first and the reply (60 bytes at 10 bits each), plus [`Config::board_latency_ms`].
    #[must_use]
    pub fn reply_timeout_ms(&self) -> u64 {
        const BITS: u64 = (14 + 32 + 14) * 10;
        let baud = u64::from(self.config.baud.max(1));
        (BITS * 1_000)
            .div_ceil(baud)
            .saturating_add(u64::from(self.config.board_latency_ms))
    }

    // ----- inside -----

    /// How long a quiet line is, in ms.
    fn quiet_ms(&self) -> u64 {
        u64::from(self.config.idle_ms.min(QUIET_MAX_MS))
    }

    /// A byte came at `now`: the line is not quiet.
    fn byte_came(&mut self, now: u64) {
        self.last_byte_ms = Some(now);
        self.quiet_told = false;
    }

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

    fn frame(&mut self, frame: Downlink, now: u64) -> Option<Event> {
        match frame {
            Downlink::Telemetry(value) => {
                self.safety.telemetry(now);
                self.telemetry = Some(Stamped { value, at_ms: now });
                self.stream.arrived(now, 0);
                Some(Event::Telemetry(value))
            }
            Downlink::Reply(reply) => {
                self.safety.reply_heard(now);
                let awaited = self.job.filter(|job| {
                    matches!(job.phase, Phase::Waiting { .. }) && job.readback() == reply.request
                });
                match awaited.map(|job| job.request) {
                    Some(Request::Read(_)) => {
                        self.finish(Ok(Outcome::Reply(reply)));
                        None
                    }
                    Some(Request::Write(settings)) => {
                        self.finish(if settings.shown_by(&reply) {
                            Ok(Outcome::Done)
                        } else {
                            Err(CoreError::ReadbackDiffers(reply.request))
                        });
                        None
                    }
                    None => Some(Event::Reply(reply)),
                }
            }
        }
    }
}

impl super::Core for DriverCore {
    type Event = Event;
    type Request = Request;
    type Outcome = Outcome;

    fn set_config(&mut self, config: Config) {
        self.config = Self::floor(config);
        self.safety.set_config(&self.config);
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
        self.busy()
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
    use crate::v1::{Geometry, Pid, SystemSettings};

    /// The forced stop, from PROTOCOL-V1.md: `0x25`, ten `00`, BCC `7B ^ 25 = 5E`.
    const FORCED_STOP: [u8; 14] = [0x7B, 0x25, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x5E, 0x7D];
    /// The vendor's readback request of the system settings.
    const READ_SYSTEM: [u8; 14] = [0x7B, 0x33, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x48, 0x7D];

    /// Everything the core has to send now, each frame taken whole.
    fn out(core: &mut DriverCore, now: u64) -> Vec<Vec<u8>> {
        let mut frames = Vec::new();
        while let Some(bytes) = core.transmit(now) {
            let bytes = bytes.to_vec();
            core.transmitted(bytes.len(), now);
            frames.push(bytes);
        }
        frames
    }

    fn hear(core: &mut DriverCore, bytes: &[u8], now: u64) -> Vec<Event> {
        let mut events = Vec::new();
        let mut rest = bytes;
        loop {
            let (event, left) = core.receive(rest, now);
            events.extend(event);
            if left.is_empty() {
                break;
            }
            rest = left;
        }
        events
    }

    fn telemetry() -> [u8; 32] {
        Telemetry {
            battery_mv: 12_000,
            quaternion: [1000, 0, 0, 0],
            ..Telemetry::default()
        }
        .encode()
    }

    fn driving(now: u64) -> DriverCore {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.velocity(BodyVelocity::new(0, 300, 0), now).unwrap();
        assert_eq!(out(&mut core, now).len(), 1);
        core
    }

    #[test]
    fn the_failsafe_sends_the_forced_stop_and_is_at_least_300_ms() {
        assert_eq!(DriverCore::new(Config::DEFAULT).config().failsafe_ms, 300);
        assert_eq!(DriverCore::new(Config::HOST).config().failsafe_ms, 300);
        let long = Config {
            failsafe_ms: 500,
            ..Config::DEFAULT
        };
        assert_eq!(DriverCore::new(long).config().failsafe_ms, 500);

        let mut core = driving(0);
        hear(&mut core, &telemetry(), 10);
        core.tick(310);
        assert!(
            out(&mut core, 310).is_empty(),
            "300 ms of silence is allowed"
        );
        core.tick(311);
        assert_eq!(out(&mut core, 311), vec![FORCED_STOP.to_vec()]);
        assert_eq!(core.failsafe_stops(), 1);
        assert!(!core.moving());
        core.tick(2_000);
        assert!(out(&mut core, 2_000).is_empty(), "sent once");
    }

    #[test]
    fn readbacks_a_silent_board_leaves_unanswered_never_hold_the_failsafe_off() {
        // Heard at 10, then silent; a readback asked for again as soon as one gives up (another
        // thread's loop): the forced stop still comes 300 ms after the last frame heard.
        let mut core = driving(0);
        hear(&mut core, &telemetry(), 10);
        let mut stopped = None;
        let mut now = 10;
        while now < 2_000 && stopped.is_none() {
            if !core.busy() {
                core.start(Request::Read(Readback::Geometry)).unwrap();
            }
            now += 1;
            core.tick(now);
            if out(&mut core, now).contains(&FORCED_STOP.to_vec()) {
                stopped = Some(now);
            }
        }
        assert_eq!(
            stopped,
            Some(311),
            "the forced stop 300 ms after the board was last heard"
        );
        assert_eq!(core.failsafe_stops(), 1);
    }

    #[test]
    fn a_readback_unanswered_ends_the_pause_an_answered_one_allowed() {
        // Moving, a readback answered at 20 (it allows the board a telemetry pause, A13), then
        // the board silent: the next readback goes unanswered, and the forced stop comes 300 ms
        // after the reply, not settings_pause_ms after the readback.
        let mut core = driving(0);
        hear(&mut core, &telemetry(), 10);
        core.start(Request::Read(Readback::Geometry)).unwrap();
        assert_eq!(out(&mut core, 10).len(), 1);
        let reply = Reply {
            request: Readback::Geometry,
            payload: [0; 10],
        }
        .encode();
        assert!(hear(&mut core, &reply, 20).is_empty());
        assert!(matches!(core.take_outcome(), Some(Ok(Outcome::Reply(_)))));
        core.start(Request::Read(Readback::Geometry)).unwrap();
        let mut stopped = None;
        let mut now = 20;
        while now < 2_000 && stopped.is_none() {
            core.tick(now);
            if out(&mut core, now).contains(&FORCED_STOP.to_vec()) {
                stopped = Some(now);
            }
            now += 1;
        }
        assert_eq!(stopped, Some(321), "the forced stop 300 ms after the reply");
    }

    #[test]
    fn telemetry_dropped_five_in_a_row_never_trips_the_failsafe() {
        // Frames every 45 ms; five dropped in a row leave a 270 ms gap.
        let mut core = driving(0);
        let mut t = 0;
        for round in 0..200u64 {
            let drop = round % 20 >= 15; // 5 of every 20 missing, in a row
            t += 45;
            if !drop {
                hear(&mut core, &telemetry(), t);
            }
            core.tick(t);
            core.velocity(BodyVelocity::new(0, 300, 0), t).unwrap();
            let sent = out(&mut core, t);
            assert!(!sent.contains(&FORCED_STOP.to_vec()), "stopped at {t} ms");
        }
        assert_eq!(core.failsafe_stops(), 0);
    }

    #[test]
    fn stop_finishes_a_cut_frame_then_sends_the_forced_stop() {
        let velocity = Command::BodyVelocity(BodyVelocity::new(0, 300, 0)).encode();
        for cut in 1..COMMAND_LEN {
            let mut core = DriverCore::new(Config::DEFAULT);
            core.velocity(BodyVelocity::new(0, 300, 0), 0).unwrap();
            let first = core.transmit(0).unwrap().to_vec();
            core.transmitted(cut, 0);
            core.stop();
            let mut wire = first.get(..cut).unwrap().to_vec();
            for frame in out(&mut core, 1) {
                wire.extend(frame);
            }
            let mut expected = velocity.to_vec();
            expected.extend(FORCED_STOP);
            assert_eq!(wire, expected, "cut after {cut} bytes");
        }
    }

    #[test]
    fn a_readback_is_sent_as_the_vendor_sends_it_and_matched_by_code() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::Read(Readback::System)).unwrap();
        assert_eq!(out(&mut core, 0), vec![READ_SYSTEM.to_vec()]);
        // Another code's reply is not the answer: it is an event.
        let pid = Reply {
            request: Readback::Pid,
            payload: [0; 10],
        };
        assert_eq!(hear(&mut core, &pid.encode(), 5), vec![Event::Reply(pid)]);
        assert!(core.busy());
        // 0x33 with 0, 10, 3600 (0E10), 2100 (0834), 165 (00A5): BCC by hand.
        let mut reply = [
            0x7B, 0x33, 0x00, 0x0A, 0x0E, 0x10, 0x08, 0x34, 0x00, 0xA5, 0, 0, 0, 0x7D,
        ];
        reply[12] = reply[..12].iter().fold(0, |a, b| a ^ b);
        assert!(hear(&mut core, &reply, 6).is_empty());
        let Some(Ok(Outcome::Reply(r))) = core.settle(6, 10) else {
            panic!("no outcome");
        };
        assert_eq!(
            r.system(),
            Some(SystemSettings {
                motor_directions: 0,
                encoder_directions: 10,
                pwm_max: 3600,
                pwm_min: 2100,
                encoder_ppr: 165,
            })
        );
    }

    #[test]
    fn an_unanswered_readback_is_sent_read_tries_times_then_fails() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::Read(Readback::Geometry)).unwrap();
        let mut sent = 0;
        let mut t = 0;
        while core.busy() && t < 10_000 {
            sent += out(&mut core, t).len();
            core.tick(t);
            t += 1;
        }
        assert_eq!(sent, usize::from(Config::DEFAULT.read_tries));
        assert_eq!(
            core.take_outcome(),
            Some(Err(CoreError::NoReadback(Readback::Geometry)))
        );
    }

    #[test]
    fn settings_keep_their_gap_and_are_confirmed_by_a_readback() {
        let geometry = Geometry {
            wheel_spacing_mm: 110,
            axle_spacing_mm: 110,
            gear_ratio: 55,
            wheel_diameter_mm: 60,
        };
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::Write(Settings::Geometry(geometry)))
            .unwrap();
        // 0x24: 006E 006E 0037 003C 0000.
        let mut frame = [
            0x7B, 0x24, 0x00, 0x6E, 0x00, 0x6E, 0x00, 0x37, 0x00, 0x3C, 0, 0, 0, 0x7D,
        ];
        frame[12] = frame[..12].iter().fold(0, |a, b| a ^ b);
        assert_eq!(out(&mut core, 1_000), vec![frame.to_vec()]);
        // The readback waits for the gap.
        assert!(out(&mut core, 1_099).is_empty());
        assert_eq!(core.wait_ms(1_099), Some(1));
        let read = out(&mut core, 1_100);
        assert_eq!(read.len(), 1);
        assert_eq!(read[0][1], 0x34);
        let mut reply = frame;
        reply[1] = 0x34;
        reply[12] = reply[..12].iter().fold(0, |a, b| a ^ b);
        hear(&mut core, &reply, 1_105);
        assert_eq!(core.take_outcome(), Some(Ok(Outcome::Done)));

        // A second write: its frame goes (100 ms have passed since the first), its readback
        // waits 100 ms; a readback that differs is said.
        let pid = Pid {
            position_kp: 3000,
            ..Pid::default()
        };
        core.start(Request::Write(Settings::Pid(pid))).unwrap();
        assert_eq!(out(&mut core, 1_110).len(), 1);
        assert!(out(&mut core, 1_209).is_empty());
        let read = out(&mut core, 1_210);
        assert_eq!(read[0][1], 0x50);
        let other = Reply {
            request: Readback::Pid,
            payload: [0; 10],
        };
        hear(&mut core, &other.encode(), 1_215);
        assert_eq!(
            core.take_outcome(),
            Some(Err(CoreError::ReadbackDiffers(Readback::Pid)))
        );
    }

    #[test]
    fn motion_is_never_held_back_by_the_settings_gap() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.start(Request::Write(Settings::Pid(Pid::default())))
            .unwrap();
        assert_eq!(out(&mut core, 0).len(), 1);
        core.stop();
        assert_eq!(out(&mut core, 1), vec![FORCED_STOP.to_vec()]);
    }

    #[test]
    fn the_core_tells_its_parser_of_a_quiet_line() {
        // A's first 4 bytes, then, 45 ms later, B from its byte 4: joined, the BCC matches
        // (v1::tests::a_frame_never_spans_a_quiet_line has the bytes written out).
        let a = Telemetry {
            velocity: [1, 0, 0],
            battery_mv: 12_000,
            ..Telemetry::default()
        }
        .encode();
        let b = Telemetry {
            velocity: [256, 0, 0],
            battery_mv: 11_900,
            ..Telemetry::default()
        }
        .encode();
        let mut core = DriverCore::new(Config::DEFAULT);
        assert!(hear(&mut core, &a[..4], 0).is_empty());
        assert_eq!(
            core.next_deadline(),
            Some(2),
            "the quiet line is a deadline"
        );
        core.tick(2);
        assert!(
            hear(&mut core, &b[4..], 45).is_empty(),
            "nothing made of the two"
        );
        assert_eq!(core.parser_stats().frames, 0);
        // Back to back, the same bytes make a frame: the quiet line is what told them apart.
        let mut blind = DriverCore::new(Config::DEFAULT);
        hear(&mut blind, &a[..4], 0);
        assert_eq!(hear(&mut blind, &b[4..], 1).len(), 1);
    }
}
