//! The board → master streaming parser: telemetry and replies out of a noisy byte stream.
//!
//! There is no checksum and no length byte (A7); `FF FA`..`FF FC` are -6..-4 as big-endian
//! `i16`, so a gyro at rest writes false headers into payloads, and `23` is an ordinary byte.
//! **One principle:** a frame is taken on evidence that does not rest on the bytes it could be
//! hiding in — where it starts, its count byte against the steps the line has taught
//! ([`counts`]: A10 does not say what it counts), and what follows it — and the less sure its
//! start, the more of what follows must vouch. The parser keeps a window of up to [`WINDOW`]
//! bytes from the candidate's first byte; the facts about a candidate are gathered (`class.rs`,
//! [`rules::Facts`]) and **one table decides** ([`rules::decide`], first row that holds, a test
//! per row; the reasons for each row: `docs/parser.md`):
//!
//! | # | where it starts | what it is | taken |
//! |---|---|---|---|
//! | 14 | Hunting | telemetry whose bytes hold a real frame it cannot be | never |
//! | 15 | any | a far count (Hunting: also the stream's first) that is a header's second byte (a cut frame) | never; Locked, Tentative: the quiet line right after |
//! | 1 | a boundary | telemetry, count continues | on its last byte |
//! | 4 | Locked, Resynced | telemetry, count near, or the stream's first | with a header after it |
//! | 5 | Locked | telemetry, count far | a chain, re-basing (or the quiet line) |
//! | 6 | Tentative | telemetry, count near | with a header after it |
//! | 7 | Tentative | telemetry, the stream's first or a far count | a chain, re-basing (or the quiet line) |
//! | 13 | Hunting, Resynced | telemetry, count far | its stream's next three frames in step |
//! | 9 | Hunting | the stream's first; a count inside a rejected frame, another stream's too, or a header's byte | its own stream's next frame |
//! | 8 | Hunting | telemetry, count continues or near | a chain (continuing: or the quiet line) |
//! | 2 | a boundary | the awaited reply, no header in its value | on its last byte |
//! | 3 | a boundary | the awaited reply, a header in its value | with a header after it |
//! | 11 | a boundary | a reply nobody awaits | the next frame's count exactly (or the quiet line) |
//! | 10 | Hunting | the awaited reply, not inside a rejected frame or a frame's tail | a chain or the quiet line, no second reply of its code |
//! | 12 | Hunting | any other reply | never |
//!
//! *Locked*: right after a frame taken on a boundary; *Resynced*: right after one found while
//! hunting; *Tentative*: right after a quiet line; *Hunting*: anywhere. A *chain* is the frames
//! right after the candidate, back to back, reaching one whose count continues its stream
//! ([`rules::Chain`] says which links count). With no step learnt, a stream's first frame found
//! while hunting needs three more of its stream in step (equal steps from its count on), a
//! step wider than [`counts::FIRST_STEP_MAX`] included; an IMU frame, also the next three of
//! any streams with a count in step (one counter shared by all), the IMU's own stepping first.
//!
//! * A rejected candidate costs **one** byte, its first: a real frame a false candidate
//!   overlapped is still found, unless it starts right inside a frame rejected on a boundary
//!   (row 14: a lone `FF FA` right before an IMU frame costs that frame).
//! * **A quiet line is time, not amnesia** ([`DownlinkParser::quiet`]): it widens every count
//!   window by the frames the time could hold; the count check never goes away.
//! * **Steps are learnt only from a line that lost nothing** ([`counts`]).
//! * After [`FORGET_AFTER`] bytes without a frame, the counts are forgotten: nothing holds the
//!   parser off for ever.
//!
//! # Memory and time
//!
//! One [`DownlinkParser`], its size asserted at compile time; nothing allocates. While locked,
//! a frame's bytes are only stored and row 1 takes it on its last byte without the general
//! judgement; [`DownlinkParser::frames`] takes such a frame straight from the caller's slice.
//! Each shortcut makes the decision the table makes (asserted at compile time against
//! [`rules::decide`]; a unit test compares them with the general judgement alone on noisy
//! streams, and property tests: any chunking, the same frames).
//!
//! # Panics
//!
//! Never, on any input: no indexing, no unchecked arithmetic on any path that bytes reach.

