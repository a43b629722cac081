//! [`Counts`]: what the count bytes have taught the parser.
//!
//! The vendor does not say what the count byte counts (A10): one counter per stream stepping by
//! 1, by some k, one counter shared by all streams, a time tick. So nothing is assumed beyond
//! "it moves on from frame to frame in a way the line shows": for each stream the parser
//! remembers its last count and **learns the steps** it has seen between consecutive frames
//! (up to [`STEPS`] of them: a shared counter gives the IMU steps of 1, 2 and 3, a time tick
//! the encoders a step of 4). A count **continues** its stream when it is one learnt step on;
//! it is **near** when it is a few steps on (frames lost: as many as the bytes and the quiet
//! time since the stream's last frame can hold, [`LOST_UNSEEN`] more if bytes were thrown away
//! since); otherwise it is **far**. A stream with no step learnt yet takes any step from 1 to
//! [`FIRST_STEP_MAX`] as continuing.
//!
//! **Steps are learnt only from a line that lost nothing** since the stream's last frame (no
//! byte thrown away, no quiet stretch as long as the stream's period): after a loss, a count
//! may have moved on by frames lost, and a step learnt from that would let false frames' counts
//! through for good. On such a line a near count cannot be frames lost: seen twice, its
//! distance is a step ([`Counts::take_near`]). (A board that sends each IMU frame in its own
//! burst leaves a quiet stretch shorter than 10 ms before every IMU frame: a step learnt only
//! from an unbroken line was never learnt there.)

use crate::telemetry::Stream;

/// Steps remembered per stream.
pub const STEPS: usize = 4;

/// While a stream has no step learnt, a count this far on (or less) continues it.
pub const FIRST_STEP_MAX: u8 = 4;

/// Fewest bytes of the line per frame of each stream (IMU, encoders, battery), rounded down
/// from the board's rates (100 / 25 / 1 Hz, 1 782 bytes/s in all at most): each such stretch
/// received since the stream's last frame allows one more lost frame.
pub const BYTES_PER_FRAME: [u16; 3] = [15, 60, 1_500];

/// The streams' periods in ms: each period of quiet line allows one more lost frame.
pub const PERIOD_MS: [u16; 3] = [10, 40, 1_000];

/// Lost frames allowed at most, however long the silence: a count this many steps on is still
/// near, never more (so the count check never vanishes).
pub const MAX_LOST: u16 = 64;

/// Frames a stream may have lost unseen when bytes were thrown away since its last frame.
pub const LOST_UNSEEN: u16 = 2;

/// How a count relates to its stream's last one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rel {
    /// No count known for the stream.
    Unknown,
    /// One learnt step on.
    Continues,
    /// A few steps on: frames were lost.
    Near,
    /// Anything else.
    Far,
}

/// One learnt step and how often it was seen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Step {
    delta: u8,
    hits: u8,
}

/// What the counts have taught the parser, per stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(align(4))]
pub struct Counts {
    /// Bit `i`: stream `i` has a count.
    known: u8,
    /// Bit `i`: stream `i`'s count was continued by a frame of its own (see [`Counts::rel`]).
    confirmed: u8,
    last: [u8; 3],
    steps: [[Step; STEPS]; 3],
    /// Bytes received since each stream's last frame (saturating).
    since: [u16; 3],
    /// Quiet time since each stream's last frame, in ms (saturating).
    quiet_ms: [u16; 3],
    /// Per stream, a far count taken but not believed (see [`Counts::skip`]): if the stream's
    /// next frame continues it instead, the board really moved its count on, and the count
    /// follows it.
    alt: [Option<u8>; 3],
    /// Per stream, how far the far count in `alt` was from the count before it: a step the
    /// board really takes once the stream's next frame continues `alt`.
    alt_step: [u8; 3],
    /// Bit `i`: no byte was thrown away since stream `i`'s last frame (see
    /// [`Counts::take_near`]).
    lossless: u8,
    /// Per stream, the last near count's distance from the count before it, when nothing was
    /// lost in between (0: none).
    near_delta: [u8; 3],
}

