//! Scoring a downlink parser against what was sent through a channel.
//!
//! * A frame is **recalled** when the channel left it untouched and the parser emitted it, equal,
//!   at its place.
//! * An emitted frame is **false** when it does not start where a sent frame of its kind
//!   started. (A frame the channel damaged, emitted at its own place, is *damaged*, not false:
//!   without a checksum nobody can tell.) One exception: a frame equal, byte for byte, to the
//!   sent frame that ends where it ends is that frame, *damaged*, even if its first byte is not
//!   the one the board sent: an `FF` inserted between a header's `FF` and its second byte, or a
//!   header's `FF` lost right after a byte `FF`, leaves the frame's bytes whole behind another
//!   `FF`. What comes out is what the board sent.
//! * **Latency** is how many bytes after a frame's last byte the parser emitted it.

use crate::board::{Gap, Read, SentFrame};
use crate::channel::Received;
use chassis_protocol::{Downlink, DownlinkParser, DownlinkStats, Lock};
use std::collections::HashMap;

/// The figures of one run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Score {
    /// Frames sent.
    pub sent: usize,
    /// Frames the channel left untouched.
    pub untouched: usize,
    /// Untouched frames emitted equal at their place.
    pub recalled: usize,
    /// Emitted frames that start where no sent frame of their kind started.
    pub false_frames: usize,
    /// Damaged frames emitted at their place.
    pub damaged: usize,
    /// Error events in the channel.
    pub errors: usize,
    /// Sum of the latencies of recalled frames, in bytes.
    pub latency_sum: usize,
    /// Largest latency of a recalled frame, in bytes.
    pub latency_max: usize,
    /// Recalled frames emitted on their last byte while the parser was Locked.
    pub on_time_locked: usize,
    /// Recalled frames whose last byte arrived while the parser was Locked.
    pub recalled_locked: usize,
    /// The parser's own counters at the end.
    pub stats: DownlinkStats,
}

impl Score {
    /// Share of untouched frames recalled.
    pub fn recall(&self) -> f64 {
        if self.untouched == 0 {
            1.0
        } else {
            self.recalled as f64 / self.untouched as f64
        }
    }

    /// False frames per million frames sent.
    pub fn false_per_million(&self) -> f64 {
        self.false_frames as f64 * 1e6 / self.sent.max(1) as f64
    }

    /// Untouched frames lost per channel error.
    pub fn lost_per_error(&self) -> f64 {
        (self.untouched - self.recalled) as f64 / self.errors.max(1) as f64
    }

    /// Mean latency of recalled frames, in bytes.
    pub fn mean_latency(&self) -> f64 {
        self.latency_sum as f64 / self.recalled.max(1) as f64
    }

    /// The figures before a run of `rx`, the channel's output for `sent`: nothing emitted yet.
    pub(crate) fn start(sent: &[SentFrame], rx: &Received) -> Score {
        Score {
            sent: sent.len(),
            errors: rx.errors,
            ..Score::default()
        }
    }

    /// The figures after the run: the frames the channel left untouched, the parser's counters.
    pub(crate) fn finish(
        mut self,
        sent: &[SentFrame],
        rx: &Received,
        parser: &DownlinkParser,
    ) -> Score {
        self.untouched = sent
            .iter()
            .filter(|f| rx.untouched(f.start, f.end()))
            .count();
        self.stats = *parser.stats();
        self
    }

    /// Adds another run's figures.
    pub fn add(&mut self, other: &Score) {
        self.sent += other.sent;
        self.untouched += other.untouched;
        self.recalled += other.recalled;
        self.false_frames += other.false_frames;
        self.damaged += other.damaged;
        self.errors += other.errors;
        self.latency_sum += other.latency_sum;
        self.latency_max = self.latency_max.max(other.latency_max);
        self.on_time_locked += other.on_time_locked;
        self.recalled_locked += other.recalled_locked;
    }
}