mod class;
pub mod counts;
mod feed;
mod judge;
pub mod rules;
mod take;

use super::stats::DownlinkStats;
use super::window::Window;
use crate::command::Register;
use crate::telemetry::{self, Downlink, Kind, Stream};
use counts::Counts;

/// Bytes the parser keeps at most: enough for a candidate and the chain after it; at start-up
/// three IMU frames with an encoder or battery frame and a reply among them.
pub const WINDOW: usize = 96;

/// After this many bytes without a frame taken, the counts are forgotten.
pub const FORGET_AFTER: u16 = 240;

/// Frames of its own stream after a candidate, all the same number of counts apart, that vouch
/// for it when no step has been learnt (start-up, a board that restarted its counts).
const IN_STEP: u8 = 3;

/// Junk bytes a candidate whose count continues exactly may have before its chain.
const MAX_GAP: usize = 2;

/// Bytes a frame rejected on a boundary is taken to have lost at most, for row 14: real frames
/// start no earlier than its header's length less this.
pub const MAX_DROPPED: usize = 2;

/// How sure the parser is of where frames start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Lock {
    /// Alignment unknown: scanning for a frame.
    Hunting,
    /// Right after a quiet line: the next byte is taken to start a frame.
    Tentative,
    /// Right after a frame taken on good evidence.
    Locked,
}

/// The board → master streaming parser. See the [module docs](self) for the rules.
///
/// ```
/// use chassis_protocol::{Battery, Downlink, DownlinkParser, Imu, Lock};
///
/// let imu = |seq| Imu { accel: [0, 1, 16_384], gyro: [0, -4, 2], seq };
/// let battery = Battery { centivolts: 1_100, percent: 87, seq: 3 };
/// let mut line = Vec::new();
/// line.extend_from_slice(&imu(7).encode());
/// line.extend_from_slice(&battery.encode());
/// line.extend_from_slice(&imu(8).encode());
/// let mut parser = DownlinkParser::new();
/// // The line was quiet before: the next byte starts a frame.
/// assert_eq!(parser.quiet(5), None);
/// // Split anywhere: the same frames. The first waits until the chain after it shows a count
/// // moving (IMU 7 then 8); from then on each frame comes out on its last byte.
/// let mut got: Vec<Downlink> = Vec::new();
/// for read in line.chunks(4) {
///     got.extend(parser.frames(read));
/// }
/// assert_eq!(got, [imu(7).into(), battery.into(), imu(8).into()]);
/// assert_eq!(parser.lock(), Lock::Locked);
/// assert_eq!(parser.stats().discarded, 0);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
// (Laid out in this order, the window's bytes first: `push`'s fast path, inlined into the
// caller's loop, then stores a byte at the parser's address plus `end`, with no offset to add;
// then what a byte reads on its way (`missing`, the lock, `since_frame`, `drain`, `resynced`),
// right after the window's `end`, so that a Cortex-M0, whose loads reach 31 bytes from a
// register, reads them from one.)
#[repr(C)]
pub struct DownlinkParser {
    buf: Window<WINDOW>,
    /// Bytes to store before anything can be decided (0 or 1: none; always 0 while `drain`):
    /// the rest of the frame whose header is at the front of the window, once judging it has
    /// needed more; or, right after a frame taken by row 1 with the window empty, the next
    /// frame's two header bytes (the first is judged with the second). Until the last one, a
    /// byte is only stored.
    missing: u8,
    lock: Lock,
    /// Bytes consumed since the last frame taken (saturating).
    since_frame: u16,
    /// The last call emitted a frame: another may be ready without a new byte.
    drain: bool,
    /// The frame before the window was found while hunting (see [`rules::Start::Resynced`]).
    resynced: bool,
    counts: Counts,
    /// The reply awaited.
    expect: Expect,
    /// Bytes stored behind frames not yet out.
    behind: Behind,
    /// Where the last judgement waited for the chain's next header (the window's length then;
    /// 0: it did not), until the next judgement: see
    /// [`chain_header_wait`](DownlinkParser::chain_header_wait).
    header_at: u8,
    /// What was thrown away right before the window.
    thrown: Thrown,
    stats: DownlinkStats,
}