impl Default for Counts {
    fn default() -> Self {
        Self::new()
    }
}

impl Counts {
    /// Nothing learnt yet.
    pub const fn new() -> Self {
        Counts {
            known: 0,
            confirmed: 0,
            last: [0; 3],
            steps: [[Step { delta: 0, hits: 0 }; STEPS]; 3],
            since: [0; 3],
            quiet_ms: [0; 3],
            alt: [None; 3],
            alt_step: [0; 3],
            lossless: 0,
            near_delta: [0; 3],
        }
    }

    /// Whether any stream has a count.
    pub const fn any_known(&self) -> bool {
        self.known != 0
    }

    /// Whether a frame of `stream` starting `bytes` after the start of another frame of its own
    /// comes sooner than the board's rates allow ([`BYTES_PER_FRAME`]) on a line that carries
    /// IMU frames: both cannot be real. The IMU frames space the others (the encoders' next
    /// frame comes after four of them, the battery's a second later), while lookalikes in a
    /// payload come back to back. (A line of one stream only may carry it back to back.)
    pub fn too_soon(&self, stream: Stream, bytes: usize) -> bool {
        let fewest = BYTES_PER_FRAME.get(stream.index()).copied().unwrap_or(0);
        self.knows(Stream::Imu) && bytes < usize::from(fewest)
    }

    /// Whether `stream` has a count.
    pub const fn knows(&self, stream: Stream) -> bool {
        self.known & (1 << stream.index()) != 0
    }

    /// Whether `stream` has a step learnt.
    pub fn has_steps(&self, stream: Stream) -> bool {
        self.steps
            .get(stream.index())
            .is_some_and(|steps| steps.iter().any(|s| s.hits > 0))
    }

    /// Whether `delta` is one of `stream`'s learnt steps.
    pub fn is_step(&self, stream: Stream, delta: u8) -> bool {
        self.step_of(stream.index(), delta).is_some()
    }

    /// Which of stream `i`'s learnt steps is `delta`, if one is.
    #[inline]
    fn step_of(&self, i: usize, delta: u8) -> Option<usize> {
        // (A step never learnt has delta 0 and no hits; a learnt one, a delta of 1 to 127 and
        // hits that only grow: so `delta` names a learnt step when it is not 0.)
        if delta == 0 {
            return None;
        }
        self.steps.get(i)?.iter().position(|s| s.delta == delta)
    }

    /// Whether `delta` divides one of stream `i`'s learnt steps (a shared counter steps a stream
    /// by multiples of one step).
    fn divides_a_step(&self, i: usize, delta: u8) -> bool {
        self.steps.get(i).is_some_and(|steps| {
            steps
                .iter()
                .any(|s| s.hits > 0 && s.delta.checked_rem(delta) == Some(0))
        })
    }

    /// Stream `i`'s smallest learnt step (1 if none).
    fn smallest_step(&self, i: usize) -> u8 {
        self.steps
            .get(i)
            .and_then(|steps| steps.iter().filter(|s| s.hits > 0).map(|s| s.delta).min())
            .unwrap_or(1)
    }

    /// `stream`'s last count (0 if none).
    pub fn last(&self, stream: Stream) -> u8 {
        self.last.get(stream.index()).copied().unwrap_or(0)
    }

    /// Frames of `stream` that may have been lost since its last one, `extra` bytes further on.
    fn lost_allowed(&self, stream: Stream, extra: usize) -> u16 {
        let i = stream.index();
        let since = self.since.get(i).copied().unwrap_or(u16::MAX);
        let since = since.saturating_add(u16::try_from(extra).unwrap_or(u16::MAX));
        let per = BYTES_PER_FRAME.get(i).copied().unwrap_or(u16::MAX).max(1);
        let quiet = self.quiet_ms.get(i).copied().unwrap_or(0);
        let period = PERIOD_MS.get(i).copied().unwrap_or(u16::MAX).max(1);
        // Rounded up: a frame that lost a byte or two is a frame lost.
        let by_bytes = since
            .saturating_add(per.saturating_sub(1))
            .checked_div(per)
            .unwrap_or(0);
        let by_time = quiet.checked_div(period).unwrap_or(0);
        // Bytes thrown away since: the line may have lost more than it shows (an overrun
        // drops whole stretches, which no byte count sees).
        let by_loss = if self.clean(i) { 0 } else { LOST_UNSEEN };
        by_bytes
            .saturating_add(by_time)
            .saturating_add(u16::from(quiet > 0))
            .saturating_add(by_loss)
            .min(MAX_LOST)
    }