/// Runs `rx` through a new downlink parser, one byte at a time, then tells it the line went
/// quiet, and scores what it emits against `sent`.
pub fn score_downlink(sent: &[SentFrame], rx: &Received) -> Score {
    score_downlink_with_gaps(sent, rx, &[])
}

/// [`score_downlink`], with the parser told of every quiet stretch of the line
/// ([`DownlinkParser::quiet`], with its length) before the first received byte that was sent
/// after it.
pub fn score_downlink_with_gaps(sent: &[SentFrame], rx: &Received, gaps: &[Gap]) -> Score {
    score_downlink_listening(sent, rx, gaps, &[])
}

/// [`score_downlink_with_gaps`], with the parser also told of every read the master sent
/// ([`DownlinkParser::expect_reply`]) before the first received byte sent from the read's
/// `from` on, and told it gave up waiting (`None`) at its `until`, as the driver does.
pub fn score_downlink_listening(
    sent: &[SentFrame],
    rx: &Received,
    gaps: &[Gap],
    reads: &[Read],
) -> Score {
    score_downlink_traced(sent, rx, gaps, reads, &mut |_| {})
}

/// A false frame the parser emitted: the frame, and where its first and last bytes are in the
/// received stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FalseFrame {
    /// The frame.
    pub frame: Downlink,
    /// Offset of its first byte in the received bytes.
    pub start: usize,
    /// Offset of its last byte in the received bytes.
    pub end: usize,
}

/// [`score_downlink_listening`], handing each false frame to `on_false` as it is judged.
pub fn score_downlink_traced(
    sent: &[SentFrame],
    rx: &Received,
    gaps: &[Gap],
    reads: &[Read],
    on_false: &mut dyn FnMut(FalseFrame),
) -> Score {
    let mut score = Score::start(sent, rx);
    let mut parser = DownlinkParser::new();
    let mut judge = Judge::new(sent, rx);
    let mut judge = |frame: Downlink, end: usize, now: usize, locked: bool, score: &mut Score| {
        judge.judge(frame, (end, now, locked), score, on_false);
    };

    // Whether the parser was Locked when each received byte arrived.
    let mut locked_at = Vec::with_capacity(rx.bytes.len());
    let mut gaps = gaps.iter().peekable();
    let mut reads = reads.iter().peekable();
    let mut awaited: Option<Read> = None;
    for (now, byte) in rx.bytes.iter().enumerate() {
        if let Some(origin) = rx.origin.get(now).copied().flatten() {
            let mut quiet_ms = 0;
            while let Some(gap) = gaps.next_if(|g| g.offset <= origin) {
                quiet_ms += gap.ms;
            }
            if quiet_ms > 0 {
                let end = now.saturating_sub(1);
                while let Some(frame) = parser.quiet(quiet_ms) {
                    let at = end - parser.buffered();
                    let locked = locked_at.get(at).copied().unwrap_or(false);
                    judge(frame, at, end, locked, &mut score);
                }
            }
            while let Some(read) = reads.next_if(|r| r.from <= origin) {
                parser.expect_reply(Some(read.register));
                awaited = Some(*read);
            }
            if awaited.is_some_and(|r| r.until <= origin) {
                parser.expect_reply(None);
                awaited = None;
            }
        }
        locked_at.push(parser.lock() == Lock::Locked);
        let mut out = parser.push(*byte);
        while let Some(frame) = out {
            let end = now - parser.buffered();
            judge(frame, end, now, locked_at[end], &mut score);
            // A chain can prove several frames at once: drain them on this byte.
            out = parser.poll();
        }
    }
    let now = rx.bytes.len().saturating_sub(1);
    while let Some(frame) = parser.idle() {
        let end = now - parser.buffered();
        judge(frame, end, now, locked_at[end], &mut score);
    }
    score.finish(sent, rx, &parser)
}

/// Judges each frame a parser emits against what was sent and what the channel did to it.
pub(crate) struct Judge<'a> {
    sent: &'a [SentFrame],
    rx: &'a Received,
    by_start: HashMap<usize, usize>,
    by_last: HashMap<usize, usize>,
    emitted_at: Vec<bool>,
}

