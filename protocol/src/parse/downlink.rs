//! The board → master streaming parser: telemetry and replies out of a noisy byte stream.
//!
//! # Why this is not a plain state machine over one frame
//!
//! There is no checksum and no length byte (ambiguity A7). `FF FA`, `FF FB` and `FF FC` are
//! -6, -5 and -4 as big-endian `i16`, so a gyro at rest writes false headers into IMU payloads
//! all the time, and `23` is an ordinary byte. UARTs drop bytes on overrun, lines pick up noise,
//! and a master may start listening mid-frame. The parser therefore keeps a small window of
//! bytes from the start of the frame it is judging, and weighs three pieces of evidence:
//!
//! 1. **The header** (`FF FA` / `FF FB` / `FF FC`, or `23` followed by a reply code the spec
//!    defines). It fixes the frame's length.
//! 2. **The count byte**: each stream has a rolling count, so a frame whose count follows the
//!    last one of its stream is almost certainly aligned (a false frame's count is right about
//!    one time in 256).
//! 3. **What follows**: the two bytes after the frame must be a header too (or the line must go
//!    quiet, see [`DownlinkParser::idle`]).
//!
//! # States
//!
//! ```text
//!             frame accepted                      CONFIRMATIONS frames continue their counts
//!   Hunting ─────────────────────► Tentative ───────────────────────────────────► Locked
//!      ▲   (header + what follows            │                                       │
//!      │    + a plausible count)              │                                       │
//!      └────────── candidate rejected: drop its first byte, rescan ◄──────────────────┘
//! ```
//!
//! * **Hunting**: alignment unknown; scanning for a frame.
//! * **Tentative**: aligned by a hunt (or by a quiet line, see [`DownlinkParser::idle`]), not yet
//!   confirmed. It must see a frame continue its count at least every [`PROBATION_FRAMES`]
//!   frames, or it is dropped.
//! * **Locked**: [`CONFIRMATIONS`] frames of this alignment continued their counts.
//!
//! [`DownlinkParser::lock`] tells the states apart, for callers that want to trust only
//! confirmed data.
//!
//! # Rules
//!
//! A candidate needs a header (which fixes its length) and all its bytes. Then its count is
//! compared with its stream's last count: it **continues** it (+1), is **near** it (up to
//! [`NEAR_STEPS`] for its stream, one more step for every [`BYTES_PER_FRAME`] of its stream
//! received since the last confirmed frame; at least [`LOCKED_STEPS`] while Locked), is **far**
//! from it, or there is no count to compare with (the stream's first frame; or a *provisional*
//! count, below). Or it **continues the last jump**: it is not the next count of its stream, but
//! the next after the count of the stream's last *jump* (a far count taken while Locked, or a
//! whole IMU or encoder candidate that a header followed and that was turned down for its count
//! alone). Two frames in a row then agree that the count has moved on: bytes were lost in a
//! burst, so more frames went missing than the bytes received since tell.
//!
//! | state | on its last byte | two bytes later, if they are a header (or the line is quiet) | otherwise |
//! |---|---|---|---|
//! | Hunting | — | count continues or is near (also a provisional count, or any count while none is trusted); a reply holding no header in its value; an IMU or encoder stream's first frame while no count is trusted; a count that continues the last jump if the frame starts where the jump candidate ended (that candidate's following header) | reject |
//! | Tentative | count continues; a reply holding no header | anything but a far count (at most PROBATION_FRAMES in a row without a count that continues); a count that continues the last jump only right after a frame whose count continued, or where the jump candidate ended | reject |
//! | Locked | count continues; a reply holding no header | count near; a count that continues the last jump; a reply; a far, provisional or first count only if the frame before was not itself taken on weak evidence (a jump, a hunt) | reject |
//!
//! The line going quiet ([`DownlinkParser::idle`]) counts as a header after the frame it ends.
//! It is no proof of a battery frame while hunting, though: hunting at a quiet line means the
//! burst of bytes before it did not parse from its start, and a false `FF FC` at an IMU frame's
//! gyro X (-4, common at rest) ends on that frame's last byte, exactly where the line goes quiet.
//! After a quiet line the next byte is taken to start a frame (Tentative), so a master that
//! reports quiet lines gets the next battery frame; measured on the simulator's bursts, starting
//! to listen anywhere then costs nothing after the first complete frame and emits nothing false
//! (taking the battery frame at the quiet line made 4.7 % of starts emit a false one).
//!
//! * A rejected candidate costs exactly **one** byte: its first. Scanning starts again at the
//!   byte after it, over the bytes already in the window, so a real frame that a false candidate
//!   overlapped is still found. Nothing is ever thrown away a frame at a time.
//! * A count is **trusted** when it continued the stream's previous count, or when its frame was
//!   taken on a confirmed (Locked) alignment without a jump. Any other count is **provisional**:
//!   it confirms a later frame that continues it, but never counts against one (except while
//!   hunting, where it is the best guess there is, once some count is trusted). A jump on a
//!   confirmed alignment moves the stream's count on by one, as if the count byte had been
//!   damaged; a frame that continues the last jump re-bases the count (frames were lost, or
//!   the board restarted its count). While hunting, only a frame that starts where the jump
//!   candidate ended: two false candidates anywhere can continue each other as well as two real
//!   frames can, but a false candidate rarely ends on the next one's header. (Measured: taking
//!   them anywhere raised false frames by a third at 1e-2 errors per byte.)
//!   [`DownlinkParser::idle`] makes every count provisional: the board pauses telemetry while
//!   settings are made, and its counts may have moved on.
//! * After [`FORGET_AFTER`] bytes without a single frame that continues its count, every count is
//!   forgotten (the board may have restarted; a false alignment may have taught a false count).
//!   That bounds how long anything can hold the parser off: it can never stay stuck.
//! * A reply whose value bytes hold `FF FA`..`FF FC` could be a truncated reply with the next
//!   frame's start in it: it waits for the next header (or a quiet line), and while hunting it is
//!   not taken.
//!
//! # The trade-off chosen
//!
//! Latency is spent only where evidence is missing. While aligned and counts continue, every
//! frame comes out on its last byte. Otherwise a frame comes out two bytes late, once the next
//! header proves the boundary, and while hunting it also needs a plausible count: that is what
//! keeps false frames rare, since the false candidates that damaged frames are full of must pass
//! a 16-bit header, a count check of a few in 256, and a following header. The price is paid at
//! start-up, when no count is known: a parser that starts listening in the middle of a frame has
//! only the headers to go by, and a payload dense with false headers can fool it for a frame or
//! two (the counts expose it right after); a first battery frame is not taken on headers alone.
//! That is on a line where frames come back to back. The real board leaves its line idle most of
//! the time (telemetry fills about 15 % of it), and a master that calls
//! [`DownlinkParser::idle`] when the line goes quiet starts exactly: on the simulator's output,
//! every frame after the first complete one and nothing false, from any start offset. Callers
//! that want no doubtful data drop frames while [`DownlinkParser::lock`] is not
//! [`Lock::Locked`]. The measured figures (recall, false frames per million, frames lost per
//! error, latency, start-up) come from `cargo xtask sweep` (`noise-sweep` in
//! `chassis-host-tests`); at 1e-3 errors per byte: 99.99 % recall, 3 to 10 false frames per
//! million sent.
//!
//! # Memory and time
//!
//! The parsing state is 32 bytes (asserted at compile time to stay at most 32); the counters are
//! a separate [`DownlinkStats`] (52 bytes). Each byte costs a header check and, on a frame's last
//! byte, a decode of at most 15 bytes and a shift of the window of at most 17 bytes. Nothing
//! allocates.
//!
//! # Panics
//!
//! Never, on any input: no indexing, no unchecked arithmetic on any path that bytes reach.

