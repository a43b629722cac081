//! Scoring `v1::DownlinkParser` against what the board sent through a [`Line`].
//!
//! Every frame the parser delivers is traced back to the received bytes it was made of (the
//! parser holds one frame's bytes at most; a delivered frame's last byte is the newest byte
//! less what it still holds), and from them to the sent bytes:
//!
//! * **in place**: its bytes are, one after the other, all the bytes of one sent frame, each
//!   possibly changed where it stood. Equal to that frame: delivered as sent (counted as
//!   **recovered** when the line left every byte of it intact). Not equal: **undetected
//!   corruption**, damage the BCC did not see.
//! * not in place, but equal byte for byte to a sent frame some of whose bytes it is made of:
//!   **reassembled**, what the board sent all the same (a 7D the line inserted right before a
//!   frame's own 7D; a dropout that joins the start of one telemetry frame to the rest of the
//!   next where the two agree, `7B 00` at least).
//! * anything else (a byte the line added, a byte lost inside, bytes of two frames, a part of
//!   one): a **framing false frame**, a frame made by the framing out of what arrived.

use super::board::{Board, SentFrame, Stream};
use super::line::{Line, transmit};
use super::plausible::plausible_frame;
use chassis_protocol::v1::{Downlink, DownlinkParser, Stats};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use std::collections::VecDeque;

/// The figures of one run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Score {
    /// Frames sent.
    pub sent: usize,
    /// Replies among them.
    pub replies: usize,
    /// Error events on the line (a bit flipped, a byte substituted, dropped or inserted, a burst,
    /// a dropout).
    pub errors: usize,
    /// Frames whose every byte arrived intact.
    pub untouched: usize,
    /// Untouched frames delivered.
    pub recovered: usize,
    /// Frames delivered in all.
    pub delivered: usize,
    /// Frames delivered equal to the frame sent there, though the line touched it (an inserted
    /// byte right before it, a byte replaced by the same value).
    pub delivered_touched: usize,
    /// Frames delivered not in place but equal to a sent frame some of whose bytes they are made
    /// of: what the board sent, reassembled.
    pub reassembled: usize,
    /// Framing false frames: delivered, not in place, equal to no frame they are made of.
    pub framing_false: usize,
    /// Of those, the ones the plausibility check refuses.
    pub framing_false_implausible: usize,
    /// Of those, the ones made of the start of one sent frame and the end of a later one, the
    /// bytes between lost: a run of lost bytes as long as a frame joins two frames whose first
    /// bytes have the same XOR.
    pub framing_false_joined: usize,
    /// Sent frames damaged in place and delivered: the BCC did not see it.
    pub undetected: usize,
    /// Of those, replies (the plausibility check looks at telemetry only).
    pub undetected_replies: usize,
    /// Of those, the ones the plausibility check refuses.
    pub undetected_implausible: usize,
    /// How many undetected corruptions the arithmetic expects (see `expect`).
    pub expected_undetected: f64,
    /// Frames delivered as sent that the plausibility check refuses (its false alarms).
    pub sent_implausible: usize,
    /// The first few framing false frames, for a closer look.
    pub false_samples: Vec<FalseFrame>,
    /// The parser's own counters at the end.
    pub stats: Stats,
}

impl Score {
    /// Share of untouched frames recovered.
    pub fn recovery(&self) -> f64 {
        if self.untouched == 0 {
            1.0
        } else {
            self.recovered as f64 / self.untouched as f64
        }
    }

    /// Per million frames sent.
    pub fn per_million(&self, count: usize) -> f64 {
        count as f64 * 1e6 / self.sent.max(1) as f64
    }
}

/// A framing false frame: what the parser delivered, the bytes it was made of, and where each
/// came from (an offset in the sent stream, or `None` for a byte the line added).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FalseFrame {
    /// The frame.
    pub frame: Downlink,
    /// Its bytes as received, with their origins.
    pub bytes: Vec<(u8, Option<usize>)>,
}

/// How many false frames a score keeps.
const SAMPLES: usize = 8;

