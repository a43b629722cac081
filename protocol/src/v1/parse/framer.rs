//! The rules both v1.0.0 parsers follow, and their two ways in: a byte at a time into the
//! bytes held ([`Framer::push`]), and straight from the caller's slice ([`Framer::take_frame`]).
//!
//! The rules: a frame starts with `7B`; its code (byte 1) gives its length; once that many bytes
//! are there it is judged: its last byte `7D`, then its BCC, then whether its content is a frame
//! of this direction. A frame taken leaves the bytes after it; a candidate that is not one drops
//! its `7B` (counted as discarded) and the next `7B` after it is tried, so a frame that began
//! inside a damaged one is never lost. A byte that cannot start a frame is discarded at once.
//! Whichever way the bytes come in, and however they are cut, the same rules see the same bytes:
//! the frames and the counters are the same.
//!
//! Byte by byte, the bytes of a frame begun are only stored (a length compared, a byte written)
//! until its last byte, when it is checked a machine word at a time; only a candidate that
//! fails, which is rare, looks through the bytes held again. Over a slice, a frame whole in the slice is checked and decoded
//! where it lies, without a copy; only the start of a frame cut by the slice's end is held, and
//! completed from the next slice.

use super::Stats;
use crate::v1::{END, START, bcc};

/// What a framer needs of its direction.
pub(super) trait Direction {
    /// What it finds.
    type Frame;

    /// The length on the wire of a frame whose code is `code` (at least 3), if the direction has
    /// such a code.
    fn len_of(code: u8) -> Option<usize>;

    /// Whether `bytes`, a candidate of its code's length whose start, end and BCC are right, is
    /// a frame of this direction (if not, it is counted as refused).
    fn accepts(bytes: &[u8]) -> bool;

    /// The frame of `bytes`, which [`accepts`](Self::accepts) takes.
    fn decode(bytes: &[u8]) -> Option<Self::Frame>;
}

/// Adds `n` to a counter, saturating.
fn add(counter: &mut u32, n: usize) {
    *counter = counter.saturating_add(u32::try_from(n).unwrap_or(u32::MAX));
}

/// The four bytes of `bytes` at `at` as a word (0 past the end).
#[inline(always)]
fn word(bytes: &[u8], at: usize) -> u32 {
    match bytes.get(at..at.saturating_add(4)) {
        Some(&[a, b, c, d]) => u32::from_ne_bytes([a, b, c, d]),
        _ => 0,
    }
}

/// The XOR of the four bytes of `word`.
#[inline(always)]
fn fold(word: u32) -> u8 {
    let [a, b, c, d] = word.to_ne_bytes();
    a ^ b ^ c ^ d
}

/// The XOR of every byte of a candidate: a word at a time, written out for the two lengths
/// frames have (a loop would stay a loop in firmware built for size).
#[inline]
fn xor_frame(frame: &[u8]) -> u8 {
    match frame.len() {
        32 => fold(
            word(frame, 0)
                ^ word(frame, 4)
                ^ word(frame, 8)
                ^ word(frame, 12)
                ^ word(frame, 16)
                ^ word(frame, 20)
                ^ word(frame, 24)
                ^ word(frame, 28),
        ),
        14 => {
            let tail = frame.get(12..).map_or(0, bcc);
            fold(word(frame, 0) ^ word(frame, 4) ^ word(frame, 8)) ^ tail
        }
        _ => bcc(frame),
    }
}

/// Judges a whole candidate (`7B`, then as many bytes as its code says) and counts the
/// verdict: whether it is a frame (then [`Direction::decode`] gives it). Out of line: both ways
/// in share it.
#[inline(never)]
fn judge<D: Direction>(stats: &mut Stats, frame: &[u8]) -> bool {
    // The BCC is the XOR of the bytes before it: with the 7D after it, all XOR to 7D.
    let counter = if frame.last() != Some(&END) {
        &mut stats.bad_end
    } else if xor_frame(frame) != END {
        &mut stats.bad_checksum
    } else if D::accepts(frame) {
        add(&mut stats.frames, 1);
        return true;
    } else {
        &mut stats.refused
    };
    add(counter, 1);
    false
}