use super::stats::DownlinkStats;
use super::window::Window;
use crate::telemetry::{self, Downlink, Kind, Stream};

/// Bytes kept: the longest frame and the two bytes after it.
const WINDOW: usize = telemetry::MAX_LEN + 2;

/// While hunting, how far past its stream's last count a count may be, per stream (IMU,
/// encoders, battery), before any allowance for lost frames: one frame of the stream may have
/// been in the damaged stretch, except for the battery, whose frames are a second apart.
pub const NEAR_STEPS: [u8; 3] = [2, 2, 1];

/// Bytes of the stream per frame of each stream (IMU, encoders, battery), rounded down from the
/// board's rates (100 / 25 / 1 Hz, 1 782 bytes/s in all): each such stretch received since the
/// last confirmed frame allows one more step.
pub const BYTES_PER_FRAME: [u16; 3] = [15, 60, 1_500];

/// While Locked, a count may jump by up to this many steps (frames lost upstream) and still be
/// trusted, once the next header proves the boundary.
pub const LOCKED_STEPS: u8 = 8;

/// After this many bytes without a frame that continues its count, the counts are forgotten
/// (the board may have restarted, or a false alignment taught false counts): the parser can
/// never stay stuck.
pub const FORGET_AFTER: u16 = 160;

/// A Tentative lock becomes Locked after this many frames whose count follows their stream.
pub const CONFIRMATIONS: u8 = 2;

/// A Tentative lock must see a frame continue its count at least every this many frames, or the
/// next frame that does not is rejected and the parser hunts again.
pub const PROBATION_FRAMES: u8 = 4;

/// How sure the parser is of where frames start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Lock {
    /// Alignment unknown: scanning for a frame.
    Hunting,
    /// Aligned by a hunt (or by a quiet line), not yet confirmed by counts.
    Tentative,
    /// Aligned and confirmed: [`CONFIRMATIONS`] frames in a row of it continued their counts.
    Locked,
}

/// `State::jump_stream` when there is no jump to remember.
const NO_JUMP: u8 = u8::MAX;

impl State {
    /// The window's front moved on by `n` bytes: so much nearer the end of the jump candidate.
    fn passed(&mut self, n: usize) {
        self.jump_ahead = match u8::try_from(n) {
            Ok(n) if n <= self.jump_ahead && self.jump_ahead != PASSED => {
                self.jump_ahead.saturating_sub(n)
            }
            _ => PASSED,
        };
    }
}

