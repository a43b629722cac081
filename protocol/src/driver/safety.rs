//! [`Safety`]: the part of the driver's policy that does not depend on the bytes: whole frames
//! out, the failsafe, time, and bounded waits. Generic over the wire format ([`Wire`]), so every
//! firmware generation the driver speaks keeps one policy.
//!
//! * **Whole frames, in order.** A frame to send is copied into the core before its first byte
//!   goes out and stays there until its last byte is taken by the UART
//!   ([`Safety::transmitted`]). A write cut short (a dropped future, a transport error) leaves the
//!   rest in the core, and whatever is sent next starts by finishing it: the board's parser never
//!   sees the start of one frame completed by another.
//! * **The failsafe.** While the chassis is moving, no frame heard from the board for
//!   `failsafe_ms` (or `settings_pause_ms` after a settings frame, until telemetry is back; a
//!   read counts once the board has answered it, whole or damaged, and a read unanswered ends
//!   the allowance)
//!   queues the wire format's stop
//!   frame ([`Wire::stop`]), ahead of anything else not yet begun.
//! * **Time** is the core's own monotonic milliseconds ([`Timebase`]): a `u32` tick counter that
//!   wraps, or a clock that goes back, never stops the failsafe or hangs a wait.
//! * **Bounded waits.** A request's wait ends after a stated number of pump turns that see the
//!   clock stand still, whatever bytes arrive meanwhile ([`Safety::stalled`]).

use super::time::Timebase;
use super::{Config, CoreError};
use core::fmt::Debug;

/// What the driver's policy needs from a wire format: the bytes of a frame to the board, and the
/// frame that stops the chassis. Everything else the policy decides on its own.
pub(crate) trait Wire {
    /// The bytes of one frame to the board (a fixed-size buffer: no allocation).
    type Frame: Copy + Debug + AsRef<[u8]>;

    /// The frame that stops the chassis: what the failsafe and `stop()` send.
    fn stop() -> Self::Frame;
}

/// What a frame is to the policy, so that its last byte leaving can be acted on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) enum FrameKind {
    /// A motion frame (velocity, motors, turn) or a stop.
    Motion,
    /// A settings frame that needs no reply (a write, an action).
    Settings,
    /// A read: its reply timeout starts when its last byte has left.
    Read,
}

/// A frame being written: its bytes and how many the UART has taken.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct InFlight<F> {
    frame: F,
    sent: usize,
    kind: FrameKind,
}

/// The wire-independent policy: frames out whole and in order, the failsafe, time, stall bounds.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Safety<W: Wire> {
    time: Timebase,
    tx: Option<InFlight<W::Frame>>,
    stop_queued: bool,
    limits: Limits,
    heard: Heard,
    /// The last settings frame sent (a read's once answered): the board may pause its
    /// telemetry after it.
    settings_sent_ms: Option<u64>,
    /// When the last read went: the low 32 bits of the core's time (its reply comes well
    /// within 2^32 ms).
    read_sent_low: u32,
    /// What the board has answered to the last read.
    answer: Answer,
    /// Telemetry frames heard since the last settings frame (saturating at 255).
    telemetry_after_settings: u8,
    moving_since_ms: Option<u64>,
    failsafe_stops: u32,
    /// Pump turns in a row, while a request runs, that saw the clock stand still.
    stalled: u32,
    stalled_at: Option<u64>,
}

/// What the board has answered to the last read, as far as the failsafe is concerned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Answer {
    /// No read waits (none sent, or its reply heard, or given up on).
    Settled,
    /// The read went; nothing from the board since says it took it.
    Awaited,
    /// After the read went, bytes came that made no frame, then the line went quiet: the board
    /// answered, and the answer was damaged on the line. It took the read, so it may pause.
    Damaged,
}

/// The failsafe's limits, from [`Config`].
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Limits {
    failsafe_ms: u32,
    settings_pause_ms: u32,
}