    /// How `count` relates to `stream`'s last count, for a frame that starts `extra` bytes after
    /// the bytes counted so far.
    ///
    /// A count no frame of its stream has continued yet (the stream's first frame since the
    /// counts were forgotten) is a guess: it may be a false frame's, passed over in a chain
    /// while the line was damaged. A count far from a guess is no evidence against its frame,
    /// so it is [`Rel::Unknown`], as if the guess had not been made (the battery's count, once a
    /// second, would otherwise hold a false count for a whole second).
    pub fn rel(&self, stream: Stream, count: u8, extra: usize) -> Rel {
        if !self.knows(stream) {
            return Rel::Unknown;
        }
        match self.rel_known(stream, count, extra) {
            Rel::Far if self.confirmed & (1 << stream.index()) == 0 => Rel::Unknown,
            rel => rel,
        }
    }

    /// [`rel`](Self::rel) for a stream with a count, confirmed or not.
    fn rel_known(&self, stream: Stream, count: u8, extra: usize) -> Rel {
        let i = stream.index();
        let last = self.last.get(i).copied().unwrap_or(0);
        let delta = count.wrapping_sub(last);
        if delta == 0 {
            return Rel::Far;
        }
        let Some(steps) = self.steps.get(i) else {
            return Rel::Far;
        };
        let mut any = false;
        for step in steps {
            if step.hits > 0 {
                if step.delta == delta {
                    return Rel::Continues;
                }
                any = true;
            }
        }
        let learnt = steps.iter().filter(|s| s.hits > 0);
        if !any && delta <= FIRST_STEP_MAX {
            return Rel::Continues;
        }
        if self.continues_alt(stream, count) {
            return Rel::Continues;
        }
        let lost = self.lost_allowed(stream, extra);
        let near = |step: u8| {
            (2..=lost.saturating_add(1))
                .any(|k| u16::from(step).saturating_mul(k) % 256 == u16::from(delta))
        };
        if any {
            if learnt.map(|s| s.delta).any(near) {
                return Rel::Near;
            }
        } else if (1..=FIRST_STEP_MAX).any(near) {
            return Rel::Near;
        }
        Rel::Far
    }

    /// Whether `count` is one step on from `stream`'s remembered far count: a learnt step, or
    /// the step that far count took from the count before it, seen again on a line that lost
    /// nothing (a shared counter steps the IMU by 4 across an encoder frame, then by 2: the
    /// 2 is far until it is seen twice).
    fn continues_alt(&self, stream: Stream, count: u8) -> bool {
        let i = stream.index();
        let Some(Some(alt)) = self.alt.get(i).copied() else {
            return false;
        };
        let delta = count.wrapping_sub(alt);
        if delta != 0 && self.alt_step.get(i) == Some(&delta) && self.divides_a_step(i, delta) {
            return true;
        }
        if !self.has_steps(stream) {
            return (1..=FIRST_STEP_MAX).contains(&delta);
        }
        self.step_of(i, delta).is_some()
    }

    /// The learnt step `count` takes `stream` on by, when nothing else has to be weighed: the
    /// stream has a count, no far count is pending, and `count` is one learnt step on. Then
    /// [`rel`](Self::rel) says [`Rel::Continues`], and [`take_step`](Self::take_step) does what
    /// [`take`](Self::take) would. `None`: ask `rel`.
    #[inline]
    pub fn learnt_step(&self, stream: Stream, count: u8) -> Option<usize> {
        let i = stream.index();
        if self.known & (1 << i) == 0 || !matches!(self.alt.get(i), Some(None)) {
            return None;
        }
        self.step_of(i, count.wrapping_sub(*self.last.get(i)?))
    }

