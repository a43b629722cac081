//! Judging the candidate at the front of the window: what the table ([`rules::decide`]) asks of
//! it, and the chain of frames after it that may vouch for it ([`Walk`]).

use super::class::{ends_with_a_header, stream_of_second};
use super::counts::{Counts, FIRST_STEP_MAX, Rel};
use super::rules::{self, Chain, Need, Seen, Walk as Rule};
use super::{DownlinkParser, IN_STEP, Lock, WINDOW};
use crate::telemetry::{self, Downlink, Kind, Stream};
use core::ops::ControlFlow::{self, Break, Continue};

/// What the bytes in the window say about the candidate at its front.
pub(super) enum Verdict {
    /// Not enough bytes to decide: at least this many more (1 or more) before a decision can
    /// fall (a quiet line aside).
    NeedMore(usize),
    /// Not before the chain's next frame: two more bytes, its header, at the window's end. A
    /// header there only makes the judgement wait for the rest of its frame, if it fits the
    /// window ([`DownlinkParser::chain_header_wait`]).
    NeedHeader,
    /// The first byte starts no frame: drop it.
    Reject,
    /// A frame of this length, and what it was seen to be.
    Accept(Downlink, usize, Seen),
}

/// Why a chain cannot decide yet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Wait {
    /// Not before this many more bytes (the window's length at most).
    Bytes(u8),
    /// Not before the next frame's header, two bytes, right at the window's end.
    Header,
}

/// What a step of the walk decided: `Break` with the chain's answer (`Err`: not yet), or
/// `Continue`.
type Step<T = ()> = ControlFlow<Result<bool, Wait>, T>;

/// A walk along the frames right after a candidate, link by link, until one vouches for it
/// (or proves it false, or more bytes are needed): what [`DownlinkParser::chain`] keeps from
/// one link to the next.
struct Walk<'a> {
    parser: &'a DownlinkParser,
    buf: &'a [u8],
    rule: Rule,
    quiet: bool,
    /// The counts as the chain so far leaves them (the candidate's own taken).
    counts: Counts,
    /// The candidate's stream, if it is telemetry.
    own: Option<Stream>,
    /// Where the next frame should start, and how many junk bytes may come first.
    pos: usize,
    gap: usize,
    /// (Own, Restart with no step learnt; Rebase) the step between the own stream's frames seen,
    /// and how many times.
    own_step: Option<(u8, u8)>,
    /// (Own, Restart) The counts of the chain's telemetry frames, whatever their streams, from
    /// the candidate's on: the last one, the step between each two, and how many times it
    /// was seen (one counter shared by all streams steps every frame alike); `None` once two
    /// steps differ.
    shared: Option<(u8, u8, u8)>,
    /// What the frames passed over (their count a header's second byte) left.
    passed: Passed,
    /// Where the chain's last frame of each stream starts, the candidate's included
    /// ([`NOT_YET`]: none), for [`Counts::too_soon`].
    starts: [u8; 3],
}

/// [`Walk::starts`] for a stream with no frame in the chain yet (no window is this long).
const NOT_YET: u8 = u8::MAX;
const _: () = assert!(WINDOW < NOT_YET as usize);

/// What the frames a chain passed over left, for a later one to vouch only from a count that
/// neither they nor the candidate gave.
#[derive(Default)]
struct Passed {
    /// The streams whose count is, last, one a frame passed over gave (a bit per stream).
    streams: u8,
    /// A frame of the candidate's own stream was a link (not passed over): its count, not the
    /// candidate's, is the one the stream's next frames continue.
    own_linked: bool,
    /// (Exact) A frame of the chain was passed over (a stream's first).
    skipped: bool,
}

impl<'a> Walk<'a> {
    /// The walk after the candidate `frame` (`len` bytes at the front of `buf`).
    fn new(
        parser: &'a DownlinkParser,
        buf: &'a [u8],
        frame: &Downlink,
        len: usize,
        rule: Rule,
        quiet: bool,
    ) -> Self {
        let mut counts = parser.counts;
        let mut starts = [NOT_YET; 3];
        let own = match (frame.kind(), frame.seq()) {
            (Kind::Telemetry(stream), Some(seq)) => {
                counts.take(stream, seq, false);
                if let Some(start) = starts.get_mut(stream.index()) {
                    *start = 0;
                }
                Some(stream)
            }
            _ => None,
        };
        Walk {
            parser,
            buf,
            rule,
            quiet,
            counts,
            own,
            pos: len,
            gap: rule.gap,
            own_step: None,
            shared: frame.seq().map(|seq| (seq, 0, 0)),
            passed: Passed::default(),
            starts,
        }
    }

