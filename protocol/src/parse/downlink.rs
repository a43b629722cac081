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
//!              frame accepted                       count continues
//!   Hunting ───────────────────────► Tentative ─────────────────────► Locked
//!      ▲   (header + what follows +      │    (the next frame's count      │
//!      │    a plausible count)           │     follows its stream)         │
//!      │                                 │                                 │
//!      └──────────── candidate rejected: drop its first byte, rescan ◄─────┘
//! ```
//!
//! * **Hunting**: alignment unknown. A candidate frame is accepted when the next two bytes are a
//!   header *and* its count is plausible: within a few steps after the last count of its stream
//!   (the window widens with the bytes thrown away since the last frame, about one step per
//!   15 bytes, since that many frames may have been lost), or it is a reply, or no stream has a
//!   count yet (start-up). After [`FORGET_AFTER`] bytes thrown away without a frame the parser
//!   forgets the counts (the board may have restarted), so it can never stay stuck.
//! * **Tentative** and **Locked**: aligned: a frame is expected to start right here. A frame
//!   whose count follows its stream, or a reply, is emitted **on its last byte** (no added
//!   latency) and confirms the lock. Any other complete frame waits for the next two bytes to
//!   prove to be a header; then a small count gap (frames lost upstream, a corrupted count byte)
//!   or a stream's first frame is accepted in both states, but a count *jump* only while
//!   Locked, and it demotes the lock to Tentative. A Tentative lock rests on a hunt's evidence
//!   alone: a jump there means the alignment is false (a gyro at rest repeats `FF FA` at the
//!   same place in every IMU frame, so a false alignment can look periodic), and the parser
//!   goes hunting. [`DownlinkParser::lock`] tells the states apart, for callers that want to
//!   trust only confirmed data.
//! * A rejected candidate — bad header where one was expected, bad following header, implausible
//!   count while hunting — costs exactly **one** byte: its first. Scanning starts again at the
//!   byte after it, over the bytes already in the window, so a real frame that a false
//!   candidate overlapped is still found. Nothing is thrown away a frame at a time.
//!
//! # The trade-off chosen
//!
//! Latency is spent only where evidence is missing: while aligned and counts follow, every
//! frame comes out on its last byte. While hunting, a frame comes out two bytes late (when the
//! next header arrives) and needs a plausible count, which is what keeps false frames rare: the
//! false candidates that damaged frames are full of must pass a 16-bit header, a count check of
//! a few in 256, and a following header. A reply at the very end of a burst while hunting waits
//! for the next byte or for [`DownlinkParser::idle`]. The measured figures (recall and false
//! frames per million against noise) are produced by the noise sweep in `chassis-host-tests`.
//!
//! # Memory and time
//!
//! The parsing state is 26 bytes (asserted at compile time to stay at most 32); the counters are
//! a separate [`DownlinkStats`] (68 bytes). Each byte costs a header check and, on a frame's last
//! byte, a decode of at most 15 bytes and a shift of the window of at most 17 bytes. Nothing
//! allocates.
//!
//! # Panics
//!
//! Never, on any input: no indexing, no unchecked arithmetic on any path that bytes reach.

use super::stats::DownlinkStats;
use super::window::Window;
use crate::telemetry::{self, Kind, Stream, Telemetry};

/// Bytes kept: the longest frame and the two bytes after it.
const WINDOW: usize = telemetry::MAX_LEN + 2;

/// While hunting, a count may follow its stream's last count by 1 up to this many steps, plus
/// one step for every [`BYTES_PER_LOST_FRAME`] bytes thrown away since the last frame.
pub const NEAR_STEPS: u8 = 2;

/// How many bytes thrown away widen the plausible count window by one step (the longest frame).
pub const BYTES_PER_LOST_FRAME: u16 = telemetry::MAX_LEN as u16;

/// After this many bytes thrown away without a frame, the counts are forgotten.
pub const FORGET_AFTER: u16 = 512;

/// How sure the parser is of where frames start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Lock {
    /// Alignment unknown: scanning for a frame.
    Hunting,
    /// Aligned by a hunt, not yet confirmed by a frame whose count follows its stream.
    Tentative,
    /// Aligned and confirmed by a count.
    Locked,
}