    /// [`take`](Self::take) for a count one learnt step on (`step`, from
    /// [`learnt_step`](Self::learnt_step)): the step is seen once more, the count confirmed.
    #[inline]
    pub fn take_step(&mut self, stream: Stream, step: usize, count: u8) {
        let i = stream.index();
        if let Some(s) = self.steps.get_mut(i).and_then(|steps| steps.get_mut(step)) {
            s.hits = s.hits.saturating_add(1);
        }
        self.confirmed |= 1 << i;
        self.set_last(i, count);
    }

    /// A frame of `stream` whose count is near (frames lost, see [`Rel::Near`]) was taken; `true`
    /// if its distance is learnt as a step instead.
    ///
    /// Frames lost explain a near count only if the line lost something. When no byte was
    /// thrown away and the line was not quiet for as long as the stream's period since its last
    /// frame, every byte in between was a frame taken and no frame of the stream fitted in the
    /// quiet: none of this stream's can be missing, and the board stepped
    /// its count by that much (one counter shared by all streams steps the IMU by 2 when an
    /// encoder frame came between, a multiple of its usual 1). The same distance seen twice
    /// that way is learnt; once may still be a frame lost whole with nothing else damaged.
    pub fn take_near(&mut self, stream: Stream, count: u8) -> bool {
        let i = stream.index();
        let delta = count.wrapping_sub(self.last(stream));
        let period = PERIOD_MS.get(i).copied().unwrap_or(0);
        let clean = self.clean(i) && self.quiet_ms.get(i).is_some_and(|q| *q < period);
        let Some(seen) = self.near_delta.get_mut(i) else {
            return false;
        };
        let again = clean && *seen == delta;
        *seen = if clean && !again { delta } else { 0 };
        self.take(stream, count, again);
        again
    }

    /// Whether no byte was thrown away since stream `i`'s last frame.
    fn clean(&self, i: usize) -> bool {
        self.lossless & (1 << i) != 0
    }

    /// A byte was thrown away: a near count after it may be frames lost.
    pub fn discarded(&mut self) {
        self.lossless = 0;
    }

    /// Stream `i`'s count is now `count`, seen just now.
    #[inline]
    fn set_last(&mut self, i: usize, count: u8) {
        self.lossless |= 1 << i;
        self.known |= 1 << i;
        if let Some(l) = self.last.get_mut(i) {
            *l = count;
        }
        if let Some(s) = self.since.get_mut(i) {
            *s = 0;
        }
        if let Some(q) = self.quiet_ms.get_mut(i) {
            *q = 0;
        }
    }

    /// A frame of `stream` went by whose count byte cannot be read (the frame is damaged):
    /// the stream moves on by its smallest step, as if the count had continued. For judging
    /// what follows it, on a copy.
    pub fn passed(&mut self, stream: Stream) {
        let i = stream.index();
        if self.knows(stream) {
            let next = self.last(stream).wrapping_add(self.smallest_step(i));
            self.set_last(i, next);
        }
    }

