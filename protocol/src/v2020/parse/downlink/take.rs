//! Taking frames and throwing bytes away: the fast paths for a frame the counts already
//! vouch for, a frame judged taken, a candidate rejected, and the bookkeeping of what was
//! consumed (the lock, the counts, the bytes before the window, the statistics).

use super::class::telemetry_header;
use super::counts::Rel;
use super::rules::{self, Chain, Facts, Need, Seen, Start, Walk};
use super::{DownlinkParser, FORGET_AFTER, Lock, MAX_DROPPED, short_ways};
use crate::telemetry::{self, Downlink, Kind, Stream};

// What row 11 needs, whatever kind of boundary: what its shortcut assumes.
const UNAWAITED: Facts = Facts {
    seen: Seen::Reply {
        awaited: false,
        clean: true,
    },
    ..ROW1
};
const _: () = assert!(matches!(
    (
        rules::decide(Start::Locked, UNAWAITED),
        rules::decide(Start::Tentative, UNAWAITED),
    ),
    (
        (
            11,
            Need::Chain(Walk {
                chain: Chain::Exact,
                gap: 0,
                ..
            })
        ),
        (
            11,
            Need::Chain(Walk {
                chain: Chain::Exact,
                gap: 0,
                ..
            })
        )
    )
));
/// What row 11's shortcut ([`DownlinkParser::unawaited_reply`]) says.
pub(super) enum Row11 {
    /// Not before this many more bytes.
    Wait(usize),
    /// Not before the next frame's header, two bytes right after the reply (as
    /// [`Verdict::NeedHeader`](super::judge::Verdict::NeedHeader)).
    Header,
    /// The reply at the front, `usize` bytes, is taken.
    Take(Downlink, usize),
    /// The general judgement decides.
    Judge,
}

/// Telemetry whose count continues its stream, and nothing else known: row 1's facts.
const ROW1: Facts = Facts {
    seen: Seen::Telemetry(Rel::Continues),
    shadow: false,
    other_fits: false,
    cut: false,
    nested: false,
};

impl DownlinkParser {
    /// The bytes just stored may have completed the frame at the front of the window: if it is
    /// alone there and row 1 takes it ([`row1_step`](Self::row1_step)), it is taken
    /// without the general judgement; a frame still incomplete waits without it; anything else
    /// is judged. The same decision either way: a shortcut, not a rule.
    #[inline(never)]
    pub(super) fn complete(&mut self) -> Option<Downlink> {
        // Row 1, the common case, without the general bookkeeping (kept apart from the rest:
        // a small function is cheap to enter).
        if !short_ways() {
            return self.run(false);
        }
        let bytes = self.buf.kept();
        if let (&[first, second, ..], Some(&seq)) = (bytes, bytes.last()) {
            if let Some(stream) = telemetry_header(&[first, second]) {
                if Kind::Telemetry(stream).len() == bytes.len() {
                    if let Some(step) = self.row1_step(stream, seq) {
                        if let Some(frame) = Downlink::read_telemetry(stream, bytes) {
                            self.take_learnt(stream, step, seq);
                            return Some(frame);
                        }
                    }
                }
            }
        }
        self.complete_judged()
    }

    /// [`complete`](Self::complete) past row 1: a frame still incomplete waits, row 11's
    /// shortcut, else the general judgement.
    #[inline(never)]
    fn complete_judged(&mut self) -> Option<Downlink> {
        if let Some(more) = self.chain_header_wait() {
            self.wait_for(more);
            return None;
        }
        let bytes = self.buf.as_slice();
        if let [first, second, ..] = *bytes {
            if let Some(kind) = Kind::from_header(first, second) {
                // Incomplete (a read that ended inside it): the judgement would wait for the
                // rest, so wait for it without judging.
                if let Some(more) = kind.len().checked_sub(bytes.len()).filter(|n| *n > 0) {
                    self.wait_for(more);
                    return None;
                }
                match self.unawaited_reply(kind) {
                    Row11::Wait(more) => {
                        self.wait_for(more);
                        return None;
                    }
                    Row11::Header => {
                        self.wait_for_header();
                        return None;
                    }
                    Row11::Take(reply, len) => {
                        self.missing = 0;
                        self.leave(Kind::Reply, len);
                        self.drain = !self.buf.is_empty();
                        return Some(reply);
                    }
                    Row11::Judge => {}
                }
            }
        }
        self.run(false)
    }

