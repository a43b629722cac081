//! The pump: what every driver core does the same way, whatever firmware generation it speaks.
//!
//! A core is a [`Pump`] (the limits, the downlink parser, the wire-independent policy of
//! `safety.rs`, the bytes read and not yet parsed, the quiet line) and its generation's own state
//! (the request in progress, the latest frames, the turn guard). The generation tells the pump
//! what it needs to know through [`Rules`]; the pump's turn is written once, here: bytes out
//! whole ([`transmit`], [`transmitted`]), bytes in ([`receive`], [`drain`]), time judged
//! ([`tick`]: the quiet line, the request's timeouts, the failsafe), the next deadline, and the
//! bounded wait for a request's end ([`settle`]). Each core's public methods for these come
//! from [`pump_api!`], so the two cores answer the shells with the same code and the same words.

use super::safety::{FrameKind, Safety, Wire};
use super::{Config, CoreError};
use crate::stream::Parser;

/// The frame a generation's parser gives.
pub(crate) type Heard<R> = <<R as Rules>::Parser as Parser>::Frame;

/// What a driver core shares with every generation's: no I/O, no clock.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Pump<W: Wire, P> {
    /// The limits in force.
    pub(crate) config: Config,
    /// The board → master parser.
    pub(crate) parser: P,
    /// Whole frames out, the failsafe, time, stall bounds.
    pub(crate) safety: Safety<W>,
    /// Bytes read from the UART and not yet parsed.
    pub(crate) rx: RxBuffer,
    /// When the last byte came.
    last_byte_ms: Option<u64>,
    /// Quiet time since the last byte has been told to the parser up to this time.
    quiet_told_ms: Option<u64>,
}

impl<W: Wire, P> Pump<W, P> {
    /// Nothing heard, nothing sent.
    pub(crate) const fn new(config: Config, parser: P) -> Self {
        Pump {
            config,
            parser,
            safety: Safety::new(&config),
            rx: RxBuffer::new(),
            last_byte_ms: None,
            quiet_told_ms: None,
        }
    }

    /// Takes new limits, keeping everything else.
    pub(crate) fn set_config(&mut self, config: Config) {
        self.config = config;
        self.safety.set_config(&config);
    }

    /// Feeds the bytes read to the parser until one completes a frame.
    // Out of line: the parser's one copy (`size_driver`: 364 B).
    #[inline(never)]
    fn parse_read(&mut self) -> Option<P::Frame>
    where
        P: Parser,
    {
        let (frame, rest) = self.parser.push_slice(self.rx.pending());
        let rest = rest.len();
        self.rx.left(rest);
        frame
    }

    /// A byte came at `now`: the line is not quiet.
    fn byte_came(&mut self, now: u64) {
        self.last_byte_ms = Some(now);
        self.quiet_told_ms = None;
    }
}

/// What a firmware generation's core tells the pump. Implemented by each public `DriverCore`.
pub(crate) trait Rules: Sized {
    /// The generation's frames to the board.
    type Wire: Wire;
    /// The generation's board → master parser.
    type Parser: Parser;
    /// What the core reports of the line.
    type Event;
    /// How a request ends well.
    type Outcome;

    /// The shared part.
    fn pump(&self) -> &Pump<Self::Wire, Self::Parser>;
    /// The shared part, mutably.
    fn pump_mut(&mut self) -> &mut Pump<Self::Wire, Self::Parser>;

    /// How long the line must be quiet before the parser is told, in ms.
    fn quiet_ms(config: &Config) -> u64;
    /// Whether a frame from the board answers a request (else it is telemetry).
    fn is_reply(frame: &Heard<Self>) -> bool;
    /// Whether bytes after a read that make no frame, then a quiet line, are taken as the
    /// read's answer damaged on the line, for the failsafe's pause allowance: for a board that
    /// pauses its telemetry after a read it took (the 2020 board, A13), not for one that does
    /// not (there a frame cut short by a dying link must not hold the failsafe off).
    const DAMAGED_REPLIES_PAUSE: bool;