    /// A frame of `stream` with `count` was taken. `learn`: its step, if new, is one the line
    /// really takes (the frame was taken on evidence that does not rest on its count).
    ///
    /// A new step is learnt only if the line lost nothing since the stream's last frame (see
    /// [`take_near`](Self::take_near)): after a loss, a count that moved on by an unknown amount
    /// may be frames lost (under a shared counter, the encoders' 5 + 6 = 11 when one of them was
    /// lost), and a step learnt from that lets false frames' counts through for good.
    pub fn take(&mut self, stream: Stream, count: u8, learn: bool) {
        let i = stream.index();
        let bit = 1u8 << i;
        let clean = self.clean(i);
        // (Most frames have no far count pending: skip the check then.)
        let rebased = matches!(self.alt.get(i), Some(Some(_))) && self.continues_alt(stream, count);
        if let Some(alt) = self.alt.get_mut(i) {
            *alt = None;
        }
        if self.known & bit == 0 {
            self.confirmed &= !bit;
        } else {
            // Re-based: the far count was real, and the step to it is one the board takes (a
            // shared counter steps the encoders by 6 when a battery frame came between).
            let delta = if rebased {
                self.alt_step.get(i).copied().unwrap_or(0)
            } else {
                count.wrapping_sub(self.last.get(i).copied().unwrap_or(0))
            };
            if let Some(steps) = self.steps.get_mut(i) {
                let none_learnt = steps.iter().all(|s| s.hits == 0);
                if let Some(step) = steps.iter_mut().find(|s| s.hits > 0 && s.delta == delta) {
                    if !rebased {
                        step.hits = step.hits.saturating_add(1);
                    }
                    self.confirmed |= bit;
                } else {
                    if rebased || (none_learnt && (1..=FIRST_STEP_MAX).contains(&delta)) {
                        self.confirmed |= bit;
                    }
                    // (A re-based step was checked when its far count came: see `skip`.)
                    if learn && (clean || rebased) && (1..=127).contains(&delta) {
                        // Replace the least seen step.
                        if let Some(slot) = steps.iter_mut().min_by_key(|s| s.hits) {
                            *slot = Step { delta, hits: 1 };
                        }
                    }
                }
            }
        }
        self.set_last(i, count);
    }

    /// A frame of `stream` came whose count byte is not to be believed (a far count taken on a
    /// certain boundary, its stream's next frame not vouching for it): the stream moves on by
    /// its smallest step, as if the count had continued.
    pub fn skip(&mut self, stream: Stream, count: u8) {
        let i = stream.index();
        // Two far counts in a row on certain boundaries: the board's count is there (it moved
        // on, was wrongly learnt, or steps by more than was learnt: a shared counter steps the
        // encoders by 5 or 6, a time tick the battery by 100). Follow it, and learn the step.
        if let Some(Some(alt)) = self.alt.get(i).copied() {
            let delta = count.wrapping_sub(alt);
            if (1..=127).contains(&delta) {
                if let Some(l) = self.last.get_mut(i) {
                    *l = alt;
                }
                if let Some(a) = self.alt.get_mut(i) {
                    *a = None;
                }
                self.take(stream, count, true);
                return;
            }
        }
        if let Some(alt) = self.alt.get_mut(i) {
            *alt = Some(count);
        }
        // (A step only from a line that lost nothing; 0 is no step.)
        let alt_step = if self.clean(i) {
            count.wrapping_sub(self.last.get(i).copied().unwrap_or(count))
        } else {
            0
        };
        if let Some(slot) = self.alt_step.get_mut(i) {
            *slot = alt_step;
        }
        let last = self.last(stream).wrapping_add(self.smallest_step(i));
        self.set_last(i, last);
    }

    /// `n` more bytes received.
    pub fn bytes(&mut self, n: usize) {
        let n = u16::try_from(n).unwrap_or(u16::MAX);
        // (Written out: a loop of three is not unrolled at opt-level "s", and this runs on
        // every frame.)
        let [imu, encoders, battery] = &mut self.since;
        *imu = imu.saturating_add(n);
        *encoders = encoders.saturating_add(n);
        *battery = battery.saturating_add(n);
    }

    /// The line was quiet for `ms`.
    pub fn quiet(&mut self, ms: u32) {
        let ms = u16::try_from(ms).unwrap_or(u16::MAX).max(1);
        for q in &mut self.quiet_ms {
            *q = q.saturating_add(ms);
        }
    }

    /// Forgets every count (the steps learnt stay: the board's counting does not change).
    pub fn forget(&mut self) {
        self.known = 0;
    }

    /// Bytes since the most recent frame of any stream.
    pub fn since_any(&self) -> u16 {
        self.since.iter().copied().min().unwrap_or(u16::MAX)
    }