/// The parsing state proper, counters excluded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct State {
    /// Bytes from the first byte of the candidate being judged.
    window: Window<WINDOW>,
    lock: Lock,
    /// Bit `i` set: `last_seq[i]` holds a count of stream `i` (IMU, encoders, battery).
    seen: u8,
    /// Bit `i` set: stream `i`'s count is provisional: learnt on an alignment not yet
    /// confirmed, or a jump, or from before a quiet line. It confirms a frame that continues it
    /// but never counts against one that does not.
    provisional: u8,
    /// The last count of each stream.
    last_seq: [u8; 3],
    /// The last count that jumped: of a frame taken on a confirmed alignment with a far count,
    /// or of a whole candidate that a header followed but whose count was not plausible. The
    /// stream's index (`NO_JUMP` if none) and the count. A frame that continues it re-bases its
    /// stream's count (see [`Continuity::ContinuesJump`]).
    jump_stream: u8,
    jump_seq: u8,
    /// The last frame was taken on weak evidence (a count jump, a hunt): the boundary after it
    /// is not certain.
    weak: bool,
    /// While Tentative: frames so far whose count continued their stream.
    confirms: u8,
    /// Downlink frames accepted since the last one that continued its count (saturating).
    since_continued: u8,
    /// The last `poll` emitted a frame: another may be ready without a new byte.
    drain: bool,
    /// Bytes received since the last frame that continued its count on a Locked alignment, less
    /// FORGET_AFTER each time the counts are forgotten: never more than FORGET_AFTER + WINDOW.
    since_confirmed: u8,
    /// How far the window's front still is from the end of the jump candidate that set
    /// `jump_stream` (`PASSED` once it is behind): 0 means the candidate at the front starts
    /// right where that one ended, so the jump candidate's following header is this one.
    jump_ahead: u8,
}

/// `State::jump_ahead` once the front has moved past the end of the jump candidate.
const PASSED: u8 = u8::MAX;

const _: () = assert!(
    FORGET_AFTER as usize + WINDOW < u8::MAX as usize,
    "since_confirmed must fit in a byte"
);

const _: () = assert!(
    core::mem::size_of::<State>() <= 32,
    "downlink state over 32 bytes"
);

/// What the bytes in the window say about the candidate at its front.
enum Verdict {
    /// Not enough bytes to decide.
    NeedMore,
    /// The first byte starts no frame: drop it. With the stream and count of a whole candidate
    /// that a header followed, turned down only for its count: remembered as a jump.
    Reject(Option<(Stream, u8)>),
    /// A frame of this length.
    Accept(Downlink, usize),
}

/// How a candidate's count relates to its stream's last count.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Continuity {
    /// A reply: no count.
    Reply,
    /// No count seen yet on this stream.
    Unknown,
    /// Exactly the next count.
    Continues,
    /// Not the next count of its stream, but the next count after the stream's last jump (see
    /// `State::jump_stream`): two frames in a row agree that the count has moved on (frames were
    /// lost, a burst of bytes was dropped, the board restarted its count). Taken when a header
    /// follows (while hunting, only where the jump candidate ended); the stream's count is
    /// re-based on it.
    ContinuesJump,
    /// Not the next count, but the stream's count is provisional: no evidence either way.
    Provisional,
    /// A few counts on from a trusted count (see [`NEAR_STEPS`]).
    Near,
    /// Anything else.
    Far,
}