    /// Row 11 without the general judgement, for a reply nobody awaits at the front of the
    /// window on a boundary: with the next frame's header not yet whole, or its frame not yet
    /// complete, it waits for it; with that frame whole, telemetry whose count is one learnt
    /// step on, it is taken (the frame after it stays in the window). The decision the table
    /// makes (asserted below); anything else is left to it.
    pub(super) fn unawaited_reply(&self, kind: Kind) -> Row11 {
        let bytes = self.buf.as_slice();
        let len = kind.len();
        if kind != Kind::Reply
            || self.lock == Lock::Hunting
            || self.expect.code == bytes.get(1).copied()
        {
            return Row11::Judge;
        }
        let (Some(head), Some(next)) = (bytes.get(..len), bytes.get(len..)) else {
            return Row11::Judge;
        };
        let [first, second, ..] = *next else {
            return if next.is_empty() {
                Row11::Header
            } else {
                Row11::Judge
            };
        };
        let Some(next_kind) = Kind::from_header(first, second) else {
            return Row11::Judge;
        };
        let next_len = next_kind.len();
        if next.len() < next_len {
            return Row11::Wait(next_len.saturating_sub(next.len()));
        }
        let continues = match (next_kind, next.last()) {
            (Kind::Telemetry(stream), Some(&seq)) if next.len() == next_len => {
                self.counts.learnt_step(stream, seq).is_some()
            }
            _ => false,
        };
        match Downlink::read(Kind::Reply, head) {
            Some(reply) if continues => Row11::Take(reply, len),
            _ => Row11::Judge,
        }
    }

    /// Row 1 as a shortcut, for a telemetry frame of `stream` whose bytes are alone in the
    /// window or about to be consumed from the caller's slice: on a boundary, a count `seq` one
    /// learnt step on takes it at once, with no judgement: the step (then
    /// [`take_learnt`](Self::take_learnt) takes it). `None`: anything else goes through the
    /// rules. A shortcut, not a rule.
    #[inline]
    pub(super) fn row1_step(&self, stream: Stream, seq: u8) -> Option<usize> {
        // (Row 1 holds on a boundary whatever kind of boundary it is.)
        const _: () = assert!(matches!(
            (
                rules::decide(Start::Locked, ROW1),
                rules::decide(Start::Tentative, ROW1),
            ),
            ((1, Need::Now), (1, Need::Now))
        ));
        if self.lock == Lock::Hunting {
            return None;
        }
        self.counts.learnt_step(stream, seq)
    }