impl Limits {
    const fn of(config: &Config) -> Self {
        Limits {
            failsafe_ms: config.failsafe_ms,
            settings_pause_ms: config.settings_pause_ms,
        }
    }
}

/// When the board was last heard.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Heard {
    /// The last frame of any kind (telemetry or reply): the board is alive.
    any_ms: Option<u64>,
    telemetry_ms: Option<u64>,
}

impl<W: Wire> Safety<W> {
    /// Nothing sent, nothing heard, the chassis taken as standing still.
    pub(crate) const fn new(config: &Config) -> Self {
        Safety {
            time: Timebase::new(),
            tx: None,
            stop_queued: false,
            limits: Limits::of(config),
            heard: Heard {
                any_ms: None,
                telemetry_ms: None,
            },
            settings_sent_ms: None,
            read_sent_low: 0,
            answer: Answer::Settled,
            telemetry_after_settings: 0,
            moving_since_ms: None,
            failsafe_stops: 0,
            stalled: 0,
            stalled_at: None,
        }
    }

    /// Takes new limits from `config`; everything else is kept.
    pub(crate) fn set_config(&mut self, config: &Config) {
        self.limits = Limits::of(config);
    }

    // ----- time -----

    /// The core's time for the caller's clock reading, kept.
    // Out of line: every call of the core starts with it, and its `u64` arithmetic inlined in
    // each costs more flash on a 32-bit core than the call (`size_driver`: 684 B).
    #[inline(never)]
    pub(crate) fn advance(&mut self, raw_ms: u64) -> u64 {
        self.time.advance(raw_ms)
    }

    /// The core's time for the caller's clock reading, not kept.
    pub(crate) const fn peek(&self, raw_ms: u64) -> u64 {
        self.time.peek(raw_ms)
    }

    /// The core's latest time.
    pub(crate) const fn now(&self) -> u64 {
        self.time.now()
    }

    // ----- frames out -----

    /// Whether a frame is being written or a stop waits to go: a new frame must wait.
    pub(crate) const fn output_pending(&self) -> bool {
        self.tx.is_some() || self.stop_queued
    }

    /// Whether no frame is being written (the next may be loaded).
    pub(crate) const fn slot_free(&self) -> bool {
        self.tx.is_none()
    }

    /// Puts `frame` in the slot: it will go out whole. [`CoreError::FramePending`] if a frame is
    /// still being written or a stop waits to go (write those out first).
    pub(crate) fn queue(&mut self, frame: W::Frame, kind: FrameKind) -> Result<(), CoreError> {
        if self.output_pending() {
            return Err(CoreError::FramePending);
        }
        self.load(frame, kind);
        Ok(())
    }

    /// Puts `frame` in the free slot (the caller checked [`slot_free`](Self::slot_free)).
    // Out of line: seven callers (every frame the core sends) share one copy (`size_driver`:
    // 100 B).
    #[inline(never)]
    pub(crate) fn load(&mut self, frame: W::Frame, kind: FrameKind) {
        // The board pauses its telemetry while settings are made, reads included (A13). A
        // write or an action is answered by nothing: its pause is allowed from when it goes. A
        // read's is allowed from when it went, once its reply comes (`reply_heard`), whole or
        // damaged (`quiet_after_garbage`): a board that answers no read is silent, not paused,
        // and reads sent to it never hold the failsafe off.
        match kind {
            FrameKind::Settings => self.settings_sent(self.now()),
            FrameKind::Read => {
                self.read_sent_low = self.now() as u32;
                self.answer = Answer::Awaited;
            }
            FrameKind::Motion => {}
        }
        self.tx = Some(InFlight {
            frame,
            sent: 0,
            kind,
        });
    }

    /// Queues the stop frame ahead of everything not yet begun, and takes the chassis as
    /// stopped.
    // Out of line: `stop()` and the failsafe share it (`size_driver`: 28 B).
    #[inline(never)]
    pub(crate) fn queue_stop(&mut self) {
        self.moving_since_ms = None;
        self.stop_queued = true;
    }