/// The board → master streaming parser. See the [module docs](self) for how it resynchronises.
///
/// ```
/// use chassis_protocol::{Battery, DownlinkParser, Lock, Downlink};
///
/// let battery = Battery { centivolts: 1_100, percent: 87, seq: 3 };
/// let mut parser = DownlinkParser::new();
/// // An IMU frame split across two reads, then a battery frame: no count is known yet, so each
/// // frame waits for proof that it is one (here, the next header).
/// let imu = [0xFF, 0xFA, 0x00, 0x01, 0xFF, 0xFE, 0x40, 0x00, 0x00, 0x00, 0xFF, 0xFC, 0x00, 0x02, 0x07];
/// let reads: [&[u8]; 3] = [&imu[..9], &imu[9..], &battery.encode()];
/// let mut got = Vec::new();
/// for read in reads {
///     got.extend(parser.frames(read));
/// }
/// assert_eq!(got.len(), 1);
/// assert!(matches!(got[0], Downlink::Imu(imu) if imu.gyro == [0, -4, 2] && imu.seq == 7));
/// // The line goes quiet: that ends the battery frame as a header would.
/// assert_eq!(parser.idle(), Some(Downlink::Battery(battery)));
/// assert_eq!(parser.lock(), Lock::Tentative);
/// assert_eq!(parser.stats().discarded, 0);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DownlinkParser {
    state: State,
    stats: DownlinkStats,
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
            state: State {
                window: Window::new(),
                lock: Lock::Hunting,
                seen: 0,
                provisional: 0,
                last_seq: [0; 3],
                jump_stream: NO_JUMP,
                jump_seq: 0,
                weak: false,
                confirms: 0,
                since_continued: 0,
                drain: false,
                since_confirmed: 0,
                jump_ahead: PASSED,
            },
            stats: DownlinkStats::new(),
        }
    }

    /// Feeds one byte. Returns a frame when this byte completes (or proves) one.
    ///
    /// At most one frame comes out per call. Right after a resynchronisation two frames can be
    /// ready at once; the second comes out of the next call (of `push`, [`push_slice`],
    /// [`poll`] or [`idle`]), never lost.
    ///
    /// [`push_slice`]: DownlinkParser::push_slice
    /// [`poll`]: DownlinkParser::poll
    /// [`idle`]: DownlinkParser::idle
    pub fn push(&mut self, byte: u8) -> Option<Downlink> {
        let ready = if self.state.drain { self.poll() } else { None };
        self.append(&[byte]);
        match ready {
            Some(frame) => Some(frame),
            None => self.poll(),
        }
    }

    /// Feeds bytes until a frame comes out; returns it and the bytes not yet consumed. Call
    /// again with the rest until it returns `(None, [])` (with an empty slice it emits a frame
    /// still ready in the window, as [`poll`](DownlinkParser::poll) does). It goes through the
    /// same states as feeding the same bytes one at a time through
    /// [`push`](DownlinkParser::push), so it emits the same frames in the same order; it only
    /// copies a frame's body in one step where no decision can fall in between.
    pub fn push_slice<'a>(&mut self, mut bytes: &'a [u8]) -> (Option<Downlink>, &'a [u8]) {
        if bytes.is_empty() && self.state.drain {
            return (self.poll(), bytes);
        }
        while let Some((&first, rest)) = bytes.split_first() {
            if self.state.drain {
                // Exactly as `push` does it, so both paths go through the same states.
                bytes = rest;
                if let Some(frame) = self.push(first) {
                    return (Some(frame), bytes);
                }
                continue;
            }
            let step = self.bytes_before_decision().max(1).min(bytes.len());
            let (now, later) = bytes.split_at_checked(step).unwrap_or((bytes, &[]));
            self.append(now);
            bytes = later;
            if let Some(frame) = self.poll() {
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

    /// Emits a frame that is already complete in the window, if any, without a new byte.
    pub fn poll(&mut self) -> Option<Downlink> {
        loop {
            match self.judge(false) {
                Verdict::NeedMore => {
                    self.state.drain = false;
                    return None;
                }
                Verdict::Reject(jump) => self.reject(jump),
                Verdict::Accept(frame, len) => {
                    self.accept(&frame, len);
                    self.state.drain = true;
                    return Some(frame);
                }
            }
        }
    }

    /// Tells the parser that the line has been quiet for at least a frame's time (two or three
    /// idle characters are enough: the board sends a frame's bytes back to back). Call it in a
    /// loop until it returns `None`.
    ///
    /// A complete frame waiting for the next header is judged as if one had come (silence is a
    /// frame boundary; but while hunting, not proof enough of a battery frame with no count to
    /// go by: see the [module docs](self)); an incomplete one is thrown away. With the window
    /// empty, the next byte is taken to start a frame (the parser becomes at least
    /// *Tentative*). UART peripherals
    /// with an idle-line interrupt make this free; without one, call it from a timeout.
    pub fn idle(&mut self) -> Option<Downlink> {
        loop {
            match self.judge(true) {
                Verdict::NeedMore => {
                    self.state.drain = false;
                    if self.state.lock == Lock::Hunting {
                        self.state.lock = Lock::Tentative;
                    }
                    // The board may have paused its telemetry (it does while settings are
                    // made): the counts may jump, so they no longer count against a frame.
                    self.state.provisional = self.state.seen;
                    return None;
                }
                Verdict::Reject(jump) => self.reject(jump),
                Verdict::Accept(frame, len) => {
                    self.accept(&frame, len);
                    self.state.drain = true;
                    return Some(frame);
                }
            }
        }
    }

    /// How sure the parser is of where frames start.
    #[must_use]
    pub const fn lock(&self) -> Lock {
        self.state.lock
    }

    /// Bytes received but not yet emitted or thrown away (at most 17).
    #[must_use]
    pub const fn buffered(&self) -> usize {
        self.state.window.len()
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

    /// Appends bytes to the window. The window always has room (see `poll`), but if it ever did
    /// not, the oldest byte is rejected rather than a new one lost.
    fn append(&mut self, mut bytes: &[u8]) {
        while !bytes.is_empty() {
            if self.state.window.is_full() {
                self.reject(None);
            }
            let taken = self.state.window.extend(bytes);
            bytes = bytes.get(taken..).unwrap_or(&[]);
            let state = &mut self.state;
            let taken = u8::try_from(taken).unwrap_or(u8::MAX);
            state.since_confirmed = state.since_confirmed.saturating_add(taken);
            if u16::from(state.since_confirmed) >= FORGET_AFTER {
                state.seen = 0;
                state.provisional = 0;
                state.jump_stream = NO_JUMP;
                state.jump_ahead = PASSED;
                // Keep the bytes past the mark, so that bytes fed one at a time and in a slice
                // leave the same state.
                let forget = u8::try_from(FORGET_AFTER).unwrap_or(u8::MAX);
                state.since_confirmed = state.since_confirmed.saturating_sub(forget);
            }
        }
    }

    /// How many bytes can be added before the verdict can change: the rest of a frame whose
    /// header is in the window, else 1.
    fn bytes_before_decision(&self) -> usize {
        match self.state.window.as_slice() {
            [first, second, ..] => match Kind::from_header(*first, *second) {
                Some(kind) => kind.len().saturating_sub(self.state.window.len()).max(1),
                None => 1,
            },
            _ => 1,
        }
    }

    /// How `frame`'s count relates to its stream's last one.
    fn continuity(&self, frame: &Downlink) -> Continuity {
        self.continuity_given(frame, self.state.provisional)
    }

    /// [`continuity`](Self::continuity), with `provisional` as the set of provisional counts.
    fn continuity_given(&self, frame: &Downlink, provisional: u8) -> Continuity {
        let state = &self.state;
        let (Some(seq), Kind::Telemetry(stream)) = (frame.seq(), frame.kind()) else {
            return Continuity::Reply;
        };
        let bit = 1u8 << stream.index();
        let last = state.last_seq.get(stream.index()).copied().unwrap_or(0);
        let step = seq.wrapping_sub(last);
        if state.seen & bit != 0 && step == 1 {
            return Continuity::Continues;
        }
        if usize::from(state.jump_stream) == stream.index() && seq.wrapping_sub(state.jump_seq) == 1
        {
            return Continuity::ContinuesJump;
        }
        if state.seen & bit == 0 {
            return Continuity::Unknown;
        }
        if provisional & bit != 0 {
            return Continuity::Provisional;
        }
        // Frames may have been lost in the bytes before this candidate.
        let before = usize::from(state.since_confirmed).saturating_sub(state.window.len());
        let i = stream.index();
        let per_frame = BYTES_PER_FRAME.get(i).copied().unwrap_or(u16::MAX).max(1);
        let widen = u16::try_from(before)
            .unwrap_or(u16::MAX)
            .checked_div(per_frame)
            .unwrap_or(0);
        let base = NEAR_STEPS.get(i).copied().unwrap_or(1);
        let mut near = u16::from(base).saturating_add(widen);
        if state.lock == Lock::Locked {
            near = near.max(u16::from(LOCKED_STEPS));
        }
        if step != 0 && u16::from(step) <= near {
            Continuity::Near
        } else {
            Continuity::Far
        }
    }

    /// While hunting, a provisional count still says where the stream was: whether `frame`'s
    /// count is near it, as if it were trusted.
    fn provisional_near(&self, frame: &Downlink) -> bool {
        matches!(
            self.continuity_given(frame, 0),
            Continuity::Continues | Continuity::Near
        )
    }

    /// Judges the candidate at the front of the window. `idle`: the line has gone quiet, so no
    /// more bytes are coming for now.
    fn judge(&self, idle: bool) -> Verdict {
        let state = &self.state;
        let buf = state.window.as_slice();
        let (first, second) = match buf {
            [] => return Verdict::NeedMore,
            [first] if Kind::may_start(*first) && !idle => return Verdict::NeedMore,
            [_] => return Verdict::Reject(None),
            [first, second, ..] => (*first, *second),
        };
        let Some(kind) = Kind::from_header(first, second) else {
            return Verdict::Reject(None);
        };
        let len = kind.len();
        let Some(bytes) = buf.get(..len) else {
            return if idle {
                Verdict::Reject(None)
            } else {
                Verdict::NeedMore
            };
        };
        let Ok(frame) = Downlink::decode(bytes) else {
            return Verdict::Reject(None);
        };
        let continuity = self.continuity(&frame);
        // A truncated reply would hold the next frame's start in its value bytes, and bytes
        // after its end; one that ends as the line goes quiet is whole.
        let quiet_fit = idle && buf.len() == len;
        let clean_reply = !holds_a_frame_start(bytes.get(2..).unwrap_or(&[])) || quiet_fit;
        let aligned = state.lock != Lock::Hunting;

        // On the frame's last byte, when the evidence is already there.
        let at_once = aligned
            && match continuity {
                Continuity::Continues => true,
                Continuity::Reply => clean_reply,
                _ => false,
            };
        if at_once {
            return Verdict::Accept(frame, len);
        }

        // Otherwise the next two bytes must be a header (or the line must be quiet)...
        let followed = match buf.get(len..) {
            Some([next, after, ..]) => Kind::from_header(*next, *after).is_some(),
            Some([next]) if !Kind::may_start(*next) => false,
            _ if idle => true,
            _ => return Verdict::NeedMore,
        };
        // ...and the count plausible for the state the parser is in.
        let plausible = match state.lock {
            Lock::Hunting => match continuity {
                Continuity::Continues | Continuity::Near => true,
                // Two false candidates can continue each other as well as two real frames:
                // while hunting, only the candidate that starts where the jump candidate ended
                // (its following header) is taken.
                Continuity::ContinuesJump => state.jump_ahead == 0,
                // A count learnt in a hunt may be false, but it is the best guess there is;
                // while no count is trusted at all (start-up), it is no evidence.
                Continuity::Provisional => {
                    state.seen & !state.provisional == 0 || self.provisional_near(&frame)
                }
                // Could be a frame's tail and the next frame's start: the driver asks again.
                Continuity::Reply => clean_reply,
                // A stream's first frame: proof enough only while no count is trusted yet, and
                // not for the battery: a false `FF FC` is as common as a false `FF FA` (at an
                // IMU frame's gyro X, -4, it even ends on the frame's last byte), and a real
                // battery frame a hundred times rarer than an IMU frame.
                Continuity::Unknown => {
                    state.seen & !state.provisional == 0
                        && frame.kind() != Kind::Telemetry(Stream::Battery)
                }
                Continuity::Far => false,
            },
            Lock::Tentative => match continuity {
                Continuity::Far => false,
                // Right after a frame that continued its count, or starting where the jump
                // candidate ended: on an alignment with nothing better to go by, a re-based
                // count is as likely a false one.
                Continuity::ContinuesJump => state.since_continued == 0 || state.jump_ahead == 0,
                _ => state.since_continued < PROBATION_FRAMES,
            },
            // On a confirmed alignment, a frame whose count says nothing (a stream's first
            // frame, a provisional count) or jumps is taken when the frame before was taken on
            // good evidence: then this boundary is certain (and a jump is most likely a damaged
            // count byte). After a frame taken on weak evidence, the boundary is in doubt.
            Lock::Locked => match continuity {
                Continuity::Unknown | Continuity::Provisional | Continuity::Far => {
                    !state.weak || quiet_fit
                }
                Continuity::Continues
                | Continuity::ContinuesJump
                | Continuity::Near
                | Continuity::Reply => true,
            },
        };
        match (followed, plausible) {
            (true, true) => Verdict::Accept(frame, len),
            // Whole and delimited, turned down for its count alone: if the next frame of its
            // stream continues this count, the count has moved on. Not for the battery: its
            // frames are a second apart, and a false `FF FC` at an IMU frame's gyro X (-4)
            // ends on that frame's count byte, so false batteries can continue each other.
            (true, false) => match (frame.seq(), frame.kind()) {
                (Some(seq), Kind::Telemetry(stream)) if stream != Stream::Battery => {
                    Verdict::Reject(Some((stream, seq)))
                }
                _ => Verdict::Reject(None),
            },
            (false, _) => Verdict::Reject(None),
        }
    }

    /// Drops the candidate's first byte and goes hunting; remembers `jump` (a stream and a count
    /// that may have moved on), if any.
    fn reject(&mut self, jump: Option<(Stream, u8)>) {
        let state = &mut self.state;
        state.window.drop_front(1);
        state.passed(1);
        if let Some((stream, seq)) = jump {
            state.jump_stream = u8::try_from(stream.index()).unwrap_or(NO_JUMP);
            state.jump_seq = seq;
            let rest = Kind::Telemetry(stream).len().saturating_sub(1);
            state.jump_ahead = u8::try_from(rest).unwrap_or(PASSED);
        }
        self.stats.discarded = self.stats.discarded.wrapping_add(1);
        if state.lock != Lock::Hunting {
            self.stats.lock_losses = self.stats.lock_losses.wrapping_add(1);
            state.lock = Lock::Hunting;
        }
    }

    /// Consumes an accepted frame: counts, count history, lock.
    fn accept(&mut self, frame: &Downlink, len: usize) {
        let continuity = self.continuity(frame);
        let state = &mut self.state;
        state.window.drop_front(len);
        state.passed(len);
        self.stats.count_frame(frame.kind());
        let confirms = continuity == Continuity::Continues;
        state.since_continued = match continuity {
            Continuity::Continues => 0,
            // A reply carries no count: it neither confirms an alignment nor counts against it.
            Continuity::Reply => state.since_continued,
            _ => state.since_continued.saturating_add(1),
        };
        state.weak = match continuity {
            _ if state.lock == Lock::Hunting => true,
            Continuity::Continues | Continuity::ContinuesJump | Continuity::Near => false,
            Continuity::Far => true,
            // A reply (taken with the next header as proof when its value holds one), a
            // stream's first frame, a provisional count: as good a boundary as the frame before.
            Continuity::Reply | Continuity::Unknown | Continuity::Provisional => state.weak,
        };
        match state.lock {
            Lock::Hunting => {
                self.stats.resyncs = self.stats.resyncs.wrapping_add(1);
                state.lock = Lock::Tentative;
                state.confirms = u8::from(confirms);
            }
            Lock::Tentative => state.confirms = state.confirms.saturating_add(u8::from(confirms)),
            Lock::Locked => {}
        }
        if state.lock == Lock::Tentative && state.confirms >= CONFIRMATIONS {
            state.lock = Lock::Locked;
        }
        if confirms && state.lock == Lock::Locked {
            // Only a confirmed alignment restarts the clock: until then, the bytes since the
            // last certain frame tell how many frames may have been lost.
            state.since_confirmed = u8::try_from(state.window.len()).unwrap_or(0);
        }
        if let (Some(seq), Kind::Telemetry(stream)) = (frame.seq(), frame.kind()) {
            if continuity == Continuity::ContinuesJump {
                // Two frames agree the count moved on: follow it.
                state.jump_stream = NO_JUMP;
            }
            if state.lock == Lock::Locked && continuity == Continuity::Far {
                record_jump(state, stream, seq);
            } else {
                // A count is trusted when it continues the last one (a false frame does that
                // about one time in 256), or when its frame sits on a confirmed alignment.
                let trusted = confirms || state.lock == Lock::Locked;
                record_seq(state, &mut self.stats, stream, seq, trusted);
            }
        }
    }
}

/// Whether `bytes` (a reply's value) hold a telemetry header, `FF FA`..`FF FC`: then the reply
/// may be a truncated one with the next frame's start in it. (A truncated reply whose last byte
/// is the next frame's `FF` is caught anyway: the two bytes after it, `FA`.., are no header.)
fn holds_a_frame_start(bytes: &[u8]) -> bool {
    bytes.windows(2).any(|w| matches!(w, [0xFF, 0xFA..=0xFC]))
}

/// A count jump on a confirmed alignment, right after a frame whose count continued: most likely
/// the count byte itself was damaged, so the stream's count moves on by one as if it had not
/// been. The jumped count is remembered: if the stream's next frame continues it, the board
/// really did move its count on (frames were lost, it restarted, or it paused its telemetry),
/// and the count follows it ([`Continuity::ContinuesJump`]).
fn record_jump(state: &mut State, stream: Stream, seq: u8) {
    let i = stream.index();
    let Some(last) = state.last_seq.get_mut(i) else {
        return;
    };
    *last = last.wrapping_add(1);
    state.jump_stream = u8::try_from(i).unwrap_or(NO_JUMP);
    state.jump_seq = seq;
    // Called once the frame is consumed: the window's front is right at its end.
    state.jump_ahead = 0;
}

/// Stores a stream's new count and counts the gap before it, if any.
fn record_seq(
    state: &mut State,
    stats: &mut DownlinkStats,
    stream: Stream,
    seq: u8,
    trusted: bool,
) {
    let i = stream.index();
    let bit = 1u8 << i;
    if let Some(last) = state.last_seq.get_mut(i) {
        if state.seen & bit != 0 {
            let step = seq.wrapping_sub(*last);
            if step != 1 {
                stats.count_gap(stream, step.wrapping_sub(1));
            }
        }
        *last = seq;
        state.seen |= bit;
        if trusted {
            state.provisional &= !bit;
        } else {
            state.provisional |= bit;
        }
    }
}

/// Iterator over the frames of a byte slice: see [`DownlinkParser::frames`].
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DownlinkFrames<'p, 'b> {
    parser: &'p mut DownlinkParser,
    rest: &'b [u8],
}

impl Iterator for DownlinkFrames<'_, '_> {
    type Item = Downlink;

    fn next(&mut self) -> Option<Downlink> {
        let (frame, rest) = self.parser.push_slice(self.rest);
        self.rest = rest;
        frame
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Battery, Encoders, Imu, Register, Reply};

    fn imu(seq: u8, gyro_z: i16) -> Imu {
        Imu {
            accel: [1, -2, 16_384],
            gyro: [-6, -5, gyro_z],
            seq,
        }
    }

    fn feed(parser: &mut DownlinkParser, bytes: &[u8]) -> Vec<Downlink> {
        bytes.iter().filter_map(|b| parser.push(*b)).collect()
    }

    #[test]
    fn state_size() {
        assert!(core::mem::size_of::<State>() <= 32);
        assert_eq!(core::mem::size_of::<State>(), 32);
        assert_eq!(core::mem::size_of::<DownlinkStats>(), 52);
    }

    #[test]
    fn locked_frames_come_out_on_their_last_byte() {
        let mut p = DownlinkParser::new();
        let a = imu(1, 0).encode();
        let b = imu(2, 0).encode();
        let c = imu(3, 0).encode();
        // The first frame proves itself by the following header.
        assert_eq!(feed(&mut p, &a), vec![]);
        assert_eq!(feed(&mut p, &b[..2]), vec![Downlink::Imu(imu(1, 0))]);
        assert_eq!(p.lock(), Lock::Tentative);
        // The second continues the count: out on its last byte, and the lock is confirmed.
        assert_eq!(feed(&mut p, &b[2..14]), vec![]);
        assert_eq!(p.push(b[14]), Some(Downlink::Imu(imu(2, 0))));
        assert_eq!(p.lock(), Lock::Tentative);
        assert_eq!(feed(&mut p, &c[..14]), vec![]);
        assert_eq!(p.push(c[14]), Some(Downlink::Imu(imu(3, 0))));
        // Two frames in a row have continued their counts: the lock is confirmed.
        assert_eq!(p.lock(), Lock::Locked);
        assert_eq!(p.buffered(), 0);
        assert_eq!(p.stats().discarded, 0);
    }

    #[test]
    fn a_reply_while_aligned_comes_out_at_once() {
        let mut p = DownlinkParser::new();
        for seq in 1..=3 {
            feed(&mut p, &imu(seq, 0).encode());
        }
        let reply = Reply::new(Register::MaxSpeed, 500);
        let out = feed(&mut p, &reply.encode());
        assert_eq!(out, vec![Downlink::Reply(reply)]);
        assert_eq!(p.lock(), Lock::Locked);
    }

    #[test]
    fn a_dropped_byte_loses_only_its_own_frame() {
        let mut p = DownlinkParser::new();
        let mut stream = Vec::new();
        for seq in 0..6u8 {
            stream.extend_from_slice(&imu(seq, -4).encode());
        }
        // Drop a payload byte of frame 3.
        stream.remove(3 * 15 + 5);
        let out: Vec<u8> = feed(&mut p, &stream)
            .into_iter()
            .chain(core::iter::from_fn(|| p.idle()))
            .filter_map(|f| f.seq())
            .collect();
        assert_eq!(out, vec![0, 1, 2, 4, 5]);
        assert_eq!(p.stats().gaps_of(Stream::Imu), 1);
        assert_eq!(p.stats().missed_of(Stream::Imu), 1);
    }

    #[test]
    fn a_count_that_moved_on_is_followed_after_two_frames_agree() {
        // Locked on IMU and encoder frames; then the IMU count moves on by 13 with no byte
        // missing (frames lost upstream), while the encoder count keeps confirming the
        // alignment. The first far IMU frame is taken as a damaged count byte, the second
        // continues it and re-bases the count: no frame is lost.
        let mut p = DownlinkParser::new();
        let mut stream = Vec::new();
        let mut enc = 0u8;
        for seq in (1..=8u8).chain(21..=40) {
            stream.extend_from_slice(&imu(seq, 3).encode());
            if seq % 4 == 0 {
                enc = enc.wrapping_add(1);
                let ticks = [1, 2, 3, i16::from(enc)];
                stream.extend_from_slice(&Encoders { ticks, seq: enc }.encode());
            }
        }
        let mut out = feed(&mut p, &stream);
        out.extend(core::iter::from_fn(|| p.idle()));
        let imu_counts: Vec<u8> = out
            .iter()
            .filter(|f| f.kind() == Kind::Telemetry(Stream::Imu))
            .filter_map(Downlink::seq)
            .collect();
        let expected: Vec<u8> = (1..=8u8).chain(21..=40).collect();
        assert_eq!(imu_counts, expected);
        assert_eq!(p.lock(), Lock::Locked);
        assert_eq!(p.stats().discarded, 0);
        assert_eq!(p.stats().missed_of(Stream::Imu), 12);
    }

    #[test]
    fn an_inserted_byte_loses_only_its_own_frame() {
        let mut p = DownlinkParser::new();
        let mut stream = Vec::new();
        for seq in 10..16u8 {
            stream.extend_from_slice(&imu(seq, -5).encode());
        }
        stream.insert(2 * 15 + 7, 0xFF);
        let mut out: Vec<u8> = feed(&mut p, &stream)
            .iter()
            .filter_map(Downlink::seq)
            .collect();
        out.extend(core::iter::from_fn(|| p.idle()).filter_map(|f| f.seq()));
        assert_eq!(out, vec![10, 11, 13, 14, 15]);
    }

    #[test]
    fn the_count_rejects_a_false_header_inside_a_payload() {
        // Start listening in the middle of an IMU frame whose gyro reads -6 (FF FA): the false
        // candidate at the FF FA must not swallow the real frame after it.
        let mut p = DownlinkParser::new();
        let first = imu(40, 0).encode();
        let mut stream = first[6..].to_vec();
        stream.extend_from_slice(
            &Encoders {
                ticks: [5, 6, 7, 8],
                seq: 9,
            }
            .encode(),
        );
        stream.extend_from_slice(&imu(41, 0).encode());
        stream.extend_from_slice(&imu(42, 0).encode());
        let out = feed(&mut p, &stream);
        assert_eq!(
            out.first().map(Downlink::kind),
            Some(Kind::Telemetry(Stream::Encoders))
        );
        assert_eq!(
            out.iter().filter_map(Downlink::seq).collect::<Vec<_>>(),
            vec![9, 41, 42]
        );
    }

    #[test]
    fn idle_completes_a_frame_and_drops_a_partial_one() {
        let mut p = DownlinkParser::new();
        let b = Battery {
            centivolts: 1_234,
            percent: 50,
            seq: 1,
        };
        // Hunting, a battery frame that only the quiet line delimits could be an IMU frame's
        // tail: dropped (all 7 bytes).
        assert_eq!(feed(&mut p, &b.encode()), vec![]);
        assert_eq!(p.idle(), None);
        assert_eq!(p.stats().discarded, 7);
        // After a quiet line it starts a frame: complete at the next quiet line, so taken.
        assert_eq!(feed(&mut p, &b.encode()), vec![]);
        assert_eq!(p.idle(), Some(Downlink::Battery(b)));
        assert_eq!(p.idle(), None);
        assert_eq!(feed(&mut p, &[0x23, 0x01, 0x00]), vec![]);
        assert_eq!(p.idle(), None);
        assert_eq!(p.stats().discarded, 10);
        assert_eq!(p.buffered(), 0);
        // After a quiet line the next byte is taken to start a frame: a reply comes out at once.
        assert_eq!(p.lock(), Lock::Tentative);
        let reply = Reply::new(Register::PendingAngle, 0);
        assert_eq!(feed(&mut p, &reply.encode()), vec![Downlink::Reply(reply)]);
    }

    #[test]
    fn forgets_counts_after_a_long_hunt() {
        let mut p = DownlinkParser::new();
        feed(&mut p, &imu(1, 0).encode());
        feed(&mut p, &imu(2, 0).encode());
        // The board restarts its counts (far from 2) after a long stretch of noise.
        let noise = [0x00u8; 600];
        feed(&mut p, &noise);
        let mut stream = imu(200, 0).encode().to_vec();
        stream.extend_from_slice(&imu(201, 0).encode());
        let out = feed(&mut p, &stream);
        assert_eq!(
            out.iter().filter_map(Downlink::seq).collect::<Vec<_>>(),
            vec![200, 201]
        );
    }

    #[test]
    fn never_stuck_on_any_single_byte_value() {
        for value in 0..=255u8 {
            let mut p = DownlinkParser::new();
            for _ in 0..100 {
                p.push(value);
            }
            assert!(p.buffered() <= WINDOW);
            let mut stream = Vec::new();
            for seq in 0..3u8 {
                stream.extend_from_slice(&imu(seq, 0).encode());
            }
            let out = feed(&mut p, &stream);
            assert!(
                out.iter().filter_map(Downlink::seq).any(|s| s == 1),
                "stuck after {value:#04x}"
            );
        }
    }
}
