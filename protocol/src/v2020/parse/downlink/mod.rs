//! The board → master streaming parser: telemetry and replies out of a noisy byte stream.
//!
//! # Why this is not a plain state machine over one frame
//!
//! There is no checksum and no length byte (ambiguity A7). `FF FA`, `FF FB` and `FF FC` are
//! -6, -5 and -4 as big-endian `i16`, so a gyro at rest writes false headers into IMU payloads
//! all the time, and `23` (a reply's `#`) is an ordinary byte. UARTs drop bytes on overrun,
//! lines pick up noise, and a master may start listening mid-frame. The parser keeps a window of
//! up to [`WINDOW`] bytes from the start of the candidate frame it is judging, and weighs:
//!
//! 1. **The header** (`FF FA` / `FF FB` / `FF FC`, or `23` and a reply code the spec defines):
//!    it fixes the frame's length.
//! 2. **The count byte**, against what the line has taught ([`counts`]): the vendor does not
//!    say what it counts (A10), so the parser learns each stream's steps from the line (per
//!    stream +1 or +k, one counter shared by all streams, a time tick: all work).
//! 3. **Where it starts**: right after a frame taken on good evidence (*Locked*; *Resynced*
//!    when that frame was found while hunting), right after a quiet line (*Tentative*), or
//!    anywhere (*Hunting*). Rows that say Locked hold for Resynced too, but row 5.
//! 4. **What follows**: a header right after it, or a **chain**: the frames right after it,
//!    back to back, reaching one whose count continues its stream (counting the candidate).
//! 5. **Whether a reply is awaited**: the master knows when it asked
//!    ([`DownlinkParser::expect_reply`]); the board answers reads only.
//!
//! # The rules
//!
//! One table, one function ([`rules::need`]), a test per row:
//!
//! | # | where the candidate starts | what it is | taken |
//! |---|---|---|---|
//! | 1 | Locked or Tentative | telemetry, count continues (or fits two streams) | on its last byte |
//! | 2 | Locked or Tentative | the awaited reply, no telemetry header inside its value | on its last byte |
//! | 3 | Locked or Tentative | the awaited reply that could hide a cut frame | with a header (or quiet line) after it |
//! | 4 | Locked | telemetry, count near (frames lost) or the stream's first | with a header (or quiet line) after it |
//! | 5 | Locked (not Resynced) | telemetry, count far | when the chain after it vouches, far counts in it re-based |
//! | 6 | Tentative | telemetry, count near (the board paused) | with a header (or quiet line) after it |
//! | 7 | Tentative | telemetry, the stream's first or a far count | when the chain vouches (far counts in it re-based), or it fills the burst up to the next quiet line |
//! | 8 | Hunting | telemetry, count continues or near (and fits no other stream) | when the chain vouches (or, the count continuing exactly, the quiet line right after it) |
//! | 9 | Hunting | telemetry, the stream's first, a count another stream's could explain (but the stream of a frame rejected on a boundary right before it), any count inside a frame rejected on a boundary, or a count that is a telemetry header's second byte (its last two bytes a header) | when its own stream's next frame in the chain continues it |
//! | 10 | Hunting | the awaited reply, not inside a frame rejected on a boundary | when the chain (or a quiet line) vouches, and the chain holds no other reply with its code |
//! | 11 | Locked or Tentative | a reply nobody awaits | when the very next frame's count continues exactly (or the quiet line ends it); Locked, past a damaged next frame, when the frame after it continues |
//! | 12 | Hunting | a reply nobody awaits, or the awaited code inside a frame rejected on a boundary | never |
//! | 13 | Hunting or Resynced | telemetry, count far | when its own stream's next three frames in the chain move on from it in step (the board restarted its counts) |
//! | 14 | Hunting | telemetry whose last bytes are a frame of another stream that lost or gained a byte, or, inside a frame rejected on a boundary and with a count not near its own stream's, a whole one; ending on the same count byte, which fits that stream; telemetry that is the tail of a frame of another stream that lost its first byte; telemetry starting in a reply's value whose tail, from the reply's end, is a whole frame of another stream (same count byte, which fits it); or, inside a frame rejected on a boundary, telemetry over the header where that frame, a byte short or long, ends, or telemetry of its kind from its byte 2 (its tail, had it gained two bytes) | never (a whole inner frame: the scan reaches it next) |
//! | 15 | any | telemetry, count far, its last two bytes a telemetry header (a cut frame running into the next one) | never |
//!
//! *A frame of another stream that lost or gained a byte* (row 14): its header inside the
//! candidate, where a frame of its stream one byte shorter (or longer) ends on the candidate's
//! count byte, and that count fits its stream: a damaged real frame, behind bytes that happen to
//! hold a header (under one counter shared by all streams, or a time tick, the count fits the
//! outer stream too, and the frames after it continue both). The inner frame cannot be taken
//! itself, so rejecting the outer one lets nothing false through. (A *whole* inner frame outside
//! a rejected frame is not enough: measured, rejecting the outer frame there cost recall and let
//! the inner, false, one through.) Inside a frame rejected on a boundary, the outer frame is
//! judged by a whole inner one only when its own count is not near: a frame cut short by a
//! dropout leaves the next whole frames in its length, with counts a few frames on.
//!
//! *The tail of a frame that lost its first byte* (row 14): a lone `FA`..`FC` among the bytes
//! thrown away right before the candidate (not after an `FF`), where the rest of a frame of that
//! stream ends on the candidate's count byte, which fits that stream: an encoder frame's header
//! in an IMU frame's payload (accel Y of -5) whose own `FF` was lost.
//!
//! *Resynced* (rows 5 and 13): right after a frame found while hunting, the boundary is only as
//! sure as that frame. Lookalikes in adversarial payloads come back to back (each ends where
//! the next starts); once one is taken, the next has a boundary of sorts, and a far count
//! there re-based by a chain of more lookalikes let a run of false frames through after a
//! dropout. A far count there needs what it needs while hunting.
//!
//! *Starting in a reply's value* (row 14): the two bytes thrown away right before the
//! candidate are `23` and a reply code, and from where that reply ends (four bytes in) the
//! candidate's tail is a whole frame of another stream, ending on the candidate's count byte,
//! which fits that stream: a reply nobody awaits (never taken while hunting) whose value starts
//! `FF FA`, then a real encoder frame; under one counter shared by all streams, or a time tick,
//! the encoder frame's count continues the IMU stream too.
//!
//! *Over the header where the rejected frame ends* (row 14): inside a frame rejected on a
//! boundary, a telemetry header inside the candidate right where that frame ends if it lost
//! (or gained) a byte is the next real frame: both cannot be real, and the scan reaches it
//! next. Lookalikes back to back in adversarial payloads, each a count on from the one before
//! (under one counter shared by all streams, when the counts pass `FA`..`FC`, payload bytes
//! are counts too), vouched for each other there, over the real frames. And *its tail from its
//! byte 2* (row 14): a frame that gained two bytes inside is rejected on its boundary; from its
//! byte 2, a frame of its kind ends on its count byte, which continues its stream. A real frame
//! starts there only if a dropout cut the rejected one right after its header and ended right
//! at a frame's start.
//!
//! *Inside a frame rejected on a boundary* (rows 9, 12 and 14): a candidate that starts within
//! the length the rejected frame's header promised, less [`MAX_DROPPED`] bytes it may have lost.
//! A real frame starts there only if the rejected one lost more bytes than that (a dropout), so
//! a count that continues there is no evidence: a byte inserted into a frame leaves its last
//! bytes and the next frame's header in the window, and payload bytes repeat counts. Nor is the
//! awaited reply's code: `23` and a code in a damaged frame's payload end on its count byte,
//! right where the next frame starts, so the chain after it vouches as well as for a real one.
//! Where a frame rejected on a boundary ends if it lost or gained a byte (or had its count byte
//! changed) is a boundary too: a frame rejected there casts the same shadow (two damaged
//! frames in a row, the second's payload holding a lookalike over the next frame's header).
//!
//! *The master asked once* (row 10): a chain after the awaited reply that holds another reply
//! with the same code (the real one, after a `23` and the code in a damaged frame's tail) does
//! not vouch for it.
//!
//! *Past a damaged next frame* (row 11): a reply nobody awaits on a certain boundary, whose next
//! frame lost a byte inside (its count byte is then the next header's first), lost its header's
//! first byte, or gained a byte, is taken when the frame right after the damaged one (where
//! that damage puts it) continues its stream, the damaged frame counted as one of its stream.
//! A damaged frame of the right length (a changed count byte) does not say which of the two is
//! wrong, and does not vouch.
//!
//! *The chain vouches* ([`rules::Chain`]) when the frames right after the candidate, back to
//! back, reach one whose count continues (or is near) its stream's count, counting the
//! candidate itself and the chain's frames before it; frames of streams with no count yet pass
//! it on, replies too; a far count ends it (fails), except on a certain boundary (row 5) where
//! it re-bases. A frame whose last two bytes are a telemetry header (its count byte the next
//! header's second, as in row 15) is passed over: its count is no evidence (a frame cut by a
//! dropout that ended on a header's second byte, re-based on that `FA`, and a lookalike in the
//! next payload ending on the following header's `FB` continued each other). A frame of the
//! candidate's own stream sooner after it than the board's rates
//! allow on a line that carries IMU frames ([`Counts::too_soon`]: an encoder frame within 60
//! bytes, a battery frame within 1 500) fails it: both cannot be real (battery lookalikes back
//! to back in a payload, their counts a learnt step apart by chance). A candidate whose count
//! continues exactly may have up to two junk bytes before its chain, unless they are the tail
//! of a frame from the boundary right before the bytes thrown away ahead of the candidate (its
//! first `FF`), which lost or gained a byte and ends where the chain starts: the chain vouches
//! for that frame, not for the candidate inside it. A quiet line right after
//! the candidate vouches for it after a quiet line (Tentative), for the awaited reply, and,
//! while hunting, for telemetry whose count continues exactly and fits no other stream,
//! outside a frame rejected on a boundary (the frame after a damaged one in the same burst);
//! never for a near count found while hunting or one another stream's could explain (a false
//! frame in a damaged frame's tail ends where the line goes quiet, on that frame's count
//! byte), nor for a stream's first frame (any payload can hold a header that ends there). The
//! chain is looked for within the window; a window full before it decides is a no.
//!
//! At start-up nothing is known: a stream's first frame found while hunting then needs three
//! more frames of its stream in the chain, equally spaced by 1 to 4 counts
//! ([`counts::FIRST_STEP_MAX`]): sensor bytes drift slowly and payloads repeat a frame's length
//! apart, so false frames' "counts" can move in small steps for a frame or two, rarely four. A parser that starts listening anywhere emits
//! nothing until the line has shown it a count. From a quiet line on a clean line (a board
//! powering up, a capture that starts in an idle stretch), every frame comes out.
//!
//! * A rejected candidate costs exactly **one** byte: its first. Scanning goes on over the bytes
//!   already in the window, so a real frame a false candidate overlapped is still found.
//! * **A quiet line is time, not amnesia** ([`DownlinkParser::quiet`]): it widens every
//!   stream's count window by the frames the time could hold (the board pauses telemetry
//!   while settings are made); the count check never goes away.
//! * **A count is a guess until its stream continues it**: a count far from one that no frame
//!   of its own stream has continued yet (a false frame passed over in a chain while the line
//!   was damaged, then a second with no battery frame to correct it) counts as unknown, not far.
//! * **Steps are learnt only from a line that lost nothing** ([`counts`]): a near count with
//!   no byte thrown away since its stream's last frame is a step, not frames lost (seen twice:
//!   a shared counter steps the IMU by 2 after an encoder frame); a count that moved on across
//!   a loss teaches nothing (it may be frames lost), and a loss allows frames lost unseen.
//! * After [`FORGET_AFTER`] bytes without a frame taken, every count is forgotten (the board
//!   may have restarted): nothing can hold the parser off for ever.
//!
//! # Memory and time
//!
//! Parsing state and counters are one [`DownlinkParser`] (size asserted at compile time). While
//! Locked, a frame's bytes are only stored; on its last byte a count one learnt step on takes
//! it (row 1) without the general judgement. Through [`DownlinkParser::frames`] (and
//! [`DownlinkParser::push_slice`]) such a frame is taken straight from the caller's slice,
//! never copied, when the window is empty; a frame cut by the end of one slice has its first
//! bytes stored in one step and is joined with the rest at the start of the next. Junk with
//! nothing before it costs a few instructions a byte. Each of these shortcuts makes the
//! decision the rules make, as the property tests check (any chunking, same frames). Nothing
//! allocates.
//!
//! # Panics
//!
//! Never, on any input: no indexing, no unchecked arithmetic on any path that bytes reach.