    /// The request's next frame, if one is due at `now`.
    fn job_frame(&mut self, now: u64) -> Option<(<Self::Wire as Wire>::Frame, FrameKind)>;
    /// The last byte of a frame of `kind` left at `now`.
    fn sent(&mut self, kind: FrameKind, now: u64);
    /// A frame from the board, heard at `at` (the failsafe has heard it already): the event to
    /// report, if any (a reply a request took is none).
    fn heard(&mut self, frame: Heard<Self>, at: u64) -> Option<Self::Event>;
    /// Time has reached `now`: the request's reply timeouts (before the failsafe is judged).
    fn timeouts(&mut self, now: u64);
    /// The failsafe was judged (`fired`: it has just queued a stop).
    fn failsafe_judged(&mut self, fired: bool);
    /// The request's next deadline, if any.
    fn job_deadline(&self) -> Option<u64>;

    /// Whether a request the user started is in progress.
    fn busy_for_user(&self) -> bool;
    /// How the last request ended, once it has (taken once).
    fn take_outcome(&mut self) -> Option<Result<Self::Outcome, CoreError>>;
    /// Ends the request in progress as if it had never started.
    fn abort(&mut self);
}

/// The bytes to write now: the rest of the frame going out, else a queued stop, else the
/// request's next frame.
pub(crate) fn transmit<R: Rules>(core: &mut R, now_ms: u64) -> Option<&[u8]> {
    let now = core.pump_mut().safety.advance(now_ms);
    if core.pump().safety.slot_free() && !core.pump_mut().safety.load_stop() {
        if let Some((frame, kind)) = core.job_frame(now) {
            core.pump_mut().safety.load(frame, kind);
        }
    }
    core.pump().safety.pending()
}

/// The UART took `n` of the bytes [`transmit`] gave.
pub(crate) fn transmitted<R: Rules>(core: &mut R, n: usize, now_ms: u64) {
    let safety = &mut core.pump_mut().safety;
    let now = safety.advance(now_ms);
    if let Some(kind) = safety.transmitted(n) {
        core.sent(kind, now);
    }
}

/// A frame the parser gave, at `at`: to the failsafe, then to the generation.
fn hear<R: Rules>(core: &mut R, frame: Heard<R>, at: u64) -> Option<R::Event> {
    let safety = &mut core.pump_mut().safety;
    if R::is_reply(&frame) {
        safety.reply_heard(at);
    } else {
        safety.telemetry(at);
    }
    core.heard(frame, at)
}

/// Feeds `bytes`: the first event they complete and the bytes not yet consumed.
pub(crate) fn receive<'a, R: Rules>(
    core: &mut R,
    bytes: &'a [u8],
    now_ms: u64,
) -> (Option<R::Event>, &'a [u8]) {
    let pump = core.pump_mut();
    let now = pump.safety.advance(now_ms);
    if !bytes.is_empty() {
        pump.byte_came(now);
    }
    let mut rest = bytes;
    loop {
        let (frame, left) = core.pump_mut().parser.push_slice(rest);
        rest = left;
        let Some(frame) = frame else {
            return (None, rest);
        };
        if let Some(event) = hear(core, frame, now) {
            return (Some(event), rest);
        }
    }
}

/// Feeds the bytes read into the pump's buffer until one completes an event.
// Out of line: the parser it runs stays one function, not a copy inlined into a shell's pump
// (`size_driver`: 88 B).
#[inline(never)]
pub(crate) fn drain<R: Rules>(core: &mut R, now_ms: u64) -> Option<R::Event> {
    let pump = core.pump_mut();
    let now = pump.safety.advance(now_ms);
    if !pump.rx.is_empty() {
        pump.byte_came(now);
    }
    // Even with no new byte: a frame found inside a damaged one may wait in the parser.
    loop {
        let frame = core.pump_mut().parse_read()?;
        if let Some(event) = hear(core, frame, now) {
            return Some(event);
        }
    }
}

