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

pub mod counts;
pub mod rules;

use super::stats::DownlinkStats;
use crate::command::Register;
use crate::telemetry::{self, Downlink, Kind, Stream};
use counts::{Counts, Rel};
use rules::{Chain, Class, Need, Start};

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

/// The bytes kept, from the first byte of the candidate being judged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Buf {
    bytes: [u8; WINDOW],
    start: u8,
    end: u8,
}

impl Buf {
    const fn new() -> Self {
        Buf {
            bytes: [0; WINDOW],
            start: 0,
            end: 0,
        }
    }

    #[inline]
    fn as_slice(&self) -> &[u8] {
        self.bytes
            .get(usize::from(self.start)..usize::from(self.end))
            .unwrap_or(&[])
    }

    #[inline]
    const fn len(&self) -> usize {
        self.end.saturating_sub(self.start) as usize
    }

    #[inline]
    const fn is_full(&self) -> bool {
        self.len() >= WINDOW
    }

    /// Appends one byte if there is room at the end; `false` if not (nothing done).
    #[inline]
    fn push(&mut self, byte: u8) -> bool {
        match self.bytes.get_mut(usize::from(self.end)) {
            Some(slot) => {
                *slot = byte;
                // (`end` indexes the window: no wrap.)
                self.end = self.end.wrapping_add(1);
                true
            }
            None => false,
        }
    }

    /// Appends what fits of `bytes`; returns how many.
    #[inline]
    fn extend(&mut self, bytes: &[u8]) -> usize {
        if usize::from(self.end).saturating_add(bytes.len()) > WINDOW && self.start > 0 {
            self.compact();
        }
        let end = usize::from(self.end);
        let taken = bytes.len().min(WINDOW.saturating_sub(end));
        let to = end.saturating_add(taken);
        match (self.bytes.get_mut(end..to), bytes.get(..taken)) {
            (Some(dst), Some(src)) => dst.copy_from_slice(src),
            _ => return 0,
        }
        self.end = u8::try_from(to).unwrap_or(self.end);
        taken
    }

    /// Moves the bytes kept to the front.
    fn compact(&mut self) {
        let (start, end) = (usize::from(self.start), usize::from(self.end));
        let old = self.bytes;
        if let Some(src) = old.get(start..end) {
            if let Some(dst) = self.bytes.get_mut(..src.len()) {
                dst.copy_from_slice(src);
            }
        }
        self.end = self.end.saturating_sub(self.start);
        self.start = 0;
    }

    /// Forgets every byte kept.
    #[inline]
    fn clear(&mut self) {
        self.start = 0;
        self.end = 0;
    }

    #[inline]
    fn drop_front(&mut self, n: usize) {
        let n = u8::try_from(n.min(self.len())).unwrap_or(0);
        self.start = self.start.saturating_add(n);
        if self.start >= self.end {
            self.start = 0;
            self.end = 0;
        }
    }
}

/// What the bytes in the window say about the candidate at its front.
enum Verdict {
    /// Not enough bytes to decide: at least this many more (1 or more) before a decision can
    /// fall (a quiet line aside).
    NeedMore(usize),
    /// The first byte starts no frame: drop it.
    Reject,
    /// A frame of this length, and what it was judged to be.
    Accept(Downlink, usize, Class),
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
    /// The kind of the frame last rejected on a boundary, and the bytes left until two past its
    /// end: more than [`MAX_DROPPED`] + 2 at start positions still inside it (row 14, see
    /// [`in_shadow`](Self::in_shadow)); 1 to 3 at the start of the frame right after it (it
    /// lost a byte, had a wrong count byte, or gained a byte: see
    /// [`other_stream_fits`](Self::other_stream_fits)).
    rejected: Option<Kind>,
    rejected_left: u8,
    /// The bytes thrown away right before the window's first byte, newest in the low byte
    /// (row 14: a frame that lost its first byte), and how many of them there are.
    before: u32,
    before_len: u8,
    stats: DownlinkStats,
}