/// The reply the master awaits ([`DownlinkParser::expect_reply`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Expect {
    /// Its code, if any.
    code: Option<u8>,
    /// What [`expect_reply`](DownlinkParser::expect_reply) said while frames were still to
    /// come out, and how many bytes were [`behind`](DownlinkParser::behind) then: it applies
    /// once those frames and bytes are judged, as if they had all come out before the call.
    next: Option<(Option<u8>, u8)>,
}

/// Bytes stored at the window's end while `drain` (after a frame came out, before the next
/// call): the judgement does not see them until what was before them is judged, then takes
/// them one at a time, as if each had come after a `poll`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Behind {
    /// How many.
    len: u8,
    /// The `missing` the frame before them left, or [`RESUME_DRAIN`] if it left another frame
    /// ready.
    resume: u8,
}

/// [`Behind::resume`] when the frame before the bytes behind left another ready (a `missing`
/// is never this large).
const RESUME_DRAIN: u8 = u8::MAX;

const _: () = assert!(
    core::mem::size_of::<DownlinkParser>() <= 228,
    "DownlinkParser over its RAM budget"
);

/// What the parser threw away right before the window: the frame last rejected on a boundary,
/// and the bytes dropped ahead of the window's first byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Thrown {
    /// The kind of the frame last rejected on a boundary, and the bytes left until two past its
    /// end: more than [`MAX_DROPPED`] + 2 at start positions still inside it (row 14, see
    /// [`in_shadow`](DownlinkParser::in_shadow)); 1 to 3 at the start of the frame right after
    /// it (it lost a byte, had a wrong count byte, or gained a byte: see
    /// [`other_stream_fits`](DownlinkParser::other_stream_fits)).
    rejected: Option<Kind>,
    rejected_left: u8,
    /// The bytes thrown away right before the window's first byte, newest in the low byte
    /// (row 14: a frame that lost its first byte), and how many of them there are.
    before: u32,
    before_len: u8,
}

impl Thrown {
    const fn new() -> Self {
        Thrown {
            rejected: None,
            rejected_left: 0,
            before: 0,
            before_len: 0,
        }
    }
}

impl Default for DownlinkParser {
    fn default() -> Self {
        Self::new()
    }
}

impl DownlinkParser {
    /// A parser that has seen nothing: hunting, no counts known. `const`, so it can live in a
    /// `static`.
    #[must_use]
    pub const fn new() -> Self {
        DownlinkParser {
            buf: Window::new(),
            counts: Counts::new(),
            lock: Lock::Hunting,
            expect: Expect {
                code: None,
                next: None,
            },
            drain: false,
            behind: Behind { len: 0, resume: 0 },
            since_frame: 0,
            missing: 0,
            resynced: false,
            header_at: 0,
            thrown: Thrown::new(),
            stats: DownlinkStats::new(),
        }
    }

    /// Feeds one byte. Returns a frame when this byte completes (or proves) one.
    ///
    /// At most one frame comes out per call. When a chain proves several frames at once, the
    /// next come out of the next calls (of `push`, [`push_slice`](Self::push_slice),
    /// [`poll`](Self::poll) or [`quiet`](Self::quiet)), never lost.
    #[inline]
    pub fn push(&mut self, byte: u8) -> Option<Downlink> {
        // The fast path, small enough to inline into the caller's loop: the last judgement
        // needs more bytes than this one (a frame, or a frame of the chain after it, is still
        // incomplete); nothing can be decided, so the byte is only stored.
        let missing = self.missing;
        if missing > 1 && self.buf.push(byte) {
            // (`missing` > 1: no wrap.)
            self.missing = missing.wrapping_sub(1);
            return None;
        }
        self.push_slow(byte)
    }