    /// The next frame's header: right at `pos`, or (first link of an exactly continuing
    /// candidate) after up to two junk bytes. `Continue` with where it starts and its kind.
    fn next_header(&self) -> Step<(usize, Kind)> {
        let (buf, pos, quiet) = (self.buf, self.pos, self.quiet);
        for at in pos..=pos.saturating_add(self.gap) {
            match (buf.get(at), buf.get(at.saturating_add(1))) {
                (Some(a), Some(b)) => {
                    if let Some(kind) = Kind::from_header(*a, *b) {
                        return Continue((at, kind));
                    }
                }
                (None, _) if at == pos && quiet => return Break(Ok(self.rule.quiet)),
                (Some(a), None) if Kind::may_start(*a) && !quiet => {
                    return Break(undecided(buf, Wait::Bytes(1)));
                }
                // Nothing after the candidate yet: the next header is two bytes. Its first
                // alone allows one decision (not a header: reject), and taking it a byte later,
                // with the second, decides the same (a reply nobody awaits is judged once less).
                (None, _) if !quiet => {
                    let wait = if at == pos {
                        Wait::Header
                    } else {
                        Wait::Bytes(1)
                    };
                    return Break(undecided(buf, wait));
                }
                _ => {}
            }
        }
        Break(self.no_header())
    }

    /// No header where the next frame should start. A reply nobody awaits, on a certain
    /// boundary, whose next frame lost its first byte: the frame after that one decides. Unless
    /// the reply's last byte is that first byte (`FF`): the next frame's header is then whole,
    /// a byte early, and it is the reply that lost a byte.
    fn no_header(&self) -> Result<bool, Wait> {
        let (buf, pos) = (self.buf, self.pos);
        let [sync, _] = telemetry::Imu::HEADER;
        let lost_first = buf
            .get(pos)
            .and_then(|second| stream_of_second(*second))
            .filter(|_| buf.get(pos.wrapping_sub(1)) != Some(&sync));
        match lost_first {
            Some(stream) if self.rule.chain == Chain::Exact && !self.passed.skipped => {
                let next = pos
                    .saturating_sub(1)
                    .saturating_add(Kind::Telemetry(stream).len());
                self.parser
                    .past_a_damaged_frame(buf, &self.counts, stream, &[next], self.quiet)
            }
            _ => Ok(false),
        }
    }

    /// The link whose header is at `at`: read whole, then judged by the chain's kind.
    fn link(&mut self, at: usize, kind: Kind) -> Step {
        let (buf, pos) = (self.buf, self.pos);
        // Junk between the candidate and its chain that is the tail of a frame from the
        // boundary before the candidate, which lost or gained a byte: the chain vouches for
        // that frame, not for the candidate inside it.
        if at > pos && self.parser.a_damaged_frame_ends_at(at) {
            return Break(Ok(false));
        }
        let end = at.saturating_add(kind.len());
        let Some(bytes) = buf.get(at..end) else {
            return Break(if self.quiet || end > WINDOW {
                Ok(false)
            } else {
                Err(more(end, buf))
            });
        };
        // What the walk reads of a link: a telemetry frame's stream and count (its last byte;
        // nothing else of it is read, so it is not decoded), or that it is a reply.
        let telemetry = match kind {
            Kind::Telemetry(stream) => match bytes.last() {
                Some(&seq) => Some((stream, seq)),
                None => return Break(Ok(false)),
            },
            Kind::Reply => {
                let Some(Downlink::Reply(reply)) = Downlink::read(kind, bytes) else {
                    return Break(Ok(false));
                };
                // The master asked once: an awaited reply whose chain holds another reply with
                // the same code is not the answer (a `23` and the code in a damaged frame's
                // tail, the real reply further on).
                if self.rule.once && self.parser.expect.code == Some(reply.code) {
                    return Break(Ok(false));
                }
                None
            }
        };
        if self.rule.chain == Chain::Exact {
            self.exact_link(telemetry, at, end)?;
            self.passed.skipped = true;
        } else if let Some((stream, seq)) = telemetry {
            self.counted_link(stream, seq, at)?;
        }
        self.pos = end;
        self.gap = 0;
        Continue(())
    }