/// Judges time: a quiet line (told to the parser; a frame that waited for it comes out), the
/// request's timeouts, the failsafe.
pub(crate) fn tick<R: Rules>(core: &mut R, now_ms: u64) -> Option<R::Event> {
    let pump = core.pump_mut();
    let now = pump.safety.advance(now_ms);
    let mut event = None;
    if let Some(last) = pump.last_byte_ms {
        if now.saturating_sub(last) >= R::quiet_ms(&pump.config) {
            // Each stretch of quiet is told once: the time since the last byte, or since it
            // was last told.
            let from = pump.quiet_told_ms.unwrap_or(last);
            let ms = u32::try_from(now.saturating_sub(from)).unwrap_or(u32::MAX);
            pump.quiet_told_ms = Some(now);
            if let Some(frame) = pump.parser.quiet(ms) {
                // Judged now, but heard when its last byte came: the failsafe counts silence
                // from there.
                event = hear(core, frame, last);
            } else if R::DAMAGED_REPLIES_PAUSE {
                // Nothing came out of the bytes before the quiet: if they came after a read,
                // they were its answer, damaged.
                pump.safety.quiet_after_garbage(last);
            }
        }
    }
    // A frame the quiet let out is taken in first (it may be the awaited reply); time is judged
    // either way, so frames held in the parser never delay the failsafe.
    core.timeouts(now);
    let fired = core.pump_mut().safety.check_failsafe(now);
    core.failsafe_judged(fired);
    event
}

/// The next time [`tick`] or [`transmit`] may have something to do, on the core's clock.
pub(crate) fn next_deadline<R: Rules>(core: &R) -> Option<u64> {
    let pump = core.pump();
    let failsafe = pump.safety.failsafe_deadline().map(|d| d.saturating_add(1));
    let quiet = match (pump.last_byte_ms, pump.parser.buffered()) {
        (Some(t), 1..) if pump.quiet_told_ms.is_none() => {
            Some(t.saturating_add(R::quiet_ms(&pump.config)))
        }
        _ => None,
    };
    [core.job_deadline(), failsafe, quiet]
        .into_iter()
        .flatten()
        .min()
}

/// How long from the clock reading `now_ms` until [`next_deadline`].
pub(crate) fn wait_ms<R: Rules>(core: &R, now_ms: u64) -> Option<u64> {
    let now = core.pump().safety.peek(now_ms);
    next_deadline(core).map(|due| due.saturating_sub(now))
}