/// Received bytes remembered: more than a frame and what the parser holds besides.
const WINDOW: usize = 64;

/// Scores a stream fed to one parser block by block.
#[derive(Clone, Debug, Default)]
pub struct Scorer {
    parser: DownlinkParser,
    /// Every frame sent so far, at its offset in the whole sent stream.
    sent: Vec<SentFrame>,
    /// Per frame sent: untouched by the line.
    untouched: Vec<bool>,
    /// Offset of the next block in the whole sent stream.
    base: usize,
    /// The last received bytes and where each came from.
    window: VecDeque<(u8, Option<usize>)>,
    score: Score,
    /// Whether the parser is told of quiet lines, as the driver tells it.
    quiet: bool,
    /// Idle stretches of the sent stream long enough to be a quiet line, as (offset of the
    /// first byte after it, byte times), in the whole sent stream.
    gaps: Vec<(usize, usize)>,
    /// Where the last received byte that was sent came from, in the whole sent stream.
    last_origin: Option<usize>,
}

/// A quiet line for the driver on a UART: 2 ms, 23 byte times at 115 200 bps.
pub const QUIET_BYTE_TIMES: usize = 23;

impl Scorer {
    /// A fresh parser, nothing sent, told nothing of the line's timing (a capture replayed).
    pub fn new() -> Self {
        Self::default()
    }

    /// A fresh parser told of every quiet line, as the driver tells it: the time between two
    /// bytes it receives (the idle line and the bytes lost between them) of at least
    /// [`QUIET_BYTE_TIMES`].
    pub fn reporting_quiet() -> Self {
        Scorer {
            quiet: true,
            ..Self::default()
        }
    }

    /// Whether the time between the sent bytes `p` and `o` (whole-stream offsets, `p < o`) is
    /// a quiet line: bytes lost between them and idle stretches before any frame in `(p, o]`.
    fn quiet_between(&self, p: usize, o: usize) -> bool {
        let lost = o.saturating_sub(p).saturating_sub(1);
        let from = self.gaps.partition_point(|(at, _)| *at <= p);
        let idle: usize = self.gaps[from..]
            .iter()
            .take_while(|(at, _)| *at <= o)
            .map(|(_, t)| *t)
            .sum();
        lost + idle >= QUIET_BYTE_TIMES
    }

    /// Feeds the next block: `stream` (offsets from the block's start) as it `arrived`.
    pub fn feed(&mut self, stream: &Stream, arrived: &super::line::Arrived) {
        let rx = &arrived.rx;
        let base = self.base;
        for f in &stream.frames {
            self.sent.push(SentFrame {
                start: f.start + base,
                frame: f.frame,
            });
            let intact = rx.untouched(f.start, f.end());
            self.untouched.push(intact);
            self.score.untouched += usize::from(intact);
            self.score.replies += usize::from(matches!(f.frame, Downlink::Reply(_)));
        }
        self.score.sent += stream.frames.len();
        self.gaps
            .extend(stream.gaps.iter().map(|g| (g.offset + base, g.byte_times)));
        self.score.errors += rx.errors;
        self.score.expected_undetected += arrived.expected_undetected;
        for (byte, origin) in rx.bytes.iter().zip(&rx.origin) {
            let origin = origin.map(|o| o + base);
            if let Some(o) = origin {
                if self.quiet
                    && self
                        .last_origin
                        .is_some_and(|p| p < o && self.quiet_between(p, o))
                {
                    // (Before this byte is in the window: a frame the quiet line gives ends
                    // right before it.)
                    while let Some(frame) = self.parser.quiet() {
                        self.judge(frame);
                    }
                }
                self.last_origin = Some(o);
            }
            if self.window.len() == WINDOW {
                self.window.pop_front();
            }
            self.window.push_back((*byte, origin));
            let mut out = self.parser.push(*byte);
            while let Some(frame) = out {
                self.judge(frame);
                out = self.parser.poll();
            }
        }
        self.base += stream.bytes.len();
    }