/// What [`Framer::take_frame`] found, before the frame is decoded (decoded in one place, into
/// the caller's frame: no copy of it on the way out).
enum Step<'a> {
    /// A frame where it lies in the caller's slice.
    InSlice(&'a [u8]),
    /// A frame of this length at the front of the bytes held.
    Held(usize),
    /// Every byte taken, no frame.
    Nothing,
}

/// Where the rules stopped in a run of bytes.
enum Scan {
    /// A frame taken: where it starts, and the offset just past it.
    Frame(usize, usize),
    /// No frame: the bytes from this offset on (if any) are the start of one, to be held.
    Rest(usize),
}

/// The rules over `bytes`, with nothing held before them: the first frame taken, or where the
/// start of a frame not yet whole begins. What comes before either is counted in `stats`.
fn scan<D: Direction, const N: usize>(stats: &mut Stats, bytes: &[u8]) -> Scan {
    let mut at = 0usize;
    loop {
        let rest = bytes.get(at..).unwrap_or(&[]);
        let Some(skip) = rest.iter().position(|b| *b == START) else {
            add(&mut stats.discarded, rest.len());
            return Scan::Rest(bytes.len());
        };
        add(&mut stats.discarded, skip);
        at = at.wrapping_add(skip);
        let candidate = rest.get(skip..).unwrap_or(&[]);
        let Some(&code) = candidate.get(1) else {
            return Scan::Rest(at);
        };
        if let Some(need) = D::len_of(code).filter(|n| *n <= N) {
            let Some(frame) = candidate.get(..need) else {
                return Scan::Rest(at);
            };
            if judge::<D>(stats, frame) {
                return Scan::Frame(at, at.wrapping_add(need));
            }
        }
        // Not a frame: one may begin at the next 7B.
        add(&mut stats.discarded, 1);
        at = at.wrapping_add(1);
    }
}

/// The bytes of at most one frame, and the rules to find one.
///
/// Held bytes are *settled* when the rules have seen them: then they are nothing, or a lone
/// `7B`, or the start of a candidate of `last + 1` bytes (more than are held).
/// They are not after a frame taken from among them (a frame found inside a damaged one): the
/// bytes after it are looked at by the next call, as when they come.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Framer<const N: usize> {
    buf: [u8; N],
    len: usize,
    /// The offset of the candidate's last byte once its code is held (settled); 0 otherwise.
    last: usize,
    settled: bool,
    stats: Stats,
}

impl<const N: usize> Framer<N> {
    /// The offsets in the buffer, as a mask, when N is a power of two (the board → master
    /// parser's 32): then an offset masked is one the compiler knows to be in the buffer.
    const MASK: usize = N.next_power_of_two().wrapping_sub(1);

    /// Holding nothing, having seen nothing.
    pub(super) const fn new() -> Self {
        Framer {
            buf: [0; N],
            len: 0,
            last: 0,
            settled: true,
            stats: Stats {
                frames: 0,
                bad_checksum: 0,
                bad_end: 0,
                refused: 0,
                discarded: 0,
            },
        }
    }

    /// What it has seen.
    pub(super) const fn stats(&self) -> Stats {
        self.stats
    }

    /// Bytes held.
    pub(super) const fn len(&self) -> usize {
        self.len
    }

    /// Takes one byte; the frame it completes, or one found among the bytes held.
    #[inline]
    pub(super) fn push<D: Direction>(&mut self, byte: u8) -> Option<D::Frame> {
        let len = self.len;
        // Inside a frame begun, before its last byte: the common case.
        if len < self.last {
            // `len & MASK` is `len` (`last` < N): no bounds check left when N is a power of two.
            if let Some(slot) = self.buf.get_mut(len & Self::MASK) {
                *slot = byte;
                self.len = len.wrapping_add(1);
            }
            return None;
        }
        self.push_rest::<D>(byte)
    }

    /// The rest of [`push`](Self::push): a byte with nothing held, a code byte, a candidate's
    /// last byte, or a byte after bytes not yet settled. Out of line, so that what `push`
    /// inlines into a caller's loop is only the common case.
    #[inline(never)]
    fn push_rest<D: Direction>(&mut self, byte: u8) -> Option<D::Frame> {
        let need = if self.len == 0 {
            self.start(byte);
            None
        } else if !self.settled {
            self.append(byte);
            self.settle::<D>(0)
        } else if self.len == 1 {
            self.code::<D>(byte);
            None
        } else {
            self.append(byte);
            self.judge_held::<D>()
        }?;
        self.decode_held::<D>(need)
    }