    /// (Exact) Only the next frame, continuing exactly; a stream's first frame (no count to
    /// judge by) is passed over, a reply is not.
    fn exact_link(&mut self, telemetry: Option<(Stream, u8)>, at: usize, end: usize) -> Step {
        let Some((stream, seq)) = telemetry else {
            return Break(Ok(false));
        };
        match self.counts.rel(stream, seq, at) {
            Rel::Continues => Break(Ok(true)),
            // On a certain boundary, frames lost upstream.
            Rel::Near => Break(Ok(self.parser.lock == Lock::Locked)),
            Rel::Unknown => {
                self.counts.take(stream, seq, false);
                Continue(())
            }
            // The next frame damaged (its count byte lost or changed): the frame after it
            // decides.
            Rel::Far if !self.passed.skipped => {
                let places = [end.saturating_sub(1), end.saturating_add(1)];
                Break(self.parser.past_a_damaged_frame(
                    self.buf,
                    &self.counts,
                    stream,
                    &places,
                    self.quiet,
                ))
            }
            Rel::Far => Break(Ok(false)),
        }
    }

    /// (Verify, Rebase, Own, Restart) A link judged by its count: one that continues (or is
    /// near) its stream's vouches, if the chain lets its stream vouch.
    fn counted_link(&mut self, stream: Stream, seq: u8, at: usize) -> Step {
        // Two frames of a stream closer than the board's rates allow (lookalikes in a payload
        // come back to back): the chain's alignment cannot be the board's.
        // (`at` is less than the window's length, and after the stream's frame before.)
        if let Some(start) = self.starts.get_mut(stream.index()) {
            let before = core::mem::replace(start, at as u8);
            if before != NOT_YET && self.counts.too_soon(stream, at.wrapping_sub(before.into())) {
                return Break(Ok(false));
            }
        }
        // A frame whose count byte is the second byte of a telemetry header (its last two
        // bytes are one: a cut frame running into the next one, row 15) is no evidence: passed
        // over. Unless, in a chain where any stream vouches, its count continues its stream
        // exactly from a count that neither a frame passed over nor the candidate gave (an IMU
        // frame whose gyro Z reads -1 and whose count is `FA`..`FC` ends so; a cut frame's
        // `FA` must not be what the next lookalike's `FB` continues).
        let bit = 1u8 << stream.index();
        if ends_with_a_header(self.buf, Kind::Telemetry(stream), at) {
            if matches!(self.rule.chain, Chain::Verify | Chain::Rebase)
                && self.passed.streams & bit == 0
                && (self.own != Some(stream) || self.passed.own_linked)
                && self.counts.rel(stream, seq, at) == Rel::Continues
            {
                return Break(Ok(true));
            }
            self.passed.streams |= bit;
            self.counts.take(stream, seq, false);
            self.shared = None;
            return Continue(());
        }
        self.passed.streams &= !bit;
        self.passed.own_linked |= self.own == Some(stream);
        if self.shared_in_step(stream, seq) || self.rebase_in_step(stream, seq) {
            return Break(Ok(true));
        }
        let vouches = self.may_vouch(stream, seq)?;
        match self.counts.rel(stream, seq, at) {
            Rel::Continues if vouches => Break(Ok(true)),
            Rel::Near if vouches => Break(Ok(true)),
            Rel::Continues | Rel::Near | Rel::Unknown => {
                self.counts.take(stream, seq, false);
                Continue(())
            }
            Rel::Far if matches!(self.rule.chain, Chain::Rebase | Chain::Restart) => {
                self.counts.take(stream, seq, false);
                Continue(())
            }
            Rel::Far => Break(Ok(false)),
        }
    }

    /// (Rebase, the candidate's stream with no step learnt) Whether the link, of the
    /// candidate's own stream, is the [`IN_STEP`]th in a row the same step on, from the
    /// candidate's count, that step wider than [`FIRST_STEP_MAX`]: a board stepping its count by
    /// 5 or more, whose counts no chain reads as continuing before a step is learnt, is vouched
    /// for as hunting vouches for it (row 9).
    fn rebase_in_step(&mut self, stream: Stream, seq: u8) -> bool {
        if self.rule.chain != Chain::Rebase
            || self.own != Some(stream)
            || self.counts.has_steps(stream)
        {
            return false;
        }
        let delta = seq.wrapping_sub(self.counts.last(stream));
        let seen = match self.own_step {
            None => 1,
            Some((step, seen)) if step == delta && seen > 0 => seen.saturating_add(1),
            // Out of step: no longer in step from the candidate's count.
            Some(_) => 0,
        };
        self.own_step = Some((delta, seen));
        seen >= IN_STEP && wide(delta)
    }