mod buf;
mod class;
pub mod counts;
mod feed;
mod judge;
pub mod rules;
mod take;

use super::stats::DownlinkStats;
use crate::command::Register;
use crate::telemetry::{self, Downlink, Kind, Stream};
use buf::Buf;
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
pub struct DownlinkParser {
    buf: Buf,
    counts: Counts,
    lock: Lock,
    /// The reply code awaited, if any.
    expect: Option<u8>,
    /// The last call emitted a frame: another may be ready without a new byte.
    drain: bool,
    /// Bytes consumed since the last frame taken (saturating).
    since_frame: u16,
    /// Bytes to store before anything can be decided (0 or 1: none; always 0 while `drain`):
    /// the rest of the frame whose header is at the front of the window, once judging it has
    /// needed more; or, right after a frame taken by row 1 with the window empty, the next
    /// frame's two header bytes (the first is judged with the second). Until the last one, a
    /// byte is only stored.
    missing: u8,
    /// The frame before the window was found while hunting (see [`Start::Resynced`]).
    resynced: bool,
    /// What was thrown away right before the window.
    thrown: Thrown,
    stats: DownlinkStats,
}

const _: () = assert!(
    core::mem::size_of::<DownlinkParser>() <= 220,
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
            buf: Buf::new(),
            counts: Counts::new(),
            lock: Lock::Hunting,
            expect: None,
            drain: false,
            since_frame: 0,
            missing: 0,
            resynced: false,
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
        if self.missing > 1 && self.buf.push(byte) {
            // (`missing` > 1: no wrap.)
            self.missing = self.missing.wrapping_sub(1);
            return None;
        }
        self.push_slow(byte)
    }

    /// Feeds bytes until a frame comes out; returns it and the bytes not yet consumed. Call
    /// again with the rest until it returns `(None, [])`. It goes through the same decisions as
    /// feeding the same bytes one at a time, so it emits the same frames in the same order; it
    /// only copies a frame's body in one step where no decision can fall in between.
    pub fn push_slice<'a>(&mut self, mut bytes: &'a [u8]) -> (Option<Downlink>, &'a [u8]) {
        if self.drain {
            if let Some(frame) = self.poll() {
                return (Some(frame), bytes);
            }
        }
        while !bytes.is_empty() {
            // With nothing kept, bytes that start no frame are thrown away at once.
            if self.buf.len() == 0 {
                let junk = bytes.iter().take_while(|b| !Kind::may_start(**b)).count();
                if junk > 0 {
                    self.discard_run(bytes.get(..junk).unwrap_or(&[]));
                    bytes = bytes.get(junk..).unwrap_or(&[]);
                    continue;
                }
            }
            // On a boundary, a frame that row 1 takes at the front of the window and `bytes`:
            // taken without the window.
            if let Some((frame, used)) = self.take_straight(bytes) {
                return (Some(frame), bytes.get(used..).unwrap_or(&[]));
            }
            if self.store_cut(bytes) {
                return (None, &[]);
            }
            // A frame whose header is (or starts) at the front is taken whole: nothing can be
            // decided before its last byte.
            let step = match (self.buf.as_slice(), bytes) {
                ([], [a, b, ..]) => Kind::from_header(*a, *b).map_or(1, Kind::len),
                ([a], [b, ..]) => {
                    Kind::from_header(*a, *b).map_or(1, |kind| kind.len().saturating_sub(1))
                }
                // What the last judgement said it needs before anything can be decided.
                _ => usize::from(self.missing),
            };
            let step = step.max(1).min(bytes.len());
            let (now, later) = bytes.split_at_checked(step).unwrap_or((bytes, &[]));
            self.append(now);
            bytes = later;
            // `complete` takes a frame alone in the window on its own when it can, else it
            // judges as `poll` does.
            if let Some(frame) = self.complete() {
                return (Some(frame), bytes);
            }
        }
        (None, bytes)
    }

    /// An iterator over the frames in `bytes`; every byte is consumed by the time it ends.
    pub fn frames<'p, 'b>(&'p mut self, bytes: &'b [u8]) -> DownlinkFrames<'p, 'b> {
        DownlinkFrames {
            parser: self,
            rest: bytes,
        }
    }

    /// Emits a frame that is already decided in the window, if any, without a new byte.
    pub fn poll(&mut self) -> Option<Downlink> {
        // (After a chain proved a frame, the next is often alone in the window: row 1.)
        self.complete()
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
    /// forgotten once its reply comes.
    pub fn expect_reply(&mut self, register: Option<Register>) {
        self.expect = register.map(Register::reply_code);
        // A candidate waiting in the window may be judged differently now: judge it at the
        // next byte, not only once the bytes it was waiting for are in.
        self.missing = self.missing.min(self.front_missing());
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

#[cfg(test)]
mod tests;
