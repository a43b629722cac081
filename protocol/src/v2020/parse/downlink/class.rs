//! The facts about a candidate ([`Facts`]): its count against the line's, and the suspicions a
//! frame can raise (inside a frame rejected on a boundary, a header for its count byte, a frame
//! nested in it, in a reply's value); and where it starts ([`Start`]). Nothing here decides.

use super::counts::{FIRST_STEP_MAX, Rel};
use super::rules::{Facts, Seen, Start};
use super::{DownlinkParser, Lock};
use crate::telemetry::{self, Downlink, Kind, Stream};

impl DownlinkParser {
    /// The facts about the candidate `frame` at the front of the window that the table
    /// ([`rules::decide`](super::rules::decide)) reads. The suspicions only hunting reads are
    /// looked for only while hunting.
    pub(super) fn facts(&self, frame: &Downlink) -> Facts {
        let hunting = self.lock == Lock::Hunting;
        let mut facts = Facts {
            seen: Seen::Telemetry(Rel::Unknown),
            shadow: hunting && self.in_shadow(),
            other_fits: false,
            cut: false,
            nested: false,
        };
        match (frame, frame.kind(), frame.seq()) {
            (Downlink::Reply(reply), ..) => {
                facts.shadow = hunting && (self.in_shadow() || self.may_be_a_frames_tail());
                facts.seen = Seen::Reply {
                    awaited: self.expect.code == Some(reply.code),
                    clean: !holds_a_frame_start(reply.encode().get(2..).unwrap_or(&[])),
                };
            }
            (_, Kind::Telemetry(stream), Some(seq)) => {
                let rel = self.counts.rel(stream, seq, 0);
                facts.seen = Seen::Telemetry(rel);
                facts.cut = ends_with_a_header(self.buf.as_slice(), frame.kind(), 0);
                if hunting {
                    facts.nested = self.nested(frame, rel);
                    facts.other_fits = matches!(rel, Rel::Continues | Rel::Near)
                        && self.other_stream_fits(stream, seq, 0);
                }
            }
            _ => {}
        }
        facts
    }

    /// While hunting, about the reply at the front of the window: whether it may be the tail
    /// of a telemetry frame whose start was lost or damaged (a payload can hold `23` and a
    /// reply code). It is when it and the bytes thrown away right before it (since the last
    /// frame taken or quiet line, or since the start) fit in a frame of a stream, and the next
    /// frame, of that stream, continues from the reply's last byte read as that frame's count.
    fn may_be_a_frames_tail(&self) -> bool {
        let len = Kind::Reply.len();
        let buf = self.buf.as_slice();
        let (Some(&last), Some(next)) = (buf.get(len.wrapping_sub(1)), buf.get(len..)) else {
            return false;
        };
        let Some(stream) = next.get(..2).and_then(telemetry_header) else {
            return false;
        };
        let (Some(&count), true) = (
            next.get(stream.seq_at()),
            usize::from(self.thrown.before_len).saturating_add(len)
                <= Kind::Telemetry(stream).len(),
        ) else {
            return false;
        };
        let delta = count.wrapping_sub(last);
        (1..=FIRST_STEP_MAX).contains(&delta) || self.counts.is_step(stream, delta)
    }

    /// Row 14's suspicion about the telemetry candidate `frame` (count `rel`) at the front of
    /// the window, while hunting: its bytes hold a real frame it cannot be.
    fn nested(&self, frame: &Downlink, rel: Rel) -> bool {
        self.in_shadow()
            && (rel != Rel::Near && self.nests_a_frame(frame, &[0])
                || self.overlaps_the_rejected_frames_next(frame)
                || self.is_the_rejected_frames_tail(frame))
            || self.nests_a_frame(frame, &[1, -1])
            || self.in_a_replys_value(frame)
            || self.inside_a_headless_frame(frame)
    }