    /// The number of frames a count `delta` on from the last one says were missed (0 when it
    /// continues; a guess from the smallest learnt step).
    pub fn missed(&self, stream: Stream, count: u8) -> u8 {
        let delta = count.wrapping_sub(self.last(stream));
        let step = self.smallest_step(stream.index()).max(1);
        delta.checked_div(step).unwrap_or(0).saturating_sub(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Counts that have taken `counts` of `stream`, in order, each teaching its step.
    fn seen(stream: Stream, counts: &[u8]) -> Counts {
        let mut c = Counts::new();
        for count in counts {
            c.take(stream, *count, true);
        }
        c
    }

    #[test]
    fn steps_are_learnt_from_the_line() {
        let mut c = Counts::new();
        assert_eq!(c.rel(Stream::Encoders, 10, 0), Rel::Unknown);
        c.take(Stream::Encoders, 10, true);
        // No step learnt yet: 1..=4 on continues; a count far from a first one, which nothing
        // has confirmed, says nothing.
        assert_eq!(c.rel(Stream::Encoders, 14, 0), Rel::Continues);
        assert_eq!(c.rel(Stream::Encoders, 30, 0), Rel::Unknown);
        c.take(Stream::Encoders, 14, true);
        // A tick of 4 per frame: learnt, and the count confirmed.
        assert_eq!(c.rel(Stream::Encoders, 18, 0), Rel::Continues);
        assert_eq!(c.rel(Stream::Encoders, 15, 0), Rel::Far);
        assert_eq!(c.rel(Stream::Encoders, 30, 0), Rel::Far);
        // Two frames lost need the bytes to have held them.
        assert_eq!(c.rel(Stream::Encoders, 26, 0), Rel::Far);
        assert_eq!(c.rel(Stream::Encoders, 26, 130), Rel::Near);
    }

    #[test]
    fn a_count_is_a_guess_until_its_stream_continues_it() {
        let mut c = Counts::new();
        c.take(Stream::Battery, 232, false);
        assert_eq!(c.rel(Stream::Battery, 9, 0), Rel::Unknown);
        // Taken as a stream's first again: still a guess.
        c.take(Stream::Battery, 9, false);
        assert_eq!(c.rel(Stream::Battery, 200, 0), Rel::Unknown);
        c.take(Stream::Battery, 10, false);
        assert_eq!(c.rel(Stream::Battery, 200, 0), Rel::Far);
        // Forgotten and seen again: a guess again.
        c.forget();
        c.take(Stream::Battery, 50, false);
        assert_eq!(c.rel(Stream::Battery, 200, 0), Rel::Unknown);
    }

    #[test]
    fn a_far_count_the_stream_then_continues_teaches_its_step() {
        // One counter shared by all streams: the encoders usually step by 5, by 6 when a
        // battery frame came between.
        let mut c = seen(Stream::Encoders, &[0, 5, 10]);
        assert_eq!(c.rel(Stream::Encoders, 16, 0), Rel::Far);
        // Taken on a certain boundary but not believed; the next frame continues it.
        c.skip(Stream::Encoders, 16);
        assert_eq!(c.rel(Stream::Encoders, 21, 0), Rel::Continues);
        c.take(Stream::Encoders, 21, true);
        // The step of 6 is learnt: the next such frame continues.
        assert_eq!(c.rel(Stream::Encoders, 27, 0), Rel::Continues);
        assert_eq!(c.rel(Stream::Encoders, 26, 0), Rel::Continues);
    }

    #[test]
    fn a_far_count_whose_step_comes_again_and_divides_a_learnt_one_is_followed() {
        // One counter shared by IMU and encoder frames, stepping by 2: the IMU steps by 4
        // across an encoder frame, which is learnt first, then by 2 (found by an outside
        // attack: the 2 was never learnt, and an IMU frame ending `FF FA` was then thrown away).
        let mut c = seen(Stream::Imu, &[240, 244]);
        assert_eq!(c.rel(Stream::Imu, 246, 0), Rel::Far);
        // Not believed, so the stream moves on by its smallest step (4): to 248.
        c.skip(Stream::Imu, 246);
        // 248 is 246 plus the same 2 again: taken (a chain believed it), the far count was
        // real, and 2 is learnt.
        c.take(Stream::Imu, 248, true);
        assert!(c.is_step(Stream::Imu, 2));
        assert_eq!(c.rel(Stream::Imu, 250, 0), Rel::Continues);
        // A step seen twice that divides no learnt step teaches nothing (header-byte payloads
        // make such pairs): 3 is no divisor of 4.
        let mut c = seen(Stream::Imu, &[240, 244]);
        c.skip(Stream::Imu, 247);
        c.take(Stream::Imu, 250, true);
        assert!(!c.is_step(Stream::Imu, 3));
        assert_ne!(c.rel(Stream::Imu, 253, 0), Rel::Continues);
    }

    #[test]
    fn quiet_time_widens_but_never_removes_the_check() {
        let mut c = Counts::new();
        c.take(Stream::Imu, 200, true);
        c.take(Stream::Imu, 201, true);
        c.quiet(500);
        // 500 ms: up to ~51 IMU frames may have gone by.
        assert_eq!(c.rel(Stream::Imu, 201u8.wrapping_add(40), 0), Rel::Near);
        assert_eq!(c.rel(Stream::Imu, 201u8.wrapping_add(120), 0), Rel::Far);
    }

    #[test]
    fn a_shared_counter_teaches_several_steps() {
        let mut c = Counts::new();
        for (count, learn) in [(1u8, true), (2, true), (4, true), (5, true), (7, true)] {
            c.take(Stream::Imu, count, learn);
        }
        assert_eq!(c.rel(Stream::Imu, 8, 0), Rel::Continues);
        assert_eq!(c.rel(Stream::Imu, 9, 0), Rel::Continues);
        assert_eq!(c.rel(Stream::Imu, 7u8.wrapping_add(100), 0), Rel::Far);
    }

    #[test]
    fn a_near_count_on_a_line_that_lost_nothing_is_a_step_once_seen_twice() {
        let mut c = seen(Stream::Imu, &[10, 11, 12]);
        // +2 with 26 bytes between (an encoder frame): one frame lost, or a step.
        assert_eq!(c.rel(Stream::Imu, 14, 26), Rel::Near);
        assert!(!c.take_near(Stream::Imu, 14));
        c.take(Stream::Imu, 15, true);
        assert_eq!(c.rel(Stream::Imu, 17, 26), Rel::Near);
        assert!(c.take_near(Stream::Imu, 17));
        assert_eq!(c.rel(Stream::Imu, 19, 0), Rel::Continues);
        // After bytes thrown away, a near count is frames lost: nothing learnt.
        let mut c = seen(Stream::Imu, &[10, 11, 12]);
        assert!(!c.take_near(Stream::Imu, 14));
        c.take(Stream::Imu, 15, true);
        c.discarded();
        assert!(!c.take_near(Stream::Imu, 17));
        assert_ne!(c.rel(Stream::Imu, 19, 0), Rel::Continues);
    }

    #[test]
    fn no_step_is_learnt_across_bytes_thrown_away() {
        // Encoders under a shared counter step by 5; one lost gives 5 + 6 = 11.
        let mut c = seen(Stream::Encoders, &[0, 5, 10]);
        c.discarded();
        c.take(Stream::Encoders, 21, true);
        assert_eq!(c.rel(Stream::Encoders, 32, 0), Rel::Far);
        // The same distance on a line that lost nothing is a step.
        c.take(Stream::Encoders, 32, true);
        assert_eq!(c.rel(Stream::Encoders, 43, 0), Rel::Continues);
    }

    #[test]
    fn bytes_thrown_away_allow_frames_lost_unseen() {
        let mut c = seen(Stream::Imu, &[10, 11, 12]);
        // 30 bytes since: 2 IMU frames' worth, so up to 2 lost (+3 at most).
        assert_eq!(c.rel(Stream::Imu, 16, 30), Rel::Far);
        // Bytes were thrown away: an overrun may have taken more than the bytes show.
        c.discarded();
        assert_eq!(c.rel(Stream::Imu, 16, 30), Rel::Near);
    }
}