    /// Loads a queued stop into the free slot.
    pub(crate) fn load_stop(&mut self) -> bool {
        if self.stop_queued && self.tx.is_none() {
            self.stop_queued = false;
            self.load(W::stop(), FrameKind::Motion);
            return true;
        }
        false
    }

    /// The bytes of the frame in the slot not yet taken by the UART.
    pub(crate) fn pending(&self) -> Option<&[u8]> {
        let tx = self.tx.as_ref()?;
        tx.frame.as_ref().get(tx.sent..)
    }

    /// The UART took `n` more bytes; the kind of the frame this completed, if it did.
    pub(crate) fn transmitted(&mut self, n: usize) -> Option<FrameKind> {
        let tx = self.tx.as_mut()?;
        tx.sent = tx.sent.saturating_add(n);
        if tx.sent < tx.frame.as_ref().len() {
            return None;
        }
        let kind = tx.kind;
        self.tx = None;
        Some(kind)
    }

    // ----- the link and the failsafe -----

    /// The driver told the chassis to move (`true`) or to stand still.
    pub(crate) fn set_moving(&mut self, moving: bool, now_ms: u64) {
        self.moving_since_ms = match (moving, self.moving_since_ms) {
            (false, _) => None,
            (true, Some(since)) => Some(since),
            (true, None) => Some(now_ms),
        };
    }

    /// Whether the driver last told the chassis to move.
    pub(crate) const fn moving(&self) -> bool {
        self.moving_since_ms.is_some()
    }

    /// A settings frame left: the board may pause its telemetry.
    // Out of line: a write, an action and a read's reply share it (`size_driver`: 8 B).
    #[inline(never)]
    pub(crate) fn settings_sent(&mut self, now_ms: u64) {
        self.settings_sent_ms = Some(now_ms);
        self.telemetry_after_settings = 0;
    }

    /// A frame of any kind was heard at `at_ms`.
    // Out of line: telemetry and replies share it (`size_driver`: 24 B).
    #[inline(never)]
    pub(crate) fn heard(&mut self, at_ms: u64) {
        self.heard.any_ms = Some(self.heard.any_ms.map_or(at_ms, |t| t.max(at_ms)));
    }

    /// A telemetry frame was heard at `at_ms`.
    pub(crate) fn telemetry(&mut self, at_ms: u64) {
        self.heard(at_ms);
        self.heard.telemetry_ms = Some(at_ms);
        if self.settings_sent_ms.is_some_and(|sent| at_ms > sent) {
            self.telemetry_after_settings = self.telemetry_after_settings.saturating_add(1);
        }
    }

    /// A reply was heard: telemetry before it was on its way before the board took the read
    /// (and paused), so it says nothing about the pause being over.
    pub(crate) fn reply_heard(&mut self, at_ms: u64) {
        self.heard(at_ms);
        self.answer = Answer::Settled;
        self.read_taken(at_ms);
    }

    /// The board took the last read (its answer came at `at_ms`): it may pause its telemetry
    /// from when the read went.
    fn read_taken(&mut self, at_ms: u64) {
        let read = self.read_sent_ms(at_ms);
        let since = self.settings_sent_ms.map_or(read, |t| t.max(read));
        self.settings_sent(since);
    }

    /// When the last read went, seen from `at_ms` (at or after it).
    fn read_sent_ms(&self, at_ms: u64) -> u64 {
        let since_read = u64::from((at_ms as u32).wrapping_sub(self.read_sent_low));
        at_ms.saturating_sub(since_read)
    }

