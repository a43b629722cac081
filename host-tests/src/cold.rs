//! Cold start, exact from the first byte: a listener that starts in the middle of a clean
//! stream, at every offset of a range, fed in chunks of one byte, of random sizes or of USB
//! packets, with the line's quiet stretches after its start reported or not. Every frame that
//! starts at or after the first byte it gets counts, the first whole one too.

use crate::board::{BoardStream, CountModel, Gap, Payload};
use chassis_protocol::{Downlink, DownlinkParser};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::collections::HashMap;

/// How the bytes reach the parser.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Chunking {
    /// One [`DownlinkParser::push`] per byte.
    Bytes,
    /// [`DownlinkParser::push_slice`] over slices of 1..=64 bytes, sizes drawn from the seed.
    Random,
    /// `push_slice` over 62-byte slices (full USB packets).
    Usb62,
}

impl Chunking {
    /// Every chunking, with its name in the tables.
    pub const ALL: [(&'static str, Chunking); 3] = [
        ("1 byte", Chunking::Bytes),
        ("random 1..64", Chunking::Random),
        ("USB 62", Chunking::Usb62),
    ];
}

/// What the starts of one stream model cost.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ColdStart {
    /// Start offsets tried.
    pub starts: usize,
    /// Frames that started at or after a start, summed over the starts.
    pub expected: usize,
    /// Of those, frames that did not come out, summed.
    pub missed: usize,
    /// Starts that missed at least one frame.
    pub starts_missing: usize,
    /// Most frames missed by one start, and the first such start's offset.
    pub worst: (usize, usize),
    /// Which frames the worst start missed (0: the first whole frame after it), at most 8.
    pub worst_missed: Vec<usize>,
    /// Frames emitted that were not sent, summed.
    pub false_frames: usize,
    /// Starts that emitted at least one false frame.
    pub starts_false: usize,
}

/// One stream model to start on cold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Model {
    /// The seed of the stream (and of the random chunk sizes).
    pub seed: u64,
    /// Payloads.
    pub payload: Payload,
    /// What the count byte counts.
    pub counts: CountModel,
    /// Frames in the stream.
    pub frames: usize,
}

/// Starts a new parser at every offset in `offsets` of `model`'s stream, fed as `chunking`
/// says, with the line's quiet stretches after the start reported (`quiet`) or not.
pub fn cold_start(
    model: Model,
    offsets: std::ops::Range<usize>,
    quiet: bool,
    chunking: Chunking,
) -> ColdStart {
    let (bytes, sent, gaps) = BoardStream::new(model.seed, 2.0)
        .with_models(model.payload, model.counts)
        .take_with_gaps(model.frames);
    let mut figures = ColdStart::default();
    for offset in offsets.take_while(|o| *o < bytes.len()) {
        let gaps: Vec<Gap> = if quiet {
            gaps.iter().filter(|g| g.offset > offset).copied().collect()
        } else {
            Vec::new()
        };
        let mut rng = Pcg64Mcg::seed_from_u64(model.seed ^ offset as u64);
        let out = listen(&bytes[offset..], offset, &gaps, chunking, &mut rng);
        let expected: Vec<Downlink> = sent
            .iter()
            .filter(|f| f.start >= offset)
            .map(|f| f.frame)
            .collect();
        let (missed, false_frames) = compare(&out, &expected);
        figures.add(offset, expected.len(), &missed, false_frames);
    }
    figures
}

impl ColdStart {
    fn add(&mut self, offset: usize, expected: usize, missed: &[usize], false_frames: usize) {
        self.starts += 1;
        self.expected += expected;
        self.missed += missed.len();
        self.starts_missing += usize::from(!missed.is_empty());
        if missed.len() > self.worst.0 {
            self.worst = (missed.len(), offset);
            self.worst_missed = missed.iter().take(8).copied().collect();
        }
        self.false_frames += false_frames;
        self.starts_false += usize::from(false_frames > 0);
    }
}

/// Feeds `bytes` (the stream from `offset` on) to a new parser, reporting `gaps` (offsets in
/// the whole stream) with `quiet`, and `idle()` at the end; returns what came out.
fn listen(
    bytes: &[u8],
    offset: usize,
    gaps: &[Gap],
    chunking: Chunking,
    rng: &mut impl Rng,
) -> Vec<Downlink> {
    let mut parser = DownlinkParser::new();
    let mut out = Vec::new();
    let mut from = 0;
    let ends = gaps.iter().map(|g| (g.offset - offset, g.ms));
    for (end, ms) in ends.chain([(bytes.len(), 0)]) {
        let mut segment = &bytes[from..end];
        while !segment.is_empty() {
            let n = match chunking {
                Chunking::Bytes => 1,
                Chunking::Random => rng.random_range(1..=64),
                Chunking::Usb62 => 62,
            };
            let (chunk, rest) = segment.split_at(n.min(segment.len()));
            segment = rest;
            if chunking == Chunking::Bytes {
                out.extend(chunk.iter().filter_map(|b| parser.push(*b)));
                out.extend(std::iter::from_fn(|| parser.poll()));
            } else {
                out.extend(parser.frames(chunk));
            }
        }
        let ms = if end == bytes.len() { 1 } else { ms };
        out.extend(std::iter::from_fn(|| parser.quiet(ms)));
        from = end;
    }
    out
}

/// Matches `out` against `expected` in order: the indices of the expected frames that did not
/// come out, and how many frames came out that were not expected (an emitted frame matches
/// the first equal expected frame after the last match; the frames it skips are missed).
pub fn compare(out: &[Downlink], expected: &[Downlink]) -> (Vec<usize>, usize) {
    let mut at: HashMap<Downlink, Vec<usize>> = HashMap::new();
    for (i, frame) in expected.iter().enumerate() {
        at.entry(*frame).or_default().push(i);
    }
    let mut next = 0;
    let mut missed = Vec::new();
    let mut false_frames = 0;
    for frame in out {
        let found = at.get(frame).and_then(|indices| {
            let k = indices.partition_point(|i| *i < next);
            indices.get(k).copied()
        });
        match found {
            Some(i) => {
                missed.extend(next..i);
                next = i + 1;
            }
            None => false_frames += 1,
        }
    }
    missed.extend(next..expected.len());
    (missed, false_frames)
}

#[cfg(test)]
mod tests {
    use super::*;
    use chassis_protocol::{Battery, Downlink};

    fn battery(seq: u8) -> Downlink {
        Downlink::Battery(Battery {
            centivolts: 1_200,
            percent: 75,
            seq,
        })
    }

    #[test]
    fn compare_counts_misses_in_order_and_frames_not_sent() {
        let expected: Vec<Downlink> = (0..5).map(battery).collect();
        let out = [battery(0), battery(9), battery(2), battery(4)];
        assert_eq!(compare(&out, &expected), (vec![1, 3], 1));
        assert_eq!(compare(&[], &expected), (vec![0, 1, 2, 3, 4], 0));
    }
}