    /// Feeds bytes until a frame comes out; returns it and the bytes not yet consumed. Call
    /// again with the rest until it returns `(None, [])`. It goes through the same decisions as
    /// feeding the same bytes one at a time, so it emits the same frames in the same order; it
    /// only copies a frame's body in one step where no decision can fall in between.
    #[inline(never)]
    pub fn push_slice<'a>(&mut self, mut bytes: &'a [u8]) -> (Option<Downlink>, &'a [u8]) {
        while let Some((&byte, rest)) = bytes.split_first() {
            if !self.drain && short_ways() {
                // With nothing kept, bytes that start no frame are thrown away at once.
                if self.buf.is_empty() && self.missing == 0 {
                    let junk = bytes.iter().take_while(|b| !Kind::may_start(**b)).count();
                    if junk > 0 {
                        self.discard_run(bytes.get(..junk).unwrap_or(&[]));
                        bytes = bytes.get(junk..).unwrap_or(&[]);
                        continue;
                    }
                }
                // On a boundary, a frame that row 1 takes at the front of the window and
                // `bytes`: taken without the window.
                if let Some((frame, used)) = self.take_straight(bytes) {
                    return (Some(frame), bytes.get(used..).unwrap_or(&[]));
                }
                if self.store_cut(bytes) {
                    return (None, &[]);
                }
                // A frame whose header is (or starts) at the front, whole in `bytes`, or the
                // bytes the last judgement waits for, all in `bytes`: stored in one copy, and
                // judged at the last, as `push` judges them. (A byte at most is kept before a
                // header: the frame fits.)
                let whole = match (self.buf.kept(), bytes) {
                    ([], [a, b, ..]) => Kind::from_header(*a, *b).map(Kind::len),
                    ([a], [b, ..]) => {
                        Kind::from_header(*a, *b).map(|kind| kind.len().saturating_sub(1))
                    }
                    _ => None,
                };
                let awaited = usize::from(self.missing);
                let awaited = (awaited > 1 && awaited <= WINDOW.saturating_sub(self.buf.len()))
                    .then_some(awaited);
                if let Some((now, later)) =
                    whole.or(awaited).and_then(|n| bytes.split_at_checked(n))
                {
                    self.buf.extend(now);
                    bytes = later;
                    self.missing = 1;
                    if let Some(frame) = self.complete() {
                        return (Some(frame), bytes);
                    }
                    continue;
                }
            }
            // Any other byte: as `push` takes it past its short ways.
            bytes = rest;
            if let Some(frame) = self.push_general(byte) {
                return (Some(frame), bytes);
            }
        }
        // A frame already decided, with no byte left to store behind it.
        let ready = if self.drain {
            self.complete_behind()
        } else {
            None
        };
        (ready, bytes)
    }

    /// An iterator over the frames in `bytes`; every byte is consumed by the time it ends.
    pub fn frames<'p, 'b>(&'p mut self, bytes: &'b [u8]) -> DownlinkFrames<'p, 'b> {
        DownlinkFrames {
            parser: self,
            rest: bytes,
        }
    }

    /// Emits a frame that is already decided in the window, if any, without a new byte.
    /// Nothing is judged while bytes the last judgement waits for are still to come (then
    /// `None`): the same decisions fall at the same bytes whether or not `poll` is called.
    pub fn poll(&mut self) -> Option<Downlink> {
        if self.missing > 0 {
            return None;
        }
        // (After a chain proved a frame, the next is often alone in the window: row 1.)
        self.complete_behind()
    }

    /// Tells the parser the line has been quiet for `ms` more milliseconds (any gap of two or
    /// three characters' time is one: the board sends a frame's bytes back to back). Call it in
    /// a loop until it returns `None`; report each stretch of quiet once (its length, or the
    /// time since the last report).
    ///
    /// A complete frame that waits for what follows it is judged with the quiet as what
    /// follows; an incomplete one is thrown away. Then the next byte is taken to start a frame
    /// (*Tentative*), and every stream's count window widens by the frames `ms` could hold.
    ///
    /// Unless the line lost a stretch of bytes: a frame that started on a boundary and misses
    /// more than [`MAX_DROPPED`] bytes when the line goes quiet lost its tail, and the bytes
    /// lost may run past the quiet stretch (a UART overrun drops whatever arrives while it
    /// lasts), so the next burst may start in the middle of a frame. The parser then goes on
    /// hunting. (A byte or two missing is noise inside the frame: the next burst is aligned.)
    pub fn quiet(&mut self, ms: u32) -> Option<Downlink> {
        if self.drain {
            // Frames not yet out and the bytes stored behind them: taken first, as by `poll`.
            if let Some(frame) = self.complete_behind() {
                return Some(frame);
            }
        }
        let cut = self.lock != Lock::Hunting && usize::from(self.front_missing()) > MAX_DROPPED;
        let frame = self.run(true);
        if frame.is_none() {
            self.counts.quiet(ms);
            self.thrown.rejected_left = 0;
            self.thrown.before_len = 0;
            if self.lock == Lock::Hunting && !cut {
                self.lock = Lock::Tentative;
            }
        }
        frame
    }

    /// [`quiet`](Self::quiet) for the shortest quiet line (1 ms): what a UART's idle-line
    /// interrupt reports.
    pub fn idle(&mut self) -> Option<Downlink> {
        self.quiet(1)
    }

    /// Tells the parser a reply to a read of `register` is awaited (`None`: none is). The
    /// master knows when it asked: an awaited reply is taken on less evidence, and a reply
    /// nobody awaits needs the next frame's count to vouch for it. The awaited code is
    /// forgotten once its reply comes. A candidate waiting in the window is judged again at
    /// the next byte. Called while frames a chain proved are still to come out (before the
    /// caller has polled them), it applies once they are out, as if they had been polled first.
    pub fn expect_reply(&mut self, register: Option<Register>) {
        let code = register.map(Register::reply_code);
        if self.drain {
            // Frames still to come out were decided without it.
            self.expect.next = Some((code, self.behind.len));
        } else {
            self.expect.next = None;
            self.expect_now(code);
        }
    }

    /// How sure the parser is of where frames start.
    #[must_use]
    pub const fn lock(&self) -> Lock {
        self.lock
    }

    /// Bytes received but not yet emitted or thrown away (at most [`WINDOW`]).
    #[must_use]
    pub const fn buffered(&self) -> usize {
        self.buf.len()
    }

    /// The counters.
    #[must_use]
    pub const fn stats(&self) -> &DownlinkStats {
        &self.stats
    }

    /// Returns the counters and starts them again from 0.
    pub fn take_stats(&mut self) -> DownlinkStats {
        core::mem::take(&mut self.stats)
    }

    /// Forgets everything but the counters: as after [`new`](DownlinkParser::new).
    pub fn reset(&mut self) {
        let stats = self.stats;
        *self = DownlinkParser::new();
        self.stats = stats;
    }
}