const _: () = assert!(
    core::mem::size_of::<DownlinkParser>() <= 220,
    "DownlinkParser over its RAM budget"
);

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
            rejected: None,
            rejected_left: 0,
            before: 0,
            before_len: 0,
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

    /// [`push`](Self::push) when a decision may fall: a frame's last byte and junk with nothing
    /// before it take short ways here, a frame's first two bytes in
    /// [`push_decide`](Self::push_decide); anything else goes through
    /// [`push_general`](Self::push_general).
    #[inline(never)]
    fn push_slow(&mut self, byte: u8) -> Option<Downlink> {
        if !self.drain {
            if self.missing == 1 {
                // This byte completes the frame at the front of the window.
                if self.buf.push(byte) {
                    return self.complete();
                }
            } else if self.missing == 0 && self.buf.len() == 0 && !Kind::may_start(byte) {
                // A byte that starts no frame, with nothing before it: thrown away at once
                // (most bytes while hunting through noise: kept apart so that it costs little).
                self.discard_run(&[byte]);
                return None;
            }
        }
        self.push_decide(byte)
    }

    /// [`push_slow`](Self::push_slow) for the bytes its short ways leave.
    #[inline(never)]
    fn push_decide(&mut self, byte: u8) -> Option<Downlink> {
        if self.missing > 1 || self.drain {
            // The window's end is full (the general path makes room), or a frame is ready.
        } else if self.missing == 0 {
            // A frame's first two bytes: with the first, nothing can be decided; with the
            // second, the header gives the length to wait for.
            // (A byte that starts no frame went the short way.)
            let wait = match self.buf.as_slice() {
                [] => Some(0),
                &[first] => Kind::from_header(first, byte).map(|kind| kind.len().saturating_sub(2)),
                _ => None,
            };
            if let Some(wait) = wait {
                if self.buf.push(byte) {
                    self.missing = u8::try_from(wait).unwrap_or(0);
                    return None;
                }
            }
        }
        self.push_general(byte)
    }

    /// [`push`](Self::push) through the general judgement.
    #[inline(never)]
    fn push_general(&mut self, byte: u8) -> Option<Downlink> {
        let ready = if self.drain { self.poll() } else { None };
        self.append(&[byte]);
        match ready {
            Some(frame) => {
                // (The window is not empty now: `missing` of 2 is for an empty one.)
                self.missing = 0;
                Some(frame)
            }
            None => self.poll(),
        }
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

    /// The bytes just stored may have completed the frame at the front of the window: if it is
    /// alone there and row 1 takes it ([`row1_step`](Self::row1_step)), it is taken
    /// without the general judgement; a frame still incomplete waits without it; anything else
    /// is judged. The same decision either way: a shortcut, not a rule.
    #[inline(never)]
    fn complete(&mut self) -> Option<Downlink> {
        let bytes = self.buf.as_slice();
        if let [first, second, ..] = *bytes {
            if let Some(kind) = Kind::from_header(first, second) {
                // Incomplete (a read that ended inside it): the judgement would wait for the
                // rest, so wait for it without judging.
                if let Some(more) = kind.len().checked_sub(bytes.len()).filter(|n| *n > 0) {
                    self.wait_for(more);
                    return None;
                }
                // Row 1, the common case, without the general bookkeeping.
                if let (Kind::Telemetry(stream), true, Some(&seq)) =
                    (kind, kind.len() == bytes.len(), bytes.last())
                {
                    if let Some(step) = self.row1_step(stream, seq) {
                        if let Some(frame) = Downlink::read_telemetry(stream, bytes) {
                            self.take_learnt(stream, step, seq);
                            return Some(frame);
                        }
                    }
                }
                if let Some(more) = self.unawaited_reply_waits(kind, self.buf.as_slice()) {
                    self.wait_for(more);
                    return None;
                }
            }
        }
        self.run(false)
    }

    /// Row 11's first two judgements without the general judgement: a reply nobody awaits, on
    /// a boundary, whose next frame's header has not come yet waits for it (two bytes), and
    /// with that header waits for the rest of that frame. `None`: anything else.
    fn unawaited_reply_waits(&self, kind: Kind, bytes: &[u8]) -> Option<usize> {
        // (What row 11 needs, whatever kind of boundary.)
        const _: () = assert!(matches!(
            (
                rules::need(Start::Locked, Class::Unexpected),
                rules::need(Start::Tentative, Class::Unexpected),
            ),
            (Need::Chain(Chain::Exact), Need::Chain(Chain::Exact))
        ));
        if kind != Kind::Reply || self.lock == Lock::Hunting {
            return None;
        }
        let code = bytes.get(1).copied()?;
        if self.expect == Some(code) {
            return None;
        }
        match bytes.get(kind.len()..)? {
            [] => Some(2),
            [first, second] => {
                let next = Kind::from_header(*first, *second)?;
                Some(next.len().saturating_sub(2)).filter(|n| *n > 0)
            }
            _ => None,
        }
    }

    /// Row 1 as a shortcut, for a telemetry frame of `stream` whose bytes are alone in the
    /// window or about to be consumed from the caller's slice: on a boundary, a count `seq` one
    /// learnt step on takes it at once, with no judgement: the step (then
    /// [`take_learnt`](Self::take_learnt) takes it). `None`: anything else goes through the
    /// rules. A shortcut, not a rule.
    #[inline]
    fn row1_step(&self, stream: Stream, seq: u8) -> Option<usize> {
        // (Row 1 holds on a boundary whatever kind of boundary it is.)
        const _: () = assert!(matches!(
            (
                rules::need(Start::Locked, Class::Continues),
                rules::need(Start::Tentative, Class::Continues),
            ),
            (Need::Now, Need::Now)
        ));
        if self.lock == Lock::Hunting {
            return None;
        }
        self.counts.learnt_step(stream, seq)
    }

    /// Row 1's bookkeeping for a frame of `stream` at the front of the window (or about to be
    /// consumed from the caller's slice) whose count `seq` is learnt step `step` on.
    #[inline]
    fn take_learnt(&mut self, stream: Stream, step: usize, seq: u8) {
        // ([`leave`](Self::leave) for a frame on a boundary, so not found while hunting, that
        // is all the window holds, if the window holds anything.)
        let kind = Kind::Telemetry(stream);
        self.buf.clear();
        self.resynced = false;
        self.left(kind, kind.len());
        self.counts.take_step(stream, step, seq);
        // The window is empty: the next frame's header is stored, then judged (a junk first
        // byte is rejected with the second as it would have been on its own).
        self.missing = 2;
        self.drain = false;
    }

    /// The slice path's shortcut: on a boundary, the window empty or holding only the first
    /// bytes of a telemetry frame, and the rest of that frame at the front of `bytes`. If row 1
    /// takes it (its count one learnt step on: [`row1_step`](Self::row1_step)), it
    /// is taken as if its bytes had been stored one by one (each of them but the last is only
    /// stored: nothing can be decided before), and the bytes of `bytes` it used are returned
    /// with it. `None`: nothing done.
    #[inline]
    fn take_straight(&mut self, bytes: &[u8]) -> Option<(Downlink, usize)> {
        if self.drain {
            return None;
        }
        let kept = self.buf.as_slice();
        let (first, second) = match (kept, bytes) {
            ([], [a, b, ..]) | ([a], [b, ..]) | ([a, b, ..], _) => (*a, *b),
            _ => return None,
        };
        let stream = telemetry_header(&[first, second])?;
        let len = Kind::Telemetry(stream).len();
        let used = len
            .checked_sub(kept.len())
            .filter(|n| (1..=bytes.len()).contains(n))?;
        // (The count is a frame's last byte: in `bytes`.)
        let seq = *bytes.get(used.wrapping_sub(1))?;
        let step = self.row1_step(stream, seq)?;
        let frame = if kept.is_empty() {
            // Straight from the caller's slice, never copied.
            Downlink::read_telemetry(stream, bytes)?
        } else {
            // A frame cut by the end of the caller's last slice: its two parts, joined.
            // (`copy_from_slice`, not a loop: a loop's exit at a length that changes every
            // time is a branch mispredicted every time.)
            let mut joined = [0u8; telemetry::MAX_LEN];
            let (head, tail) = joined.split_at_mut_checked(kept.len())?;
            head.copy_from_slice(kept);
            tail.get_mut(..used)?.copy_from_slice(bytes.get(..used)?);
            Downlink::read_telemetry(stream, &joined)?
        };
        self.take_learnt(stream, step, seq);
        Some((frame, used))
    }

    /// The slice path's other shortcut: the window empty, and `bytes` the first bytes of a
    /// frame, its header whole, cut by the end of the caller's slice. Nothing can be decided
    /// before its last byte: they are stored (`true`). `false`: nothing done.
    #[inline]
    fn store_cut(&mut self, bytes: &[u8]) -> bool {
        if self.drain || self.buf.len() > 0 {
            return false;
        }
        let Some(kind) = (match bytes {
            [first, second, ..] => Kind::from_header(*first, *second),
            _ => None,
        }) else {
            return false;
        };
        match kind.len().checked_sub(bytes.len()).filter(|n| *n > 0) {
            Some(more) if self.buf.extend(bytes) == bytes.len() => {
                self.wait_for(more);
                true
            }
            _ => false,
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
            self.rejected_left = 0;
            self.before_len = 0;
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

    fn run(&mut self, quiet: bool) -> Option<Downlink> {
        self.missing = 0;
        loop {
            match self.judge(quiet) {
                Verdict::NeedMore(n) => {
                    self.wait_for(n);
                    return None;
                }
                Verdict::Reject => self.reject(),
                Verdict::Accept(frame, len, class) => {
                    self.accept(&frame, len, class);
                    // Another frame can be ready at once only if bytes are left.
                    self.drain = self.buf.len() > 0;
                    return Some(frame);
                }
            }
        }
    }

    /// Nothing can be decided before `n` more bytes: until then they are only stored.
    #[inline]
    fn wait_for(&mut self, n: usize) {
        self.drain = false;
        // Only a wait of two bytes or more is worth the shortcut: with one, the next byte is
        // judged anyway (and a lone junk byte is dropped at once).
        self.missing = if n > 1 {
            u8::try_from(n).unwrap_or(u8::MAX)
        } else {
            0
        };
    }

    /// Appends bytes; if the window is ever full, its first byte is rejected rather than a new
    /// byte lost.
    fn append(&mut self, mut bytes: &[u8]) {
        while !bytes.is_empty() {
            if self.buf.is_full() {
                self.reject();
            }
            let taken = self.buf.extend(bytes);
            bytes = bytes.get(taken..).unwrap_or(&[]);
        }
    }

    /// Bytes still missing from the frame whose header is at the front of the window (0 if
    /// there is none, or it is complete).
    fn front_missing(&self) -> u8 {
        match self.buf.as_slice() {
            [first, second, ..] => match Kind::from_header(*first, *second) {
                Some(kind) => u8::try_from(kind.len().saturating_sub(self.buf.len())).unwrap_or(0),
                None => 0,
            },
            _ => 0,
        }
    }

    /// What the candidate `frame`, starting `at` bytes into the window, is.
    fn class(&self, frame: &Downlink, at: usize) -> Class {
        match frame {
            // (Inside a frame rejected on a boundary, the awaited code is no evidence either:
            // row 12.)
            Downlink::Reply(reply)
                if self.expect == Some(reply.code)
                    && !(self.lock == Lock::Hunting && self.in_shadow() && at == 0) =>
            {
                Class::Expected {
                    clean: !holds_a_frame_start(reply.encode().get(2..).unwrap_or(&[])),
                }
            }
            Downlink::Reply(_) => Class::Unexpected,
            _ if self.lock == Lock::Hunting
                && at == 0
                && (self.in_shadow()
                    && (!self.near(frame) && self.nests_a_frame(frame, &[0])
                        || self.overlaps_the_rejected_frames_next(frame)
                        || self.is_the_rejected_frames_tail(frame))
                    || self.nests_a_frame(frame, &[1, -1])
                    || self.in_a_replys_value(frame)
                    || self.inside_a_headless_frame(frame)) =>
            {
                Class::Nested
            }
            _ => match (frame.kind(), frame.seq()) {
                (Kind::Telemetry(stream), Some(seq)) => {
                    let cut = self.ends_with_a_header(frame, at);
                    match self.counts.rel(stream, seq, at) {
                        // (Inside a frame rejected on a boundary, a continuing count is no
                        // evidence, nor one that is a header's second byte: row 9.)
                        Rel::Continues | Rel::Near
                            if self.lock == Lock::Hunting
                                && (self.in_shadow() && at == 0
                                    || self.other_stream_fits(stream, seq, at)
                                    || cut) =>
                        {
                            Class::Ambiguous
                        }
                        Rel::Continues => Class::Continues,
                        Rel::Near => Class::Near,
                        Rel::Unknown => Class::First,
                        Rel::Far if cut => Class::Cut,
                        Rel::Far => Class::Far,
                    }
                }
                _ => Class::Unexpected,
            },
        }
    }

    /// Inside a frame rejected on a boundary: whether a telemetry header lies inside the
    /// candidate `frame` (at the window's front) right where that frame, had it lost or gained a
    /// byte, would end: where the frame after it starts.
    fn overlaps_the_rejected_frames_next(&self, frame: &Downlink) -> bool {
        let end = usize::from(self.rejected_left).saturating_sub(2);
        let len = frame.kind().len();
        let buf = self.buf.as_slice();
        [end.wrapping_sub(1), end.saturating_add(1)]
            .into_iter()
            .filter(|at| (1..=len.saturating_sub(2)).contains(at))
            .any(|at| {
                buf.get(at..at.saturating_add(2))
                    .and_then(telemetry_header)
                    .is_some()
            })
    }

    /// Inside a frame rejected on a boundary: whether the candidate `frame` (at the window's
    /// front) is of the rejected frame's kind and starts two bytes into it, so that it ends
    /// where that frame ends if it gained two bytes, on its count byte: its payload from there.
    fn is_the_rejected_frames_tail(&self, frame: &Downlink) -> bool {
        self.rejected == Some(frame.kind()) && usize::from(self.rejected_left) == frame.kind().len()
    }

    /// Whether the last two bytes of the candidate `frame`, starting `at` bytes into the window,
    /// are a telemetry header.
    fn ends_with_a_header(&self, frame: &Downlink, at: usize) -> bool {
        let end = at.saturating_add(frame.kind().len());
        self.buf
            .as_slice()
            .get(end.saturating_sub(2)..end)
            .and_then(telemetry_header)
            .is_some()
    }

    /// Whether the telemetry candidate `frame` at the front of the window ends with a frame of
    /// another stream whose count (the candidate's) continues (or is near) that stream's; that
    /// frame's bytes there number its length plus one of `damage` (0: whole; -1: it lost a
    /// byte; 1: it gained one).
    fn nests_a_frame(&self, frame: &Downlink, damage: &[i8]) -> bool {
        let (Kind::Telemetry(outer), Some(seq)) = (frame.kind(), frame.seq()) else {
            return false;
        };
        let len = frame.kind().len();
        let bytes = self.buf.as_slice().get(..len).unwrap_or(&[]);
        // Only the places where such a frame would start are looked at.
        Stream::ALL.iter().any(|inner| {
            *inner != outer
                && damage.iter().any(|d| {
                    let inner_len = Kind::Telemetry(*inner)
                        .len()
                        .saturating_add_signed(isize::from(*d));
                    len.checked_sub(inner_len)
                        .filter(|off| *off > 0)
                        .is_some_and(|off| {
                            bytes
                                .get(off..off.saturating_add(2))
                                .and_then(telemetry_header)
                                == Some(*inner)
                                && matches!(
                                    self.counts.rel(*inner, seq, off),
                                    Rel::Continues | Rel::Near
                                )
                        })
                })
        })
    }

    /// Whether the telemetry candidate `frame` at the front of the window starts in a reply's
    /// value (the two bytes thrown away right before it are `23` and a reply code) and its
    /// tail, from where that reply ends, is a whole frame of another stream whose count (the
    /// candidate's) fits that stream: the reply and that frame are real, the candidate
    /// straddles them (a value starting `FF FA`).
    fn in_a_replys_value(&self, frame: &Downlink) -> bool {
        let (Kind::Telemetry(outer), Some(seq)) = (frame.kind(), frame.seq()) else {
            return false;
        };
        let [code, hash, ..] = self.before.to_le_bytes();
        if self.before_len < 2 || Kind::from_header(hash, code) != Some(Kind::Reply) {
            return false;
        }
        let len = frame.kind().len();
        let off = Kind::Reply.len().saturating_sub(2);
        let bytes = self.buf.as_slice().get(..len).unwrap_or(&[]);
        bytes
            .get(off..off.saturating_add(2))
            .and_then(telemetry_header)
            .is_some_and(|inner| {
                inner != outer
                    && Kind::Telemetry(inner).len().saturating_add(off) == len
                    && matches!(self.counts.rel(inner, seq, off), Rel::Continues | Rel::Near)
            })
    }

    /// Whether the telemetry candidate `frame` at the front of the window is the tail of a
    /// frame of another stream that lost its first byte: that frame's second header byte
    /// (`FA`..`FC`, not after an `FF`; after a frame taken or a quiet line, the byte before it
    /// is not known) among the bytes thrown away right before it, where the rest of that frame
    /// ends on the candidate's count byte, which fits that stream.
    fn inside_a_headless_frame(&self, frame: &Downlink) -> bool {
        let (Kind::Telemetry(own), Some(seq)) = (frame.kind(), frame.seq()) else {
            return false;
        };
        let len = frame.kind().len();
        // The byte `back` bytes before the window's first, if it was seen.
        let seen = self.before.to_le_bytes();
        let before = |back: usize| {
            seen.get(back.wrapping_sub(1))
                .copied()
                .filter(|_| back <= usize::from(self.before_len))
        };
        let [sync, _] = telemetry::Imu::HEADER;
        Stream::ALL.iter().any(|outer| {
            // The outer frame less its first byte ends where the candidate ends.
            let back = Kind::Telemetry(*outer)
                .len()
                .saturating_sub(1)
                .saturating_sub(len);
            *outer != own
                && back > 0
                && before(back).and_then(stream_of_second) == Some(*outer)
                && before(back.saturating_add(1)) != Some(sync)
                && matches!(self.counts.rel(*outer, seq, 0), Rel::Continues | Rel::Near)
        })
    }

    /// Whether the telemetry `frame` at the front of the window has a near count.
    fn near(&self, frame: &Downlink) -> bool {
        match (frame.kind(), frame.seq()) {
            (Kind::Telemetry(stream), Some(seq)) => self.counts.rel(stream, seq, 0) == Rel::Near,
            _ => false,
        }
    }

    /// Whether `seq` would continue (or be near) a stream other than `stream`; not counting, for
    /// a candidate right after a frame rejected on a boundary, that frame's stream: the count
    /// fits the slot of that damaged frame (one counter shared by all streams, a time tick),
    /// which is no evidence against the frame after it.
    fn other_stream_fits(&self, stream: Stream, seq: u8, at: usize) -> bool {
        let explained = match self.rejected {
            Some(Kind::Telemetry(rejected)) if at == 0 && (1..=3).contains(&self.rejected_left) => {
                Some(rejected)
            }
            _ => None,
        };
        Stream::ALL.iter().any(|other| {
            *other != stream
                && Some(*other) != explained
                && matches!(self.counts.rel(*other, seq, at), Rel::Continues | Rel::Near)
        })
    }

    /// Where the candidate at the front of the window starts, as the rules see it.
    fn start(&self) -> Start {
        match self.lock {
            Lock::Locked if self.resynced => Start::Resynced,
            lock => Start::from(lock),
        }
    }

    /// Judges the candidate at the front of the window. `quiet`: the line has gone quiet, so
    /// no more bytes are coming for now.
    fn judge(&self, quiet: bool) -> Verdict {
        let buf = self.buf.as_slice();
        let (first, second) = match buf {
            [] => return Verdict::NeedMore(1),
            [first] if Kind::may_start(*first) && !quiet => return Verdict::NeedMore(1),
            [_] => return Verdict::Reject,
            [first, second, ..] => (*first, *second),
        };
        let Some(kind) = Kind::from_header(first, second) else {
            return Verdict::Reject;
        };
        let len = kind.len();
        let Some(bytes) = buf.get(..len) else {
            return if quiet {
                Verdict::Reject
            } else {
                Verdict::NeedMore(len.saturating_sub(buf.len()))
            };
        };
        let Some(frame) = Downlink::read(kind, bytes) else {
            return Verdict::Reject;
        };
        let class = self.class(&frame, 0);
        let taken = match rules::need(self.start(), class) {
            Need::Now => Ok(true),
            Need::Never => Ok(false),
            Need::Follow => followed(buf, len, quiet).ok_or(1),
            Need::Chain(chain) => self.chain(buf, &frame, len, class, chain, quiet),
        };
        match taken {
            Ok(true) => Verdict::Accept(frame, len, class),
            Ok(false) => Verdict::Reject,
            Err(more) => Verdict::NeedMore(more.max(1)),
        }
    }

    /// Whether the chain of frames after the candidate (`frame`, `len` bytes) vouches for it;
    /// `Err(n)`: not decided yet, and not before `n` more bytes (a frame of the chain is
    /// incomplete: nothing is judged until its last byte).
    fn chain(
        &self,
        buf: &[u8],
        frame: &Downlink,
        len: usize,
        class: Class,
        chain: Chain,
        quiet: bool,
    ) -> Result<bool, usize> {
        let mut counts = self.counts;
        let own = match (frame.kind(), frame.seq()) {
            (Kind::Telemetry(stream), Some(seq)) => {
                counts.take(stream, seq, false);
                Some(stream)
            }
            _ => None,
        };
        // A quiet line right after the candidate: it filled the burst from one quiet line to
        // the next (Tentative), or its own count already continues.
        let quiet_vouches = match chain {
            // A reply nobody awaits that fills the line from a boundary up to the quiet line.
            Chain::Exact => self.lock != Lock::Hunting,
            Chain::Own | Chain::Restart => false,
            // A far count on a boundary that fills the line up to the quiet.
            Chain::Rebase => self.lock != Lock::Hunting,
            // Hunting, a quiet line vouches only for the awaited reply and a count that
            // continues exactly and fits no other stream, outside a frame rejected on a
            // boundary: a false frame in a damaged frame's tail ends exactly where the line goes
            // quiet, on that frame's count byte.
            Chain::Verify => {
                self.lock == Lock::Tentative
                    || matches!(class, Class::Expected { .. } | Class::Continues)
            }
        };
        let mut pos = len;
        let mut gap = if class == Class::Continues {
            MAX_GAP
        } else {
            0
        };
        let mut own_step: Option<(u8, u8)> = None;
        // (Exact) a frame of the chain already passed over.
        let mut skipped = false;
        loop {
            // The next frame's header: right at `pos`, or (first link of an exactly continuing
            // candidate) after up to two junk bytes.
            let mut found = None;
            for at in pos..=pos.saturating_add(gap) {
                match (buf.get(at), buf.get(at.saturating_add(1))) {
                    (Some(a), Some(b)) => {
                        if let Some(kind) = Kind::from_header(*a, *b) {
                            found = Some((at, kind));
                            break;
                        }
                    }
                    (None, _) if at == pos && quiet => {
                        return Ok(quiet_vouches);
                    }
                    (Some(a), None) if Kind::may_start(*a) && !quiet => return undecided(buf, 1),
                    // Nothing after the candidate yet: the next header is two bytes. Its
                    // first alone allows one decision (not a header: reject), and taking it
                    // a byte later, with the second, decides the same (a reply nobody awaits
                    // is judged once less).
                    (None, _) if !quiet => return undecided(buf, if at == pos { 2 } else { 1 }),
                    _ => {}
                }
            }
            let Some((at, kind)) = found else {
                // A reply nobody awaits, on a certain boundary, whose next frame lost its
                // first byte: the frame after that one decides. Unless the reply's last byte
                // is that first byte (`FF`): the next frame's header is then whole, a byte
                // early, and it is the reply that lost a byte.
                let [sync, _] = telemetry::Imu::HEADER;
                let lost_first = buf
                    .get(pos)
                    .and_then(|second| stream_of_second(*second))
                    .filter(|_| buf.get(pos.wrapping_sub(1)) != Some(&sync));
                return match lost_first {
                    Some(stream) if chain == Chain::Exact && !skipped => {
                        let next = pos
                            .saturating_sub(1)
                            .saturating_add(Kind::Telemetry(stream).len());
                        self.past_a_damaged_frame(buf, &counts, stream, &[next], quiet)
                    }
                    _ => Ok(false),
                };
            };
            // Junk between the candidate and its chain that is the tail of a frame from the
            // boundary before the candidate, which lost or gained a byte: the chain vouches for
            // that frame, not for the candidate inside it.
            if at > pos && self.a_damaged_frame_ends_at(at) {
                return Ok(false);
            }
            let end = at.saturating_add(kind.len());
            let Some(bytes) = buf.get(at..end) else {
                return if quiet || end > WINDOW {
                    Ok(false)
                } else {
                    Err(end.saturating_sub(buf.len()))
                };
            };
            let Some(next) = Downlink::read(kind, bytes) else {
                return Ok(false);
            };
            // The master asked once: an awaited reply whose chain holds another reply with the
            // same code is not the answer (a `23` and the code in a damaged frame's tail, the
            // real reply further on).
            if matches!(class, Class::Expected { .. })
                && matches!(next, Downlink::Reply(reply) if self.expect == Some(reply.code))
            {
                return Ok(false);
            }
            if chain == Chain::Exact {
                // Only the next frame, continuing exactly; a stream's first frame (no count to
                // judge by) is passed over, a reply is not.
                match (next.kind(), next.seq()) {
                    (Kind::Telemetry(stream), Some(seq)) => match counts.rel(stream, seq, at) {
                        Rel::Continues => return Ok(true),
                        // On a certain boundary, frames lost upstream.
                        Rel::Near => return Ok(self.lock == Lock::Locked),
                        Rel::Unknown => counts.take(stream, seq, false),
                        // The next frame damaged (its count byte lost or changed): the frame
                        // after it decides.
                        Rel::Far if !skipped => {
                            let places = [end.saturating_sub(1), end.saturating_add(1)];
                            return self.past_a_damaged_frame(buf, &counts, stream, &places, quiet);
                        }
                        Rel::Far => return Ok(false),
                    },
                    _ => return Ok(false),
                }
                pos = end;
                gap = 0;
                skipped = true;
                continue;
            }
            if let (Kind::Telemetry(stream), Some(seq)) = (next.kind(), next.seq()) {
                if own == Some(stream) && counts.too_soon(stream, at) {
                    return Ok(false);
                }
                // A frame whose count byte is the second byte of a telemetry header (its last
                // two bytes are one: a cut frame running into the next one, row 15) is no
                // evidence: passed over.
                if self.ends_with_a_header(&next, at) {
                    counts.take(stream, seq, false);
                    pos = end;
                    gap = 0;
                    continue;
                }
                let own_only = matches!(chain, Chain::Own | Chain::Restart);
                let mut vouches = !own_only || own == Some(stream);
                let in_step = chain == Chain::Restart || !counts.has_steps(stream);
                if vouches && own_only && in_step {
                    // No step learnt: sensor bytes drift slowly, and payloads repeat a frame's
                    // length apart, so false frames' "counts" can move in small steps for a
                    // while. Four frames of the stream, equally spaced, vouch.
                    let delta = seq.wrapping_sub(counts.last(stream));
                    match own_step {
                        Some((step, seen)) if step == delta && seen >= IN_STEP - 1 => {}
                        Some((step, seen)) if step == delta => {
                            own_step = Some((step, seen.saturating_add(1)));
                            vouches = false;
                        }
                        Some(_) => return Ok(false),
                        None => {
                            own_step = Some((delta, 1));
                            vouches = false;
                        }
                    }
                }
                match counts.rel(stream, seq, at) {
                    Rel::Continues if vouches => return Ok(true),
                    Rel::Near if vouches => return Ok(chain != Chain::Exact),
                    Rel::Continues | Rel::Near => counts.take(stream, seq, false),
                    Rel::Unknown => counts.take(stream, seq, false),
                    Rel::Far if matches!(chain, Chain::Rebase | Chain::Restart) => {
                        counts.take(stream, seq, false);
                    }
                    Rel::Far => return Ok(false),
                }
            }
            pos = end;
            gap = 0;
        }
    }

    /// Whether a telemetry frame that started on the boundary right before the bytes thrown away
    /// ahead of the window (one to three of them, the first `FF`) and lost or gained a byte
    /// would end `at` bytes into the window.
    fn a_damaged_frame_ends_at(&self, at: usize) -> bool {
        let thrown = usize::from(self.before_len);
        let [sync, _] = telemetry::Imu::HEADER;
        let first = self
            .before
            .to_le_bytes()
            .get(thrown.wrapping_sub(1))
            .copied();
        if !(1..=3).contains(&thrown) || first != Some(sync) {
            return false;
        }
        let span = thrown.saturating_add(at);
        [Stream::Imu, Stream::Encoders, Stream::Battery]
            .into_iter()
            .map(|stream| Kind::Telemetry(stream).len())
            .any(|len| span.saturating_add(1) == len || span == len.saturating_add(1))
    }

    /// For a reply nobody awaits on a certain boundary (row 11) whose next frame is damaged:
    /// whether a frame right after that one, at one of `places` (where it starts if the damaged
    /// frame lost its header's first byte, or lost or gained a byte inside), continues its
    /// stream's count.
    #[inline(never)]
    fn past_a_damaged_frame(
        &self,
        buf: &[u8],
        counts: &Counts,
        damaged: Stream,
        places: &[usize],
        quiet: bool,
    ) -> Result<bool, usize> {
        if self.lock != Lock::Locked {
            return Ok(false);
        }
        let mut counts = *counts;
        counts.passed(damaged);
        for &at in places {
            let next = match (buf.get(at), buf.get(at.saturating_add(1))) {
                (Some(a), Some(b)) => Kind::from_header(*a, *b),
                _ if quiet => return Ok(false),
                _ => return undecided(buf, at.saturating_add(2).saturating_sub(buf.len())),
            };
            let Some(Kind::Telemetry(stream)) = next else {
                continue;
            };
            let end = at.saturating_add(Kind::Telemetry(stream).len());
            let Some(seq) = buf.get(at.saturating_add(stream.seq_at())) else {
                return if quiet || end > WINDOW {
                    Ok(false)
                } else {
                    Err(end.saturating_sub(buf.len()))
                };
            };
            if counts.rel(stream, *seq, at) == Rel::Continues {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Drops the candidate's first byte and goes hunting.
    fn reject(&mut self) {
        // A frame rejected on a boundary: the start positions inside it (row 14) and right
        // after it. (Right where the frame rejected before ends, a byte lost or gained or its
        // count byte changed, is a boundary too.)
        let boundary = self.lock != Lock::Hunting || (1..=3).contains(&self.rejected_left);
        if let (true, [first, second, ..]) = (boundary, self.buf.as_slice()) {
            if let Some(kind) = Kind::from_header(*first, *second) {
                self.rejected = Some(kind);
                self.rejected_left = u8::try_from(kind.len().saturating_add(2)).unwrap_or(0);
            }
        }
        let first = self.buf.as_slice().first().copied().unwrap_or(0);
        self.buf.drop_front(1);
        self.discard(first);
    }

    /// Whether the candidate at the front of the window starts inside the frame last rejected
    /// on a boundary: within the length its header promised, less [`MAX_DROPPED`] bytes it may
    /// have lost.
    fn in_shadow(&self) -> bool {
        usize::from(self.rejected_left) > MAX_DROPPED.saturating_add(2)
    }

    /// Counts one byte thrown away (already out of the window, or never in it): `byte`, the
    /// one right before the window's first byte now.
    fn discard(&mut self, byte: u8) {
        self.before = self.before << 8 | u32::from(byte);
        self.thrown_away(1);
    }

    /// Counts the bytes of `run` thrown away, in one step: the same as one
    /// [`discard`](Self::discard) per byte. The last of them is now right before the window's
    /// first byte.
    #[inline]
    fn discard_run(&mut self, run: &[u8]) {
        let n = run.len();
        for byte in run.iter().skip(n.saturating_sub(4)) {
            self.before = self.before << 8 | u32::from(*byte);
        }
        self.thrown_away(n);
    }

    /// The counters, counts and lock for `n` bytes thrown away.
    #[inline]
    fn thrown_away(&mut self, n: usize) {
        self.before_len = self
            .before_len
            .saturating_add(u8::try_from(n).unwrap_or(u8::MAX));
        self.consumed(n);
        self.counts.discarded();
        self.stats.discarded = self
            .stats
            .discarded
            .wrapping_add(u32::try_from(n).unwrap_or(u32::MAX));
        if self.lock != Lock::Hunting && n > 0 {
            self.stats.lock_losses = self.stats.lock_losses.wrapping_add(1);
            self.lock = Lock::Hunting;
        }
    }

    /// `n` bytes left the window (the counts are forgotten each time [`FORGET_AFTER`] bytes
    /// without a frame are reached, as if one byte at a time).
    fn consumed(&mut self, n: usize) {
        self.rejected_left = self
            .rejected_left
            .saturating_sub(u8::try_from(n).unwrap_or(u8::MAX));
        self.counts.bytes(n);
        let mut total = usize::from(self.since_frame).saturating_add(n);
        let forget_after = usize::from(FORGET_AFTER);
        if total >= forget_after {
            self.counts.forget();
            total = total.checked_rem(forget_after).unwrap_or(0);
        }
        self.since_frame = u16::try_from(total).unwrap_or(0);
    }

    /// Consumes an accepted frame: counts, counters, lock.
    fn accept(&mut self, frame: &Downlink, len: usize, class: Class) {
        if let (Class::Continues, Kind::Telemetry(stream), Some(seq)) =
            (class, frame.kind(), frame.seq())
        {
            self.take_continuing(stream, seq, len);
            return;
        }
        // A far count taken on a certain boundary is believed only if its own stream's next
        // frame continues it (the board moved its count on); otherwise it is a damaged count
        // byte, and the stream moves on by a step.
        let believed = class != Class::Far
            || self.chain(self.buf.as_slice(), frame, len, class, Chain::Own, false) == Ok(true);
        // Frames lost (a near count) teach no step, unless nothing was lost.
        let near = match (class, frame.kind(), frame.seq()) {
            (Class::Near, ..) => true,
            (Class::Ambiguous, Kind::Telemetry(stream), Some(seq)) => {
                self.counts.rel(stream, seq, 0) == Rel::Near
            }
            _ => false,
        };
        self.leave(frame.kind(), len);
        match (frame.kind(), frame.seq(), frame) {
            (Kind::Telemetry(stream), Some(seq), _) if !believed => self.counts.skip(stream, seq),
            (Kind::Telemetry(stream), Some(seq), _) if near => {
                let missed = self.counts.missed(stream, seq);
                if !self.counts.take_near(stream, seq) {
                    self.stats.count_gap(stream, missed);
                }
            }
            (Kind::Telemetry(stream), Some(seq), _) => self.counts.take(stream, seq, true),
            (_, _, Downlink::Reply(reply)) if self.expect == Some(reply.code) => {
                self.expect = None;
            }
            _ => {}
        }
    }
}

impl DownlinkParser {
    /// [`accept`](Self::accept) for telemetry whose count continues its stream (row 1): the
    /// frame's bytes leave the window, its count and step are taken, the parser is Locked.
    fn take_continuing(&mut self, stream: Stream, seq: u8, len: usize) {
        self.leave(Kind::Telemetry(stream), len);
        self.counts.take(stream, seq, true);
    }

    /// A frame of `kind`, `len` bytes, was taken: its bytes leave the window, it is counted, and
    /// the parser is Locked right after it (the counts are the caller's).
    #[inline]
    fn leave(&mut self, kind: Kind, len: usize) {
        self.buf.drop_front(len);
        self.resynced = self.lock == Lock::Hunting;
        if self.lock == Lock::Hunting {
            self.stats.resyncs = self.stats.resyncs.wrapping_add(1);
        }
        self.left(kind, len);
    }

    /// What every frame taken does to the counters, the counts' clock and the lock, wherever
    /// its bytes were.
    #[inline]
    fn left(&mut self, kind: Kind, len: usize) {
        self.counts.bytes(len);
        self.since_frame = 0;
        self.rejected_left = 0;
        self.before_len = 0;
        self.stats.count_frame(kind);
        self.lock = Lock::Locked;
    }
}

/// Not decided: `more` bytes are needed, unless the window is already full.
fn undecided(buf: &[u8], more: usize) -> Result<bool, usize> {
    if buf.len() >= WINDOW {
        Ok(false)
    } else {
        Err(more)
    }
}

/// Whether a header (or the quiet line) follows the `len` bytes of the candidate.
fn followed(buf: &[u8], len: usize, quiet: bool) -> Option<bool> {
    match buf.get(len..) {
        Some([next, after, ..]) => Some(Kind::from_header(*next, *after).is_some()),
        Some([next]) if !Kind::may_start(*next) => Some(false),
        Some([]) | None if quiet => Some(true),
        _ if quiet => Some(false),
        _ => None,
    }
}

/// Whether `bytes` hold a telemetry header (a reply's value that might be a cut reply with the
/// next frame's start in it).
fn holds_a_frame_start(bytes: &[u8]) -> bool {
    bytes
        .windows(2)
        .any(|pair| telemetry_header(pair).is_some())
}

/// The stream whose telemetry header ends with `second`, if one does.
fn stream_of_second(second: u8) -> Option<Stream> {
    let [sync, _] = telemetry::Imu::HEADER;
    telemetry_header(&[sync, second])
}

/// The stream whose telemetry header `pair` is, if it is one.
fn telemetry_header(pair: &[u8]) -> Option<Stream> {
    match pair {
        [a, b] => match Kind::from_header(*a, *b) {
            Some(Kind::Telemetry(stream)) => Some(stream),
            _ => None,
        },
        _ => None,
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