    /// The line went quiet after bytes that made no frame, the last of them at `last_byte_ms`
    /// (the parser threw them away). If they came after the awaited read went, the board
    /// answered it and the answer was damaged on the line (a byte lost, changed or added): the
    /// board took the read and may pause, as for a reply heard whole. The read itself still
    /// waits for a reply it can use; only the failsafe counts this as an answer.
    pub(crate) fn quiet_after_garbage(&mut self, last_byte_ms: u64) {
        let after_read = last_byte_ms > self.read_sent_ms(last_byte_ms);
        let no_frame_since = self.heard.any_ms.is_none_or(|t| t < last_byte_ms);
        if self.answer == Answer::Awaited && after_read && no_frame_since {
            self.answer = Answer::Damaged;
            self.read_taken(last_byte_ms);
        }
    }

    /// The last read went unanswered past its deadline: the board is not answering, so it is
    /// not paused either (a paused board answers reads), unless it answered it damaged. The
    /// pause allowed for the frames sent up to that read ends: silence counts from the last
    /// frame heard.
    pub(crate) fn read_unanswered(&mut self) {
        let answer = core::mem::replace(&mut self.answer, Answer::Settled);
        if answer == Answer::Damaged {
            return;
        }
        let read = self.read_sent_ms(self.now());
        if self.settings_sent_ms.is_some_and(|t| t <= read) {
            self.settings_sent_ms = None;
        }
    }

    /// When the last frame of any kind was heard.
    pub(crate) const fn last_heard_ms(&self) -> Option<u64> {
        self.heard.any_ms
    }

    /// When the last telemetry frame was heard.
    pub(crate) const fn last_telemetry_ms(&self) -> Option<u64> {
        self.heard.telemetry_ms
    }

    /// Times the failsafe has stopped the chassis.
    pub(crate) const fn failsafe_stops(&self) -> u32 {
        self.failsafe_stops
    }

    /// Whether a frame was heard within `failsafe_ms` of `now_ms`.
    pub(crate) fn link_alive(&self, now_ms: u64) -> bool {
        self.heard
            .any_ms
            .is_some_and(|t| now_ms.saturating_sub(t) <= u64::from(self.limits.failsafe_ms))
    }

    /// When the failsafe falls due, if the chassis is moving.
    pub(crate) fn failsafe_deadline(&self) -> Option<u64> {
        let since = self.moving_since_ms?;
        let heard = self.heard.any_ms.map_or(since, |t| t.max(since));
        let silent_until = heard.saturating_add(u64::from(self.limits.failsafe_ms));
        // The pause allowance lasts until telemetry is heard again: once the board streams
        // after the settings frame, its pause is over, and silence is silence. Two frames, not
        // one: a frame the board sent just before the pause can come out of the parser after
        // the settings frame went (confirmed by the reply's first byte).
        let paused_until = match self.settings_sent_ms {
            Some(_) if self.telemetry_after_settings >= 2 => 0,
            Some(sent) => sent.saturating_add(u64::from(self.limits.settings_pause_ms)),
            None => 0,
        };
        Some(silent_until.max(paused_until))
    }

    /// Judges the failsafe at `now_ms` (call once every byte the UART holds has been read):
    /// `true` if it fell due, and the stop is queued.
    pub(crate) fn check_failsafe(&mut self, now_ms: u64) -> bool {
        if self.failsafe_deadline().is_some_and(|due| now_ms > due) {
            self.queue_stop();
            self.failsafe_stops = self.failsafe_stops.wrapping_add(1);
            return true;
        }
        false
    }

    // ----- bounded waits -----

    /// One turn of a shell's pump while a request waits: `true` once `limit` turns in a row saw
    /// the clock stand still (whatever bytes came meanwhile): time will never end the wait.
    pub(crate) fn stalled(&mut self, now_ms: u64, limit: u32) -> bool {
        if self.stalled_at == Some(now_ms) {
            self.stalled = self.stalled.saturating_add(1);
            if self.stalled >= limit {
                self.reset_stall();
                return true;
            }
        } else {
            self.stalled = 0;
            self.stalled_at = Some(now_ms);
        }
        false
    }

    /// Forgets the stall count (a request ended).
    pub(crate) fn reset_stall(&mut self) {
        self.stalled = 0;
        self.stalled_at = None;
    }
}