    /// A frame among the bytes held, if they are not settled.
    pub(super) fn poll<D: Direction>(&mut self) -> Option<D::Frame> {
        if self.settled {
            return None;
        }
        let need = self.settle::<D>(0)?;
        self.decode_held::<D>(need)
    }

    /// The line was quiet: nothing that comes next completes what is held (a frame's bytes
    /// come back to back). A frame whole among the bytes held comes out (call again until
    /// `None`); the start of a frame cut short is thrown away a byte at a time, counted, so that
    /// a frame that began inside it is still found. At `None` nothing is held.
    pub(super) fn quiet<D: Direction>(&mut self) -> Option<D::Frame> {
        loop {
            if let Some(frame) = self.poll::<D>() {
                return Some(frame);
            }
            // Settled: nothing, or the start of a candidate that will never be whole.
            if self.len == 0 {
                return None;
            }
            // Its 7B goes; a frame may begin after it.
            add(&mut self.stats.discarded, 1);
            if let Some(need) = self.settle::<D>(1) {
                if let Some(frame) = self.decode_held::<D>(need) {
                    return Some(frame);
                }
            }
        }
    }

    /// Takes bytes from the front of `bytes` until a frame comes out (a frame whole in them is
    /// checked and decoded where it lies); `bytes` keeps the rest. `None`: every byte taken.
    #[inline]
    pub(super) fn take_frame<D: Direction>(&mut self, bytes: &mut &[u8]) -> Option<D::Frame> {
        match self.step::<D>(bytes) {
            Step::InSlice(frame) => D::decode(frame),
            Step::Held(need) => self.decode_held::<D>(need),
            Step::Nothing => None,
        }
    }