    /// Whether the chain asks for frames in step to vouch for a candidate of `stream`: an Own
    /// chain while the stream has no step learnt, a Restart chain always.
    fn in_step_needed(&self, stream: Stream) -> bool {
        match self.rule.chain {
            Chain::Restart => true,
            Chain::Own => !self.counts.has_steps(stream),
            _ => false,
        }
    }

    /// (Own, Restart, while the candidate's stream has no step learnt) Whether the link of
    /// `stream` with count `seq` makes [`IN_STEP`] steps in a row, equal and of 1 to
    /// [`FIRST_STEP_MAX`], between the counts of the chain's telemetry frames, whatever their
    /// streams: one counter shared by all streams, which the candidate's own stream alone
    /// shows in uneven steps (+2 past an encoder frame). Its own stream steps first.
    fn shared_in_step(&mut self, stream: Stream, seq: u8) -> bool {
        let Some((last, step, seen)) = self.shared else {
            return false;
        };
        let own = self.own.unwrap_or(stream);
        if !self.in_step_needed(own) {
            return false;
        }
        // Only the IMU, whose frames the others come between, and not one whose tail is a
        // whole frame of another stream: under one shared counter that frame's count (the
        // candidate's) continues the line whether or not the candidate is real.
        if own != Stream::Imu || seen == 0 && self.parser.ends_with_a_frame(own) {
            self.shared = None;
            return false;
        }
        let delta = seq.wrapping_sub(last);
        let fits =
            (1..=FIRST_STEP_MAX).contains(&delta) || self.rule.chain == Chain::Own && wide(delta);
        if seen > 0 && delta != step || !fits {
            self.shared = None;
            return false;
        }
        // The candidate's own stream steps first, straight from the candidate (replies aside):
        // a dropout can cut a frame of another stream so that it ends on the own stream's next
        // count byte, that frame's header lost with it, and such a frame between the candidate
        // and its stream's next frame would make a gap in the own stream look like the shared
        // step, and teach the own stream twice its step.
        if stream != own && self.own_step.is_none() {
            self.shared = None;
            return false;
        }
        // A frame of a stream with no count yet is no evidence, but keeps the steps: its count
        // is anyone's (the same dropout can cut it onto the own stream's next count).
        let seen = if self.counts.knows(stream) {
            seen.saturating_add(1)
        } else {
            seen
        };
        self.shared = Some((seq, delta, seen));
        seen >= IN_STEP
    }

    /// Whether a link of `stream` (count `seq`) may vouch: any stream's, but only the
    /// candidate's own in an Own or Restart chain, and there, with no step learnt, only after
    /// [`IN_STEP`] frames equally spaced (sensor bytes drift slowly, and payloads repeat a
    /// frame's length apart, so false frames' "counts" can move in small steps for a while).
    fn may_vouch(&mut self, stream: Stream, seq: u8) -> Step<bool> {
        let own_only = matches!(self.rule.chain, Chain::Own | Chain::Restart);
        let vouches = !own_only || self.own == Some(stream);
        if !(vouches && self.in_step_needed(stream)) {
            return Continue(vouches);
        }
        let delta = seq.wrapping_sub(self.counts.last(stream));
        match self.own_step {
            // In step by more than a stream's first step may be (a shared counter stepping by
            // 5 or more): the count will not read as continuing, the frames in step vouch.
            Some((step, seen)) if step == delta && seen >= IN_STEP - 1 => {
                if self.rule.chain == Chain::Own && wide(delta) {
                    Break(Ok(true))
                } else {
                    Continue(true)
                }
            }
            Some((step, seen)) if step == delta => {
                self.own_step = Some((step, seen.saturating_add(1)));
                Continue(false)
            }
            // Out of step: the chain fails, unless the chain's frames of every stream are
            // still in step (one counter shared by all streams): then only they may vouch.
            Some(_) if self.shared.is_some() => {
                self.own_step = Some((0, 0));
                Continue(false)
            }
            Some(_) => Break(Ok(false)),
            None => {
                self.own_step = Some((delta, 1));
                Continue(false)
            }
        }
    }
}