impl<'a> Judge<'a> {
    /// A judge of frames parsed from `rx`, the channel's output for `sent`.
    pub(crate) fn new(sent: &'a [SentFrame], rx: &'a Received) -> Self {
        Judge {
            sent,
            rx,
            by_start: sent.iter().enumerate().map(|(i, f)| (f.start, i)).collect(),
            by_last: sent
                .iter()
                .enumerate()
                .map(|(i, f)| (f.end().saturating_sub(1), i))
                .collect(),
            emitted_at: vec![false; sent.len()],
        }
    }

    /// Counts `frame`, whose last byte is received byte `end`, emitted when byte `now` was
    /// in, with the parser Locked (`locked`) when `end` arrived, into `score`.
    pub(crate) fn judge(
        &mut self,
        frame: Downlink,
        (end, now, locked): (usize, usize, bool),
        score: &mut Score,
        on_false: &mut dyn FnMut(FalseFrame),
    ) {
        let len = frame.encode().len();
        let start = (end + 1).saturating_sub(len);
        let origin = |at: usize| self.rx.origin.get(at).copied().flatten();
        let place = origin(start).and_then(|s| self.by_start.get(&s).copied());
        match place {
            Some(i) if self.sent[i].frame.kind() == frame.kind() => {
                let original = &self.sent[i];
                if self.rx.untouched(original.start, original.end())
                    && original.frame == frame
                    && !self.emitted_at[i]
                {
                    self.emitted_at[i] = true;
                    score.recalled += 1;
                    let latency = now - end;
                    score.latency_sum += latency;
                    score.latency_max = score.latency_max.max(latency);
                    if locked {
                        score.recalled_locked += 1;
                        score.on_time_locked += usize::from(latency == 0);
                    }
                } else {
                    score.damaged += 1;
                }
            }
            _ => {
                // The sent frame's bytes, whole, behind another `FF` (see the module docs).
                let whole = origin(end)
                    .and_then(|last| self.by_last.get(&last))
                    .is_some_and(|i| self.sent[*i].frame == frame);
                if whole {
                    score.damaged += 1;
                } else {
                    score.false_frames += 1;
                    on_false(FalseFrame { frame, start, end });
                }
            }
        }
    }
}

/// What starting to listen in the middle of a clean stream costs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Startup {
    /// Start offsets tried.
    pub starts: usize,
    /// Starts after which every frame following the first complete one came out.
    pub all_after_first: usize,
    /// Most frames after the first complete one lost by any start.
    pub worst_lost: usize,
    /// Starts that emitted at least one false frame.
    pub with_false: usize,
    /// False frames emitted, in all.
    pub false_frames: usize,
}

/// Starts a new parser at every offset of the first three frames of `seeds` clean streams of
/// `frames` frames, and counts what the starts cost.
pub fn startup(seeds: std::ops::Range<u64>, frames: usize) -> Startup {
    starts(seeds.map(|seed| {
        let (bytes, sent) = crate::BoardStream::new(seed, 2.0).take(frames.max(4));
        // Back to back: the line goes quiet only at the end.
        let ends = vec![bytes.len()];
        (bytes, sent, ends)
    }))
}

/// [`startup`] over the board simulator's output with the line going quiet between the bursts
/// the board sends, and the parser told so with [`DownlinkParser::idle`] after each (as the
/// driver does after 2 ms without a byte): every offset of the first three frames of `seeds`
/// streams of `frames` frames.
pub fn startup_with_idle(seeds: std::ops::Range<u64>, frames: usize) -> Startup {
    starts(seeds.map(|seed| crate::board::simulator_bursts(seed, frames.max(4))))
}