/// The request's end, if it has ended, or [`CoreError::ClockStalled`] once `limit` calls in a
/// row saw the clock stand still (the request is then aborted).
pub(crate) fn settle<R: Rules>(
    core: &mut R,
    now_ms: u64,
    limit: u32,
) -> Option<Result<R::Outcome, CoreError>> {
    let now = core.pump_mut().safety.advance(now_ms);
    if let Some(outcome) = core.take_outcome() {
        core.pump_mut().safety.reset_stall();
        return Some(outcome);
    }
    if !core.busy_for_user() {
        // Ended without an outcome: the core's own request took its place.
        core.pump_mut().safety.reset_stall();
        return Some(Err(CoreError::Aborted));
    }
    if core.pump_mut().safety.stalled(now, limit) {
        core.abort();
        return Some(Err(CoreError::ClockStalled));
    }
    None
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

/// The public methods every core has, in one text: the pump's turn for the shells, the request's
/// end, and the state of the link. Used inside each core's `impl` block; `$event` and
/// `$outcome` are the core's own types, and the core has fields `pump` and `job` (an `Option`).
macro_rules! pump_api {
    ($event:ty, $outcome:ty) => {
        /// The configuration in force.
        #[must_use]
        pub const fn config(&self) -> &$crate::driver::Config {
            &self.pump.config
        }

        /// The core's time: the latest clock reading it was given, made monotonic (see
        /// [`crate::driver`], "Time"). Every time the core reports ([`Stamped`](crate::driver::Stamped), rates) is on
        /// it.
        #[must_use]
        pub const fn now_ms(&self) -> u64 {
            self.pump.safety.now()
        }

        /// The bytes to write to the UART now, if any: the rest of a frame already going out,
        /// else the next frame (a stop first, then the request's frames, each put in the slot
        /// whole). Tell the core how many the UART took with
        /// [`transmitted`](Self::transmitted); until then the same bytes come out again.
        pub fn transmit(&mut self, now_ms: u64) -> Option<&[u8]> {
            $crate::driver::pump::transmit(self, now_ms)
        }

        /// The UART took `n` of the bytes [`transmit`](Self::transmit) gave. A read's reply
        /// timeout starts when its last byte has left.
        pub fn transmitted(&mut self, n: usize, now_ms: u64) {
            $crate::driver::pump::transmitted(self, n, now_ms);
        }

        /// Feeds received bytes; returns the first event they complete and the bytes not yet
        /// consumed (feed them again: nothing is dropped).
        pub fn receive<'a>(&mut self, bytes: &'a [u8], now_ms: u64) -> (Option<$event>, &'a [u8]) {
            $crate::driver::pump::receive(self, bytes, now_ms)
        }

        /// Where a shell reads the UART into (call only when [`rx_empty`](Self::rx_empty)),
        /// then [`rx_filled`](Self::rx_filled) with the count read. The bytes are the core's:
        /// they survive a dropped future, an error and a rebuilt driver.
        pub fn rx_space(&mut self) -> &mut [u8] {
            self.pump.rx.space()
        }

        /// Records that `n` bytes were read into [`rx_space`](Self::rx_space).
        pub fn rx_filled(&mut self, n: usize) {
            self.pump.rx.filled(n);
        }

        /// Whether every byte read into [`rx_space`](Self::rx_space) has gone through the
        /// parser.
        #[must_use]
        pub const fn rx_empty(&self) -> bool {
            self.pump.rx.is_empty()
        }

        /// Feeds the bytes read into [`rx_space`](Self::rx_space) to the parser until one
        /// completes an event. A frame found inside a damaged one comes out at the next call.
        pub fn drain(&mut self, now_ms: u64) -> Option<$event> {
            $crate::driver::pump::drain(self, now_ms)
        }

        /// Judges time: a quiet line (a frame that waited for one comes out: call until
        /// `None`), the reply timeout (retry or error), the failsafe (a stop queued for
        /// [`transmit`](Self::transmit)). Call it once every byte the UART holds has gone
        /// through [`receive`](Self::receive) or [`drain`](Self::drain).
        pub fn tick(&mut self, now_ms: u64) -> Option<$event> {
            $crate::driver::pump::tick(self, now_ms)
        }

        /// The next time [`tick`](Self::tick) or [`transmit`](Self::transmit) may have
        /// something to do (a reply deadline, a held read, the failsafe, a quiet line), on the
        /// core's clock ([`now_ms`](Self::now_ms)).
        #[must_use]
        pub fn next_deadline(&self) -> Option<u64> {
            $crate::driver::pump::next_deadline(self)
        }

        /// How long from the clock reading `now_ms` until
        /// [`next_deadline`](Self::next_deadline), in ms (0 if it has passed), for a shell that
        /// sleeps until then.
        #[must_use]
        pub fn wait_ms(&self, now_ms: u64) -> Option<u64> {
            $crate::driver::pump::wait_ms(self, now_ms)
        }

        /// Whether a request is in progress (the core's own included).
        #[must_use]
        pub const fn busy(&self) -> bool {
            self.job.is_some()
        }

        /// Whether a request the user started is in progress.
        #[must_use]
        pub fn busy_for_user(&self) -> bool {
            $crate::driver::pump::Rules::busy_for_user(self)
        }

        /// How the last request ended, once it has (taken once).
        pub fn take_outcome(&mut self) -> Option<Result<$outcome, $crate::driver::CoreError>> {
            $crate::driver::pump::Rules::take_outcome(self)
        }

        /// What a shell asks after each turn of its pump while a request runs: the request's
        /// end, if it has ended, or [`CoreError::ClockStalled`](crate::driver::CoreError::ClockStalled) once `limit` turns in a row saw
        /// the clock stand still, whatever bytes came meanwhile: time will never end the wait.
        /// A stalled request is aborted.
        pub fn settle(
            &mut self,
            now_ms: u64,
            limit: u32,
        ) -> Option<Result<$outcome, $crate::driver::CoreError>> {
            $crate::driver::pump::settle(self, now_ms, limit)
        }

        /// Times the failsafe has stopped the chassis.
        #[must_use]
        pub const fn failsafe_stops(&self) -> u32 {
            self.pump.safety.failsafe_stops()
        }

        /// Whether the board has been heard (a frame of any kind) within
        /// [`Config::failsafe_ms`](crate::driver::Config::failsafe_ms) of the clock reading `now_ms`.
        #[must_use]
        pub fn link_alive(&self, now_ms: u64) -> bool {
            self.pump.safety.link_alive(self.pump.safety.peek(now_ms))
        }

        /// Whether the driver last told the chassis to move, and the failsafe has not stopped
        /// it since.
        #[must_use]
        pub const fn moving(&self) -> bool {
            self.pump.safety.moving()
        }

        /// When the last telemetry frame came.
        #[must_use]
        pub const fn last_telemetry_ms(&self) -> Option<u64> {
            self.pump.safety.last_telemetry_ms()
        }

        /// When the last frame of any kind (telemetry or reply) came.
        #[must_use]
        pub const fn last_heard_ms(&self) -> Option<u64> {
            self.pump.safety.last_heard_ms()
        }

        /// What has come from the board, judged at `now_ms` (for
        /// [`words_heard`]($crate::driver::host::words_heard)).
        #[cfg(feature = "std")]
        #[must_use]
        pub fn heard(&self, now_ms: u64) -> $crate::driver::host::Heard {
            $crate::driver::host::Heard::from_link(
                self.last_heard_ms(),
                self.link_alive(now_ms),
                self.parser_stats().discarded,
            )
        }
    };
}