    /// Judges a frame the parser just delivered.
    fn judge(&mut self, frame: Downlink) {
        let len = frame.encode().len();
        // Its last byte is the newest less what the parser still holds.
        let last = self.window.len() - 1 - self.parser.buffered();
        let first = last + 1 - len;
        let span: Vec<(u8, Option<usize>)> = self.window.range(first..=last).copied().collect();
        let in_place = span
            .first()
            .and_then(|(_, o)| *o)
            .and_then(|o| self.sent.binary_search_by_key(&o, |f| f.start).ok())
            .filter(|k| {
                let sent = &self.sent[*k];
                sent.len() == len
                    && span
                        .iter()
                        .enumerate()
                        .all(|(i, (_, o))| *o == Some(sent.start + i))
            });
        let reassembled = in_place.is_none() && self.made_of_one_equal(&span, &frame);
        let joined = in_place.is_none() && self.joined(&span);
        let plausible = plausible_frame(&frame);
        let score = &mut self.score;
        score.delivered += 1;
        match in_place {
            Some(k) if self.sent[k].frame == frame => {
                if self.untouched[k] {
                    score.recovered += 1;
                } else {
                    score.delivered_touched += 1;
                }
                score.sent_implausible += usize::from(!plausible);
            }
            Some(_) => {
                score.undetected += 1;
                score.undetected_replies += usize::from(matches!(frame, Downlink::Reply(_)));
                score.undetected_implausible += usize::from(!plausible);
            }
            None if reassembled => {
                score.reassembled += 1;
                score.sent_implausible += usize::from(!plausible);
            }
            None => {
                score.framing_false += 1;
                score.framing_false_implausible += usize::from(!plausible);
                score.framing_false_joined += usize::from(joined);
                if score.false_samples.len() < SAMPLES {
                    score.false_samples.push(FalseFrame { frame, bytes: span });
                }
            }
        }
    }

    /// Whether one of the sent frames whose bytes are in `span` is `frame`, byte for byte.
    fn made_of_one_equal(&self, span: &[(u8, Option<usize>)], frame: &Downlink) -> bool {
        span.iter().filter_map(|(_, o)| *o).any(|o| {
            let k = self.sent.partition_point(|f| f.start <= o);
            k.checked_sub(1)
                .and_then(|k| self.sent.get(k))
                .is_some_and(|f| o < f.end() && f.frame == *frame)
        })
    }

    /// Whether the received bytes `span` are the start of one sent frame joined to the end of a
    /// later one: no byte added, in order, one run of sent bytes missing between them, the first
    /// byte a sent frame's first, the last a sent frame's last. (Whether a byte was changed is
    /// not asked.)
    fn joined(&self, span: &[(u8, Option<usize>)]) -> bool {
        let Some(origins) = span.iter().map(|(_, o)| *o).collect::<Option<Vec<usize>>>() else {
            return false;
        };
        let gaps = origins.windows(2).filter(|w| w[1] != w[0] + 1).count();
        let (Some(first), Some(last)) = (origins.first(), origins.last()) else {
            return false;
        };
        let starts = self.sent.binary_search_by_key(first, |f| f.start).is_ok();
        let ends = self
            .sent
            .binary_search_by_key(&(last + 1), |f| f.end())
            .is_ok();
        origins.windows(2).all(|w| w[1] > w[0]) && gaps == 1 && starts && ends
    }

    /// The figures, with the parser's counters.
    pub fn finish(mut self) -> Score {
        self.score.stats = self.parser.stats();
        self.score
    }
}