/// The parsing state proper, counters excluded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct State {
    /// Bytes from the first byte of the candidate being judged.
    window: Window<WINDOW>,
    lock: Lock,
    /// Bit `i` set: `last_seq[i]` holds the last count of stream `i`.
    seen: u8,
    /// The last count of each stream (IMU, encoders, battery).
    last_seq: [u8; 3],
    /// Bytes thrown away since the last frame emitted (saturating).
    skipped: u16,
    /// The last `poll` emitted a frame: another may be ready without a new byte.
    drain: bool,
}

const _: () = assert!(
    core::mem::size_of::<State>() <= 32,
    "downlink state over 32 bytes"
);

/// What the bytes in the window say about the candidate at its front.
enum Verdict {
    /// Not enough bytes to decide.
    NeedMore,
    /// The first byte starts no frame: drop it.
    Reject,
    /// A frame of this length.
    Accept(Telemetry, usize),
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
    /// A few counts on (see [`NEAR_STEPS`]).
    Near,
    /// Anything else.
    Far,
}

/// The board → master streaming parser. See the [module docs](self) for how it resynchronises.
///
/// ```
/// use chassis_protocol::{Battery, DownlinkParser, Telemetry};
///
/// let mut parser = DownlinkParser::new();
/// // Noise, then a battery frame split across two reads.
/// let reads: [&[u8]; 2] = [&[0x00, 0xFF, 0xFC, 0x04], &[0x4C, 0x00, 0x57, 0x03]];
/// let mut frames = 0;
/// for read in reads {
///     for frame in parser.frames(read) {
///         assert_eq!(frame, Telemetry::Battery(Battery { centivolts: 1_100, percent: 87, seq: 3 }));
///         frames += 1;
///     }
/// }
/// // Hunting: the frame waits for proof that it is one (the next header, or a quiet line).
/// assert_eq!(frames, 0);
/// assert!(parser.idle().is_some());
/// assert_eq!(parser.stats().discarded, 1);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
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
                last_seq: [0; 3],
                skipped: 0,
                drain: false,
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
    pub fn push(&mut self, byte: u8) -> Option<Telemetry> {
        let ready = if self.state.drain { self.poll() } else { None };
        self.append(&[byte]);
        match ready {
            Some(frame) => Some(frame),
            None => self.poll(),
        }
    }

    /// Feeds bytes until a frame comes out; returns it and the bytes not yet consumed. Call
    /// again with the rest until it returns `(None, [])`. Emits exactly the frames that feeding
    /// the same bytes one at a time through [`push`](DownlinkParser::push) would, in the same
    /// order, and copies a frame's body in one step where it can.
    pub fn push_slice<'a>(&mut self, mut bytes: &'a [u8]) -> (Option<Telemetry>, &'a [u8]) {
        if self.state.drain {
            if let Some(frame) = self.poll() {
                return (Some(frame), bytes);
            }
        }
        while !bytes.is_empty() {
            let step = self.bytes_before_decision().clamp(1, bytes.len());
            let (now, rest) = bytes.split_at_checked(step).unwrap_or((bytes, &[]));
            self.append(now);
            bytes = rest;
            if let Some(frame) = self.poll() {
                return (Some(frame), bytes);
            }
        }
        (None, bytes)
    }

    /// An iterator over the frames in `bytes`; every byte is consumed by the time it ends.
    pub fn frames<'p, 'b>(&'p mut self, bytes: &'b [u8]) -> Frames<'p, 'b> {
        Frames {
            parser: self,
            rest: bytes,
        }
    }

    /// Emits a frame that is already complete in the window, if any, without a new byte.
    pub fn poll(&mut self) -> Option<Telemetry> {
        loop {
            match self.judge(false) {
                Verdict::NeedMore => {
                    self.state.drain = false;
                    return None;
                }
                Verdict::Reject => self.reject(),
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
    /// frame boundary); an incomplete one is thrown away. With the window empty, the next byte
    /// is taken to start a frame (the parser becomes at least *Tentative*). UART peripherals
    /// with an idle-line interrupt make this free; without one, call it from a timeout.
    pub fn idle(&mut self) -> Option<Telemetry> {
        loop {
            match self.judge(true) {
                Verdict::NeedMore => {
                    self.state.drain = false;
                    if self.state.lock == Lock::Hunting {
                        self.state.lock = Lock::Tentative;
                    }
                    return None;
                }
                Verdict::Reject => self.reject(),
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
                self.reject();
            }
            let taken = self.state.window.extend(bytes);
            bytes = bytes.get(taken..).unwrap_or(&[]);
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
    fn continuity(&self, frame: &Telemetry) -> Continuity {
        let (Some(seq), Kind::Telemetry(stream)) = (frame.seq(), frame.kind()) else {
            return Continuity::Reply;
        };
        let i = stream.index();
        if self.state.seen & (1 << i) == 0 {
            return Continuity::Unknown;
        }
        let last = self.state.last_seq.get(i).copied().unwrap_or(0);
        let step = seq.wrapping_sub(last);
        let widen = self.state.skipped / BYTES_PER_LOST_FRAME;
        let near = u16::from(NEAR_STEPS).saturating_add(widen);
        match step {
            1 => Continuity::Continues,
            0 => Continuity::Far,
            s if u16::from(s) <= near => Continuity::Near,
            _ => Continuity::Far,
        }
    }

    /// Judges the candidate at the front of the window. `idle`: the line has gone quiet, so no
    /// more bytes are coming for now.
    fn judge(&self, idle: bool) -> Verdict {
        let buf = self.state.window.as_slice();
        let (first, second) = match buf {
            [] => return Verdict::NeedMore,
            [first] if Kind::may_start(*first) && !idle => return Verdict::NeedMore,
            [_] => return Verdict::Reject,
            [first, second, ..] => (*first, *second),
        };
        let Some(kind) = Kind::from_header(first, second) else {
            return Verdict::Reject;
        };
        let len = kind.len();
        let Some(bytes) = buf.get(..len) else {
            return if idle {
                Verdict::Reject
            } else {
                Verdict::NeedMore
            };
        };
        let Ok(frame) = Telemetry::decode(bytes) else {
            return Verdict::Reject;
        };
        let continuity = self.continuity(&frame);
        let aligned = self.state.lock != Lock::Hunting;
        if aligned && matches!(continuity, Continuity::Continues | Continuity::Reply) {
            return Verdict::Accept(frame, len);
        }
        let followed = match buf.get(len..) {
            Some([next, after, ..]) => Kind::from_header(*next, *after).is_some(),
            Some([next]) if !Kind::may_start(*next) => false,
            _ if idle => true,
            _ => return Verdict::NeedMore,
        };
        let plausible = match continuity {
            Continuity::Reply | Continuity::Continues | Continuity::Near => true,
            // A stream's first frame: proof enough while aligned, or when nothing is known yet.
            Continuity::Unknown => aligned || self.state.seen == 0,
            // Only a confirmed lock takes a count jump (telemetry paused, frames lost upstream).
            Continuity::Far => self.state.lock == Lock::Locked,
        };
        if followed && plausible {
            Verdict::Accept(frame, len)
        } else {
            Verdict::Reject
        }
    }

    /// Drops the candidate's first byte and goes hunting.
    fn reject(&mut self) {
        let state = &mut self.state;
        state.window.drop_front(1);
        self.stats.discarded = self.stats.discarded.wrapping_add(1);
        state.skipped = state.skipped.saturating_add(1);
        if state.skipped >= FORGET_AFTER {
            state.seen = 0;
        }
        if state.lock != Lock::Hunting {
            self.stats.lock_losses = self.stats.lock_losses.wrapping_add(1);
            state.lock = Lock::Hunting;
        }
    }

    /// Consumes an accepted frame: counts, count history, lock.
    fn accept(&mut self, frame: &Telemetry, len: usize) {
        let continuity = self.continuity(frame);
        let state = &mut self.state;
        state.window.drop_front(len);
        state.skipped = 0;
        self.stats.count_frame(frame.kind());
        if let (Some(seq), Kind::Telemetry(stream)) = (frame.seq(), frame.kind()) {
            record_seq(state, &mut self.stats, stream, seq);
        }
        state.lock = match (state.lock, continuity) {
            (Lock::Hunting, _) => {
                self.stats.resyncs = self.stats.resyncs.wrapping_add(1);
                Lock::Tentative
            }
            (_, Continuity::Continues) => Lock::Locked,
            // A count jump is taken on the next frame's header alone: no longer confirmed.
            (_, Continuity::Far) => Lock::Tentative,
            (lock, _) => lock,
        };
    }
}

/// Stores a stream's new count and counts the gap before it, if any.
fn record_seq(state: &mut State, stats: &mut DownlinkStats, stream: Stream, seq: u8) {
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
    }
}

/// Iterator over the frames of a byte slice: see [`DownlinkParser::frames`].
#[derive(Debug)]
pub struct Frames<'p, 'b> {
    parser: &'p mut DownlinkParser,
    rest: &'b [u8],
}

impl Iterator for Frames<'_, '_> {
    type Item = Telemetry;

    fn next(&mut self) -> Option<Telemetry> {
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

    fn feed(parser: &mut DownlinkParser, bytes: &[u8]) -> Vec<Telemetry> {
        bytes.iter().filter_map(|b| parser.push(*b)).collect()
    }

    #[test]
    fn state_size() {
        assert!(core::mem::size_of::<State>() <= 32);
        assert_eq!(core::mem::size_of::<State>(), 26);
    }

    #[test]
    fn locked_frames_come_out_on_their_last_byte() {
        let mut p = DownlinkParser::new();
        let a = imu(1, 0).encode();
        let b = imu(2, 0).encode();
        let c = imu(3, 0).encode();
        // The first frame proves itself by the following header.
        assert_eq!(feed(&mut p, &a), vec![]);
        assert_eq!(feed(&mut p, &b[..2]), vec![Telemetry::Imu(imu(1, 0))]);
        assert_eq!(p.lock(), Lock::Tentative);
        // The second continues the count: out on its last byte, and the lock is confirmed.
        assert_eq!(feed(&mut p, &b[2..14]), vec![]);
        assert_eq!(p.push(b[14]), Some(Telemetry::Imu(imu(2, 0))));
        assert_eq!(p.lock(), Lock::Locked);
        assert_eq!(feed(&mut p, &c[..14]), vec![]);
        assert_eq!(p.push(c[14]), Some(Telemetry::Imu(imu(3, 0))));
        assert_eq!(p.buffered(), 0);
        assert_eq!(p.stats().discarded, 0);
    }

    #[test]
    fn a_reply_while_aligned_comes_out_at_once() {
        let mut p = DownlinkParser::new();
        feed(&mut p, &imu(1, 0).encode());
        feed(&mut p, &imu(2, 0).encode());
        let reply = Reply::new(Register::MaxSpeed, 500);
        let out = feed(&mut p, &reply.encode());
        assert_eq!(out, vec![Telemetry::Reply(reply)]);
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
    fn an_inserted_byte_loses_only_its_own_frame() {
        let mut p = DownlinkParser::new();
        let mut stream = Vec::new();
        for seq in 10..16u8 {
            stream.extend_from_slice(&imu(seq, -5).encode());
        }
        stream.insert(2 * 15 + 7, 0xFF);
        let mut out: Vec<u8> = feed(&mut p, &stream)
            .iter()
            .filter_map(Telemetry::seq)
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
            out.first().map(Telemetry::kind),
            Some(Kind::Telemetry(Stream::Encoders))
        );
        assert_eq!(
            out.iter().filter_map(Telemetry::seq).collect::<Vec<_>>(),
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
        assert_eq!(feed(&mut p, &b.encode()), vec![]);
        assert_eq!(p.idle(), Some(Telemetry::Battery(b)));
        assert_eq!(p.idle(), None);
        assert_eq!(feed(&mut p, &[0x23, 0x01, 0x00]), vec![]);
        assert_eq!(p.idle(), None);
        assert_eq!(p.stats().discarded, 3);
        assert_eq!(p.buffered(), 0);
        // After a quiet line the next byte is taken to start a frame: a reply comes out at once.
        assert_eq!(p.lock(), Lock::Tentative);
        let reply = Reply::new(Register::PendingAngle, 0);
        assert_eq!(feed(&mut p, &reply.encode()), vec![Telemetry::Reply(reply)]);
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
            out.iter().filter_map(Telemetry::seq).collect::<Vec<_>>(),
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
                out.iter().filter_map(Telemetry::seq).any(|s| s == 1),
                "stuck after {value:#04x}"
            );
        }
    }
}