    /// Inside a frame rejected on a boundary: whether a telemetry header lies inside the
    /// candidate `frame` (at the window's front) right where that frame, had it lost or gained a
    /// byte, would end: where the frame after it starts.
    pub(super) fn overlaps_the_rejected_frames_next(&self, frame: &Downlink) -> bool {
        let end = usize::from(self.thrown.rejected_left).saturating_sub(2);
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
    pub(super) fn is_the_rejected_frames_tail(&self, frame: &Downlink) -> bool {
        self.thrown.rejected == Some(frame.kind())
            && usize::from(self.thrown.rejected_left) == frame.kind().len()
    }

    /// Whether the telemetry candidate `frame` at the front of the window ends with a frame of
    /// another stream whose count (the candidate's) continues (or is near) that stream's; that
    /// frame's bytes there number its length plus one of `damage` (0: whole; -1: it lost a
    /// byte; 1: it gained one).
    pub(super) fn nests_a_frame(&self, frame: &Downlink, damage: &[i8]) -> bool {
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

    /// Whether the telemetry candidate of `outer` at the front of the window ends with the
    /// whole of a frame of another stream (its header where that frame would start, counts
    /// aside).
    pub(super) fn ends_with_a_frame(&self, outer: Stream) -> bool {
        let len = Kind::Telemetry(outer).len();
        let bytes = self.buf.as_slice().get(..len).unwrap_or(&[]);
        Stream::ALL.iter().any(|inner| {
            let off = len.saturating_sub(Kind::Telemetry(*inner).len());
            *inner != outer
                && off > 0
                && bytes
                    .get(off..off.saturating_add(2))
                    .and_then(telemetry_header)
                    == Some(*inner)
        })
    }

    /// Whether the telemetry candidate `frame` at the front of the window starts in a reply's
    /// value (the two bytes thrown away right before it are `23` and a reply code) and its
    /// tail, from where that reply ends, is a whole frame of another stream whose count (the
    /// candidate's) fits that stream: the reply and that frame are real, the candidate
    /// straddles them (a value starting `FF FA`).
    pub(super) fn in_a_replys_value(&self, frame: &Downlink) -> bool {
        let (Kind::Telemetry(outer), Some(seq)) = (frame.kind(), frame.seq()) else {
            return false;
        };
        let [code, hash, ..] = self.thrown.before.to_le_bytes();
        if self.thrown.before_len < 2 || Kind::from_header(hash, code) != Some(Kind::Reply) {
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
                    && matches!(
                        self.counts.rel(inner, seq, off),
                        Rel::Continues | Rel::Near | Rel::Unknown
                    )
            })
    }

    /// Whether the telemetry candidate `frame` at the front of the window is the tail of a
    /// frame of another stream that lost its first byte: that frame's second header byte
    /// (`FA`..`FC`, not after an `FF`; after a frame taken or a quiet line, the byte before it
    /// is not known) among the bytes thrown away right before it, where the rest of that frame
    /// ends on the candidate's count byte, which fits that stream.
    pub(super) fn inside_a_headless_frame(&self, frame: &Downlink) -> bool {
        let (Kind::Telemetry(own), Some(seq)) = (frame.kind(), frame.seq()) else {
            return false;
        };
        let len = frame.kind().len();
        // The byte `back` bytes before the window's first, if it was seen.
        let seen = self.thrown.before.to_le_bytes();
        let before = |back: usize| {
            seen.get(back.wrapping_sub(1))
                .copied()
                .filter(|_| back <= usize::from(self.thrown.before_len))
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

    /// Whether `seq` would continue (or be near) a stream other than `stream`; not counting, for
    /// a candidate right after a frame rejected on a boundary, that frame's stream: the count
    /// fits the slot of that damaged frame (one counter shared by all streams, a time tick),
    /// which is no evidence against the frame after it.
    pub(super) fn other_stream_fits(&self, stream: Stream, seq: u8, at: usize) -> bool {
        let explained = match self.thrown.rejected {
            Some(Kind::Telemetry(rejected))
                if at == 0 && (1..=3).contains(&self.thrown.rejected_left) =>
            {
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
    pub(super) fn start(&self) -> Start {
        match self.lock {
            Lock::Locked if self.resynced => Start::Resynced,
            lock => Start::from(lock),
        }
    }
}

/// Whether the last two bytes of a frame of `kind` starting `at` bytes into `window` are a
/// telemetry header.
#[inline(never)]
pub(super) fn ends_with_a_header(window: &[u8], kind: Kind, at: usize) -> bool {
    let end = at.saturating_add(kind.len());
    window
        .get(end.saturating_sub(2)..end)
        .and_then(telemetry_header)
        .is_some()
}

/// Whether `bytes` hold a telemetry header (a reply's value that might be a cut reply with the
/// next frame's start in it).
pub(super) fn holds_a_frame_start(bytes: &[u8]) -> bool {
    bytes
        .windows(2)
        .any(|pair| telemetry_header(pair).is_some())
}
/// The stream whose telemetry header ends with `second`, if one does.
pub(super) fn stream_of_second(second: u8) -> Option<Stream> {
    let [sync, _] = telemetry::Imu::HEADER;
    telemetry_header(&[sync, second])
}
/// The stream whose telemetry header `pair` is, if it is one.
#[inline]
pub(super) fn telemetry_header(pair: &[u8]) -> Option<Stream> {
    // (The headers themselves, not `Kind::from_header`: a reply's header needs a table
    // lookup, a telemetry header two compares.)
    match *pair {
        [a, b] if [a, b] == telemetry::Imu::HEADER => Some(Stream::Imu),
        [a, b] if [a, b] == telemetry::Encoders::HEADER => Some(Stream::Encoders),
        [a, b] if [a, b] == telemetry::Battery::HEADER => Some(Stream::Battery),
        _ => None,
    }
}