/// The shells' [`Core`](super::Core) for a core whose public methods [`pump_api!`] wrote.
macro_rules! core_impl {
    ($core:ty, $event:ty, $request:ty, $outcome:ty) => {
        impl $crate::driver::Core for $core {
            type Event = $event;
            type Request = $request;
            type Outcome = $outcome;

            fn set_config(&mut self, config: $crate::driver::Config) {
                <$core>::set_config(self, config);
            }
            fn start(&mut self, request: $request) -> Result<(), $crate::driver::CoreError> {
                <$core>::start(self, request)
            }
            fn stop(&mut self) {
                <$core>::stop(self);
            }
            fn abort(&mut self) {
                <$core>::abort(self);
            }
            fn busy_for_user(&self) -> bool {
                <$core>::busy_for_user(self)
            }
            fn settle(
                &mut self,
                now_ms: u64,
                limit: u32,
            ) -> Option<Result<$outcome, $crate::driver::CoreError>> {
                <$core>::settle(self, now_ms, limit)
            }
            fn transmit(&mut self, now_ms: u64) -> Option<&[u8]> {
                <$core>::transmit(self, now_ms)
            }
            fn transmitted(&mut self, n: usize, now_ms: u64) {
                <$core>::transmitted(self, n, now_ms);
            }
            fn rx_space(&mut self) -> &mut [u8] {
                <$core>::rx_space(self)
            }
            fn rx_filled(&mut self, n: usize) {
                <$core>::rx_filled(self, n);
            }
            fn drain(&mut self, now_ms: u64) -> Option<$event> {
                <$core>::drain(self, now_ms)
            }
            fn tick(&mut self, now_ms: u64) -> Option<$event> {
                <$core>::tick(self, now_ms)
            }
            fn wait_ms(&self, now_ms: u64) -> Option<u64> {
                <$core>::wait_ms(self, now_ms)
            }
        }
    };
}

pub(crate) use {core_impl, pump_api};