/// Starts a new parser at every offset of the first three frames of `seeds` clean streams of
/// `frames` frames (five replies a second, so that replies are among them), in one slice each:
/// how many starts gave every frame that starts at or after the offset, the most frames any
/// start lost, and the false frames (delivered, not sent).
pub fn startup(seeds: std::ops::Range<u64>, frames: usize) -> crate::Startup {
    let mut figures = crate::Startup::default();
    for seed in seeds {
        let stream = Board::new(seed, 5.0).take(frames.max(4));
        let third = stream.frames[3].start;
        for offset in 0..third {
            let want: Vec<Downlink> = stream
                .frames
                .iter()
                .filter(|f| f.start >= offset)
                .map(|f| f.frame)
                .collect();
            let mut parser = DownlinkParser::new();
            use chassis_protocol::v1::Parser as _;
            let got: Vec<Downlink> = parser.frames(&stream.bytes[offset..]).collect();
            let false_frames = got.iter().filter(|f| !want.contains(f)).count();
            let lost = want.iter().filter(|f| !got.contains(f)).count();
            figures.starts += 1;
            figures.all_after_first += usize::from(lost == 0);
            figures.worst_lost = figures.worst_lost.max(lost);
            figures.with_false += usize::from(false_frames > 0);
            figures.false_frames += false_frames;
        }
    }
    figures
}

/// Frames per block: the line runs block by block, so memory stays small (a burst or a dropout
/// never spans two blocks; one in about 10 000 frames is cut short that way at most).
pub const BLOCK: usize = 10_000;

/// Replies a second in the stream the sweep runs.
pub const REPLIES_PER_SECOND: f64 = 1.0;

/// `frames` frames of a board seeded with `seed` (one reply a second) over `line` (its noise
/// seeded with `seed ^ 0x5EED`), into one parser.
pub fn run(line: &Line, frames: usize, seed: u64) -> Score {
    run_with(Scorer::new(), line, frames, seed)
}

/// [`run`], the parser told of every quiet line as the driver tells it
/// ([`Scorer::reporting_quiet`]).
pub fn run_reporting_quiet(line: &Line, frames: usize, seed: u64) -> Score {
    run_with(Scorer::reporting_quiet(), line, frames, seed)
}

fn run_with(mut scorer: Scorer, line: &Line, frames: usize, seed: u64) -> Score {
    let mut board = Board::new(seed, REPLIES_PER_SECOND);
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x5EED);
    let mut left = frames;
    while left > 0 {
        let n = left.min(BLOCK);
        left -= n;
        let stream = board.take(n);
        let arrived = transmit(&stream, line, &mut rng);
        scorer.feed(&stream, &arrived);
    }
    scorer.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clean_line_recovers_everything() {
        let s = run(&Line::default(), 25_000, 1);
        assert_eq!(s.sent, 25_000);
        assert_eq!(s.untouched, s.sent);
        assert_eq!(s.recovered, s.sent);
        assert_eq!(s.delivered, s.sent);
        assert_eq!(
            (s.framing_false, s.undetected, s.sent_implausible),
            (0, 0, 0)
        );
    }

    #[test]
    fn a_frame_cut_and_a_frame_changed_are_told_apart() {
        let stream = Board::new(4, 1.0).take(3);
        // The first frame loses its last 8 bytes; in the second, two bytes of the payload swap
        // bits 0 (the BCC cannot see it).
        let cut = stream.frames[0].end() - 8..stream.frames[0].end();
        let mut rx = crate::channel::Received {
            bytes: Vec::new(),
            origin: Vec::new(),
            touched: vec![false; stream.bytes.len()],
            errors: 2,
            kept: vec![true; stream.bytes.len()],
        };
        let second = stream.frames[1].start;
        for (i, b) in stream.bytes.iter().enumerate() {
            if cut.contains(&i) {
                rx.touched[i] = true;
                rx.kept[i] = false;
                continue;
            }
            let flip = u8::from(i == second + 4 || i == second + 9);
            if flip != 0 {
                rx.touched[i] = true;
                rx.kept[i] = false;
            }
            rx.bytes.push(b ^ flip);
            rx.origin.push(Some(i));
        }
        let arrived = super::super::line::Arrived {
            rx,
            ..Default::default()
        };
        let mut scorer = Scorer::new();
        scorer.feed(&stream, &arrived);
        let s = scorer.finish();
        assert_eq!((s.untouched, s.recovered), (1, 1), "{s:?}");
        assert_eq!((s.undetected, s.framing_false), (1, 0), "{s:?}");
    }
}