    /// Row 1's bookkeeping for a frame of `stream` at the front of the window (or about to be
    /// consumed from the caller's slice) whose count `seq` is learnt step `step` on.
    #[inline]
    pub(super) fn take_learnt(&mut self, stream: Stream, step: usize, seq: u8) {
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
    pub(super) fn take_straight(&mut self, bytes: &[u8]) -> Option<(Downlink, usize)> {
        if self.drain {
            return None;
        }
        let kept = self.buf.kept();
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
    pub(super) fn store_cut(&mut self, bytes: &[u8]) -> bool {
        if self.drain || !self.buf.is_empty() {
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

    /// Bytes still missing from the frame whose header is at the front of the window (0 if
    /// there is none, or it is complete).
    pub(super) fn front_missing(&self) -> u8 {
        match self.buf.as_slice() {
            [first, second, ..] => match Kind::from_header(*first, *second) {
                Some(kind) => u8::try_from(kind.len().saturating_sub(self.buf.len())).unwrap_or(0),
                None => 0,
            },
            _ => 0,
        }
    }

    /// Drops the candidate's first byte and goes hunting.
    pub(super) fn reject(&mut self) {
        // A frame rejected on a boundary: the start positions inside it (row 14) and right
        // after it. (Right where the frame rejected before ends, a byte lost or gained or its
        // count byte changed, is a boundary too.)
        let boundary = self.lock != Lock::Hunting || (1..=3).contains(&self.thrown.rejected_left);
        if let (true, [first, second, ..]) = (boundary, self.buf.as_slice()) {
            if let Some(kind) = Kind::from_header(*first, *second) {
                self.thrown.rejected = Some(kind);
                self.thrown.rejected_left = u8::try_from(kind.len().saturating_add(2)).unwrap_or(0);
            }
        }
        let first = self.buf.as_slice().first().copied().unwrap_or(0);
        self.buf.drop_front(1);
        self.discard(first);
    }

    /// Whether the candidate at the front of the window starts inside the frame last rejected
    /// on a boundary: within the length its header promised, less [`MAX_DROPPED`] bytes it may
    /// have lost.
    pub(super) fn in_shadow(&self) -> bool {
        usize::from(self.thrown.rejected_left) > MAX_DROPPED.saturating_add(2)
    }

    /// Counts one byte thrown away (already out of the window, or never in it): `byte`, the
    /// one right before the window's first byte now.
    pub(super) fn discard(&mut self, byte: u8) {
        self.thrown.before = self.thrown.before << 8 | u32::from(byte);
        self.thrown_away(1);
    }

    /// Counts the bytes of `run` thrown away, in one step: the same as one
    /// [`discard`](Self::discard) per byte. The last of them is now right before the window's
    /// first byte.
    #[inline]
    pub(super) fn discard_run(&mut self, run: &[u8]) {
        let n = run.len();
        for byte in run.iter().skip(n.saturating_sub(4)) {
            self.thrown.before = self.thrown.before << 8 | u32::from(*byte);
        }
        self.thrown_away(n);
    }

    /// The counters, counts and lock for `n` bytes thrown away.
    #[inline]
    pub(super) fn thrown_away(&mut self, n: usize) {
        self.thrown.before_len = self
            .thrown
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
    pub(super) fn consumed(&mut self, n: usize) {
        self.thrown.rejected_left = self
            .thrown
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
    pub(super) fn accept(&mut self, frame: &Downlink, len: usize, seen: Seen) {
        // A far count taken (on a certain boundary, or a restart) is believed only if its own
        // stream's next frame continues it (the board moved its count on); otherwise it is a
        // damaged count byte, and the stream moves on by a step.
        let believed = seen != Seen::Telemetry(Rel::Far)
            || self.chain(
                self.buf.as_slice(),
                frame,
                len,
                Walk::only(Chain::Own),
                false,
            ) == Ok(true);
        // Frames lost (a near count) teach no step, unless nothing was lost.
        let near = seen == Seen::Telemetry(Rel::Near);
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
            (_, _, Downlink::Reply(reply)) if self.expect.code == Some(reply.code) => {
                self.expect.code = None;
            }
            _ => {}
        }
    }
}

impl DownlinkParser {
    /// A frame of `kind`, `len` bytes, was taken: its bytes leave the window, it is counted, and
    /// the parser is Locked right after it (the counts are the caller's).
    // (Always inlined: out of line, its two callers cost more flash than its copies.)
    #[inline(always)]
    pub(super) fn leave(&mut self, kind: Kind, len: usize) {
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
    pub(super) fn left(&mut self, kind: Kind, len: usize) {
        self.counts.bytes(len);
        self.since_frame = 0;
        self.thrown.rejected_left = 0;
        self.thrown.before_len = 0;
        self.stats.count_frame(kind);
        self.lock = Lock::Locked;
    }
}