impl DownlinkParser {
    /// Whether the chain of frames after the candidate (`frame`, `len` bytes) vouches for it;
    /// `Err(n)`: not decided yet, and not before `n` more bytes (a frame of the chain is
    /// incomplete: nothing is judged until its last byte).
    pub(super) fn chain(
        &self,
        buf: &[u8],
        frame: &Downlink,
        len: usize,
        rule: Rule,
        quiet: bool,
    ) -> Result<bool, Wait> {
        let mut walk = Walk::new(self, buf, frame, len, rule, quiet);
        loop {
            let step = match walk.next_header() {
                Continue((at, kind)) => walk.link(at, kind),
                Break(answer) => Break(answer),
            };
            if let Break(answer) = step {
                return answer;
            }
        }
    }

    /// Judges the candidate at the front of the window. `quiet`: the line has gone quiet, so
    /// no more bytes are coming for now.
    pub(super) fn judge(&self, quiet: bool) -> Verdict {
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
        let facts = self.facts(&frame);
        let taken = match rules::decide(self.start(), facts).1 {
            Need::Now => Ok(true),
            Need::Never => Ok(false),
            Need::Follow => followed(buf, len, quiet).ok_or(Wait::Bytes(1)),
            Need::Quiet => match buf.get(len..) {
                Some([]) | None if quiet => Ok(true),
                Some([]) | None => Err(Wait::Bytes(1)),
                Some(_) => Ok(false),
            },
            Need::Chain(rule) => self.chain(buf, &frame, len, rule, quiet),
        };
        match taken {
            Ok(true) => Verdict::Accept(frame, len, facts.seen),
            Ok(false) => Verdict::Reject,
            Err(Wait::Bytes(more)) => Verdict::NeedMore(usize::from(more.max(1))),
            Err(Wait::Header) => Verdict::NeedHeader,
        }
    }

    /// Whether a telemetry frame that started on the boundary right before the bytes thrown away
    /// ahead of the window (one to three of them, the first `FF`) and lost or gained a byte
    /// would end `at` bytes into the window.
    pub(super) fn a_damaged_frame_ends_at(&self, at: usize) -> bool {
        let thrown = usize::from(self.thrown.before_len);
        let [sync, _] = telemetry::Imu::HEADER;
        let first = self
            .thrown
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
    pub(super) fn past_a_damaged_frame(
        &self,
        buf: &[u8],
        counts: &Counts,
        damaged: Stream,
        places: &[usize],
        quiet: bool,
    ) -> Result<bool, Wait> {
        if self.lock != Lock::Locked {
            return Ok(false);
        }
        let mut counts = *counts;
        counts.passed(damaged);
        for &at in places {
            let next = match (buf.get(at), buf.get(at.saturating_add(1))) {
                (Some(a), Some(b)) => Kind::from_header(*a, *b),
                _ if quiet => return Ok(false),
                _ => {
                    return undecided(buf, more(at.saturating_add(2), buf));
                }
            };
            let Some(Kind::Telemetry(stream)) = next else {
                continue;
            };
            let end = at.saturating_add(Kind::Telemetry(stream).len());
            let Some(seq) = buf.get(at.saturating_add(stream.seq_at())) else {
                return if quiet || end > WINDOW {
                    Ok(false)
                } else {
                    Err(more(end, buf))
                };
            };
            if counts.rel(stream, *seq, at) == Rel::Continues {
                return Ok(true);
            }
        }
        Ok(false)
    }
}

/// Whether `delta` is a step wider than a stream's first step may be ([`FIRST_STEP_MAX`]) and
/// still a step on (any up to 255: a count stepping down by one steps by 255).
fn wide(delta: u8) -> bool {
    delta > FIRST_STEP_MAX
}

/// Not before `end` bytes are in the window that holds `buf`.
fn more(end: usize, buf: &[u8]) -> Wait {
    Wait::Bytes(u8::try_from(end.saturating_sub(buf.len())).unwrap_or(u8::MAX))
}

/// Not decided: `wait`, unless the window is already full.
fn undecided(buf: &[u8], wait: Wait) -> Result<bool, Wait> {
    if buf.len() >= WINDOW {
        Ok(false)
    } else {
        Err(wait)
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