/// Every start offset in the first three frames of each stream (bytes, frames sent, where the
/// line goes quiet), the parser told of each quiet line with `idle()`.
fn starts(streams: impl Iterator<Item = (Vec<u8>, Vec<SentFrame>, Vec<usize>)>) -> Startup {
    let mut figures = Startup::default();
    for (bytes, sent, quiet_at) in streams {
        let Some(third) = sent.get(3) else {
            continue;
        };
        for offset in 0..third.start {
            let first = sent
                .iter()
                .position(|f| f.start >= offset)
                .unwrap_or(sent.len());
            let mut parser = DownlinkParser::new();
            let mut out: Vec<Downlink> = Vec::new();
            let mut from = offset;
            for &end in quiet_at.iter().filter(|end| **end > offset) {
                out.extend(parser.frames(&bytes[from..end]));
                out.extend(std::iter::from_fn(|| parser.idle()));
                from = end;
            }
            let expected: Vec<Downlink> = sent[first..].iter().map(|f| f.frame).collect();
            figures.add_start(&out, &expected);
        }
    }
    figures
}

impl Startup {
    /// Counts one start: what the parser emitted against the frames from the first complete one.
    fn add_start(&mut self, out: &[Downlink], expected: &[Downlink]) {
        let false_frames = out.iter().filter(|f| !expected.contains(f)).count();
        let lost = expected.iter().skip(1).filter(|f| !out.contains(f)).count();
        self.starts += 1;
        self.all_after_first += usize::from(lost == 0);
        self.worst_lost = self.worst_lost.max(lost);
        self.with_false += usize::from(false_frames > 0);
        self.false_frames += false_frames;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::board::BoardStream;
    use crate::channel::{Noise, transmit};
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    #[test]
    fn a_clean_stream_is_recalled_whole_and_on_time_once_locked() {
        let (bytes, sent) = BoardStream::new(3, 2.0).take(5_000);
        let rx = transmit(&bytes, &Noise::default(), &mut Pcg64Mcg::seed_from_u64(0));
        let score = score_downlink(&sent, &rx);
        assert_eq!(score.untouched, 5_000);
        assert_eq!(score.recalled, 5_000);
        assert_eq!(score.false_frames, 0);
        assert_eq!(score.damaged, 0);
        // Replies nobody awaits (this stream model sends them with no read) wait for the next
        // frame's count to vouch for them; each stream's first frame waits two bytes; all else
        // is on time.
        assert!(
            score.on_time_locked as f64 > 0.96 * score.recalled_locked as f64,
            "{score:?}"
        );
    }

    #[test]
    fn a_sent_frame_whole_behind_an_inserted_ff_is_damaged_not_false() {
        let (bytes, sent) = BoardStream::new(3, 2.0).take(200);
        let clean = transmit(&bytes, &Noise::default(), &mut Pcg64Mcg::seed_from_u64(0));
        // An `FF` inserted between the header bytes of an IMU frame well into the stream.
        let imu = sent
            .iter()
            .skip(100)
            .find(|f| matches!(f.frame, Downlink::Imu(_)))
            .expect("an IMU frame");
        let at = imu.start + 1;
        let mut rx = clean.clone();
        rx.bytes.insert(at, 0xFF);
        rx.origin.insert(at, None);
        rx.touched[at] = true;
        rx.errors = 1;
        let score = score_downlink(&sent, &rx);
        assert_eq!(score.untouched, 199);
        assert_eq!(score.false_frames, 0, "{score:?}");
        assert_eq!(score.damaged, 1, "{score:?}");
        assert_eq!(score.recalled, 199, "{score:?}");
    }

    #[test]
    fn a_noisy_stream_is_scored_against_the_channel() {
        let (bytes, sent) = BoardStream::new(4, 2.0).take(20_000);
        let rx = transmit(&bytes, &Noise::mixed(1e-3), &mut Pcg64Mcg::seed_from_u64(5));
        let score = score_downlink(&sent, &rx);
        assert!(score.errors > 100);
        assert!(score.untouched < score.sent);
        assert!(score.recall() > 0.99, "{score:?}");
    }
}