    /// The work of [`take_frame`](Self::take_frame): what is held first (settled, then
    /// completed from the front of `bytes`), then straight from the slice.
    fn step<'a, D: Direction>(&mut self, bytes: &mut &'a [u8]) -> Step<'a> {
        loop {
            if !self.settled {
                if let Some(need) = self.settle::<D>(0) {
                    return Step::Held(need);
                }
            }
            if self.len == 0 {
                break;
            }
            if self.last == 0 {
                // A lone 7B: the next byte is its code.
                let Some((&byte, rest)) = bytes.split_first() else {
                    return Step::Nothing;
                };
                *bytes = rest;
                self.code::<D>(byte);
                continue;
            }
            let wanted = self.last.saturating_add(1).saturating_sub(self.len);
            let Some((part, rest)) = bytes.split_at_checked(wanted) else {
                // Not enough to complete it.
                self.extend(bytes);
                *bytes = &[];
                return Step::Nothing;
            };
            *bytes = rest;
            self.extend(part);
            if let Some(need) = self.judge_held::<D>() {
                return Step::Held(need);
            }
        }
        match scan::<D, N>(&mut self.stats, bytes) {
            Scan::Frame(start, end) => {
                let frame = bytes.get(start..end).unwrap_or(&[]);
                *bytes = bytes.get(end..).unwrap_or(&[]);
                Step::InSlice(frame)
            }
            Scan::Rest(at) => {
                let rest = bytes.get(at..).unwrap_or(&[]);
                self.extend(rest);
                self.settle_on::<D>(rest.get(1).copied());
                *bytes = &[];
                Step::Nothing
            }
        }
    }

    /// The frame of `need` bytes at the front of the bytes held, taken: the bytes after it, if
    /// any, stay held, not yet settled. Out of line: every way out of the bytes held ends here.
    #[inline(never)]
    fn decode_held<D: Direction>(&mut self, need: usize) -> Option<D::Frame> {
        let found = D::decode(self.buf.get(..need).unwrap_or(&[]));
        if need < self.len {
            self.keep_from(need);
            self.settled = false;
        } else {
            self.len = 0;
            self.settled = true;
        }
        self.last = 0;
        found
    }

    /// Nothing held (a byte may follow).
    fn start(&mut self, byte: u8) {
        if byte == START {
            if let Some(slot) = self.buf.first_mut() {
                *slot = START;
                self.len = 1;
            }
        } else {
            add(&mut self.stats.discarded, 1);
        }
    }

    /// A lone `7B` held: `byte` is its code.
    #[inline]
    fn code<D: Direction>(&mut self, byte: u8) {
        if let Some(need) = D::len_of(byte).filter(|n| *n <= N) {
            self.append(byte);
            self.last = need.saturating_sub(1);
        } else {
            // The 7B starts no frame of this direction; the byte may start one.
            add(&mut self.stats.discarded, 1);
            self.clear();
            self.start(byte);
        }
    }

    /// Judges the candidate held, whole: the frame (its length; it is at the front), or one
    /// found among its bytes after its 7B.
    #[inline]
    fn judge_held<D: Direction>(&mut self) -> Option<usize> {
        let need = self.last.wrapping_add(1);
        if judge::<D>(&mut self.stats, self.buf.get(..need).unwrap_or(&[])) {
            return Some(need);
        }
        add(&mut self.stats.discarded, 1);
        self.settle::<D>(1)
    }

    /// The rules over the bytes held from `from` on: a frame found among them, moved to the
    /// front (its length; to be taken by [`decode_held`](Self::decode_held)), or none (what is
    /// held then is settled).
    fn settle<D: Direction>(&mut self, from: usize) -> Option<usize> {
        let held = self.buf.get(from..self.len).unwrap_or(&[]);
        match scan::<D, N>(&mut self.stats, held) {
            Scan::Frame(start, end) => {
                self.keep_from(from.wrapping_add(start));
                Some(end.wrapping_sub(start))
            }
            Scan::Rest(at) => {
                self.keep_from(from.wrapping_add(at));
                self.settle_held::<D>();
                None
            }
        }
    }

    /// The bytes held are a lone `7B` or a candidate not yet whole, or nothing: where its
    /// last byte will be.
    fn settle_held<D: Direction>(&mut self) {
        let code = self
            .buf
            .get(..self.len)
            .and_then(|held| held.get(1))
            .copied();
        self.settle_on::<D>(code);
    }

    /// As [`settle_held`](Self::settle_held), with the code held (if any) as `code`.
    fn settle_on<D: Direction>(&mut self, code: Option<u8>) {
        self.last = code
            .and_then(D::len_of)
            .map_or(0, |need| need.saturating_sub(1));
        self.settled = true;
    }

    /// Forgets the bytes held before `from`: the rest moved to the front, a byte at a time (a
    /// rare path, reached from several, so out of line; `copy_within` would link a `memmove`
    /// of 1.5 KiB into a firmware that had none).
    #[inline(never)]
    fn keep_from(&mut self, from: usize) {
        let len = self.len.min(N);
        let from = from.min(len);
        for (to, at) in (from..len).enumerate() {
            if let Some(byte) = self.buf.get(at).copied() {
                if let Some(slot) = self.buf.get_mut(to) {
                    *slot = byte;
                }
            }
        }
        self.len = len.wrapping_sub(from);
    }

    /// Holds one byte more. Room is always left: a candidate is judged once whole, and what
    /// a frame taken from among the bytes held leaves is shorter than a frame. (Were it not,
    /// the byte would be counted as discarded.)
    fn append(&mut self, byte: u8) {
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = byte;
            self.len = self.len.wrapping_add(1);
        } else {
            add(&mut self.stats.discarded, 1);
        }
    }

    /// Holds `bytes` after the bytes held (at most the room left: a candidate's missing bytes,
    /// or the start of one, always fit).
    fn extend(&mut self, bytes: &[u8]) {
        let len = self.len.min(N);
        let n = bytes.len().min(N.wrapping_sub(len));
        // Both of length `n`: the copy cannot fail.
        if let (Some(room), Some(part)) =
            (self.buf.get_mut(len..len.wrapping_add(n)), bytes.get(..n))
        {
            room.copy_from_slice(part);
            self.len = len.wrapping_add(n);
        }
    }

    /// Holds nothing.
    fn clear(&mut self) {
        self.len = 0;
        self.last = 0;
        self.settled = true;
    }
}