/// The frames in a slice, from [`DownlinkParser::frames`].
#[derive(Debug)]
pub struct DownlinkFrames<'p, 'b> {
    parser: &'p mut DownlinkParser,
    rest: &'b [u8],
}

impl Iterator for DownlinkFrames<'_, '_> {
    type Item = Downlink;

    #[inline]
    fn next(&mut self) -> Option<Downlink> {
        // (The common case first, inlined into the caller's loop.)
        if let Some((frame, used)) = self.parser.take_straight(self.rest) {
            self.rest = self.rest.get(used..).unwrap_or(&[]);
            return Some(frame);
        }
        if self.rest.is_empty() && !self.parser.drain {
            return None;
        }
        if self.parser.store_cut(self.rest) {
            self.rest = &[];
            return None;
        }
        let (frame, rest) = self.parser.push_slice(self.rest);
        self.rest = rest;
        frame
    }
}

// Each telemetry frame's count is its last byte (`take_straight` reads it there).
const _: () = assert!(
    Stream::Imu.seq_at() + 1 == Kind::Telemetry(Stream::Imu).len()
        && Stream::Encoders.seq_at() + 1 == Kind::Telemetry(Stream::Encoders).len()
        && Stream::Battery.seq_at() + 1 == Kind::Telemetry(Stream::Battery).len()
);

/// The longest frame, for the window's size check.
const _: () = assert!(WINDOW >= 3 * telemetry::MAX_LEN + 11 + 6 + 2 * 7);

/// Whether the short ways (row 1 on a frame's last byte, row 11's shortcut, a header's wait,
/// junk dropped at once, `push_slice`'s copies) are taken: always, except in the unit test
/// that compares them with the general judgement alone.
#[inline(always)]
fn short_ways() -> bool {
    #[cfg(test)]
    {
        !shortcut_tests::GENERAL_ONLY.with(core::cell::Cell::get)
    }
    #[cfg(not(test))]
    {
        true
    }
}

#[cfg(test)]
mod shortcut_tests;
#[cfg(test)]
mod tests;
