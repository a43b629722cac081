//! The line a v1.0.0 stream crosses: the crate's noisy channel ([`crate::channel`]) on the bytes
//! sent, bit errors on top of it, and noise on the idle line between frames.
//!
//! * The channel's substitutions, drops, insertions, bursts and dropouts strike the sent bytes
//!   as [`channel::transmit`] has them, at their rates per byte.
//! * A **bit error** flips one data bit of a sent byte in place, each bit independently with
//!   probability [`Line::bit_error`]; the UART's start and stop bits are taken to survive (a slip
//!   is a drop or an insertion).
//! * Insertions and bursts strike per byte *time*: on the idle line between frames (about 94 %
//!   of the time at 22 Hz) they arrive as spurious bytes, one or a burst's worth, before the next
//!   frame. They touch no sent byte.

use super::board::Stream;
use super::expect;
use crate::channel::{self, Noise, Received};
use rand::Rng;

/// What a line does to the bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Line {
    /// The channel's noise, per byte sent (insertions and bursts also per idle byte time).
    pub noise: Noise,
    /// Probability that a data bit of a sent byte arrives flipped.
    pub bit_error: f64,
}

impl Line {
    /// Bit errors at `p` per bit and nothing else.
    pub fn bits(p: f64) -> Self {
        Line {
            bit_error: p,
            ..Line::default()
        }
    }

    /// The channel's `noise` and nothing else.
    pub fn noise(noise: Noise) -> Self {
        Line {
            noise,
            ..Line::default()
        }
    }

    /// This line with the channel's `noise` instead of its own.
    pub fn with(self, noise: Noise) -> Self {
        Line { noise, ..self }
    }
}

/// What arrived.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Arrived {
    /// The bytes and where each came from (offsets into the stream's bytes); `touched` and
    /// `kept` count bit errors too.
    pub rx: Received,
    /// Spurious bytes that arrived on the idle line.
    pub idle_bytes: usize,
    /// Bits flipped.
    pub flipped_bits: usize,
    /// How many sent frames the line is expected to damage in place so that they still pass
    /// their BCC, given what the channel did to each (see [`expect`]): bit errors on frames
    /// the channel left alone, and random values in two or more payload or BCC bytes of a
    /// frame whose other bytes it left in place.
    pub expected_undetected: f64,
}

/// Sends `stream` over `line`.
pub fn transmit(stream: &Stream, line: &Line, rng: &mut impl Rng) -> Arrived {
    let mut rx = channel::transmit(&stream.bytes, &line.noise, rng);
    let n = stream.bytes.len();

    // Where each sent byte arrived (if it did), before any bit error.
    let mut at = vec![usize::MAX; n];
    for (j, o) in rx.origin.iter().enumerate() {
        if let Some(o) = o {
            at[*o] = j;
        }
    }
    let expected_undetected = expectation(stream, &rx, &at, line.bit_error);

    let idle_bytes = idle_noise(stream, &line.noise, &mut rx, rng);
    let flipped_bits = flip_bits(&mut rx, line.bit_error, rng);
    Arrived {
        rx,
        idle_bytes,
        flipped_bits,
        expected_undetected,
    }
}

/// The expected number of frames damaged in place that pass their BCC, given the channel's
/// damage (`rx` before bit errors; `at`: where each sent byte arrived) and bit errors at `p`.
fn expectation(stream: &Stream, rx: &Received, at: &[usize], p: f64) -> f64 {
    let mut sum = 0.0;
    for f in &stream.frames {
        let (start, end) = (f.start, f.end());
        if rx.untouched(start, end) {
            sum += expect::undetected(&f.frame, p);
            continue;
        }
        // In place: every byte arrived, one right after the other.
        let in_place = at[start] != usize::MAX
            && (start + 1..end).all(|i| at[i] != usize::MAX && at[i] == at[i - 1] + 1);
        if !in_place {
            continue;
        }
        // Bytes that arrived as a random value (substituted, or a burst's garbage).
        let random: Vec<usize> = (start..end)
            .filter(|i| !rx.kept[*i])
            .map(|i| i - start)
            .collect();
        let len = end - start;
        // Random values only in payload and BCC bytes (start, code and end would have to come
        // out right by chance as well: 1 in 65 536 or less, left out), two or more of them:
        // their XOR is uniform, so the BCC matches with probability 1/256, the frame's 24 other
        // fixed bits unflipped.
        let fixed_clean = !random.iter().any(|r| *r < 2 || *r == len - 1);
        if fixed_clean && random.len() >= 2 {
            sum += (1.0 - p).powi(24) / 256.0;
        }
    }
    sum
}

/// Spurious bytes on the idle line: insertions (one byte) and bursts (`burst_len` bytes, cut at
/// the gap's end) at their rates per idle byte time, placed before the first byte that arrived
/// of the frame after the gap. Returns how many.
fn idle_noise(stream: &Stream, noise: &Noise, rx: &mut Received, rng: &mut impl Rng) -> usize {
    let rate = noise.insert + noise.burst;
    if rate <= 0.0 || stream.gaps.is_empty() {
        return 0;
    }
    // (position in the gap's frame's offset order, bytes) for every event.
    let mut spurious: Vec<(usize, Vec<u8>)> = Vec::new();
    for gap in &stream.gaps {
        let mut t = geometric(rng, rate);
        let mut bytes = Vec::new();
        while t < gap.byte_times {
            rx.errors += 1;
            if rng.random_bool(noise.insert / rate) {
                bytes.push(rng.random());
                t += 1;
            } else {
                let len = noise.burst_len.max(1).min(gap.byte_times - t);
                bytes.extend((0..len).map(|_| rng.random::<u8>()));
                t += len;
            }
            t += geometric(rng, rate);
        }
        if !bytes.is_empty() {
            spurious.push((gap.offset, bytes));
        }
    }
    if spurious.is_empty() {
        return 0;
    }
    let total: usize = spurious.iter().map(|(_, b)| b.len()).sum();
    let mut bytes = Vec::with_capacity(rx.bytes.len() + total);
    let mut origin = Vec::with_capacity(rx.bytes.len() + total);
    let mut pending = spurious.into_iter().peekable();
    for (b, o) in rx.bytes.iter().zip(&rx.origin) {
        if let Some(at) = o {
            while let Some((_, garbage)) = pending.next_if(|(offset, _)| offset <= at) {
                origin.extend(std::iter::repeat_n(None, garbage.len()));
                bytes.extend(garbage);
            }
        }
        bytes.push(*b);
        origin.push(*o);
    }
    for (_, garbage) in pending {
        origin.extend(std::iter::repeat_n(None, garbage.len()));
        bytes.extend(garbage);
    }
    rx.bytes = bytes;
    rx.origin = origin;
    total
}

/// Flips each data bit of every sent byte that arrived with probability `p`; marks the bytes
/// flipped as touched and not kept. Returns how many bits.
fn flip_bits(rx: &mut Received, p: f64, rng: &mut impl Rng) -> usize {
    if p <= 0.0 {
        return 0;
    }
    // The sent bytes that arrived, as one run of bits; the gap to the next flip is geometric.
    let sent: Vec<usize> = (0..rx.bytes.len())
        .filter(|j| rx.origin[*j].is_some())
        .collect();
    let bits = sent.len() * 8;
    let mut flipped = 0;
    let mut at = geometric(rng, p);
    while at < bits {
        let j = sent[at / 8];
        rx.bytes[j] ^= 1 << (at % 8);
        if let Some(o) = rx.origin[j] {
            rx.touched[o] = true;
            rx.kept[o] = false;
        }
        rx.errors += 1;
        flipped += 1;
        at += 1 + geometric(rng, p);
    }
    flipped
}

/// Trials before the next success of probability `p` (0 < p ≤ 1): geometric, by inversion.
fn geometric(rng: &mut impl Rng, p: f64) -> usize {
    if p >= 1.0 {
        return 0;
    }
    let u: f64 = rng.random();
    // 1 - u is in (0, 1]: its logarithm is finite.
    let k = ((1.0 - u).ln() / (1.0 - p).ln()).floor();
    if k >= usize::MAX as f64 {
        usize::MAX
    } else {
        k as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::v1::board::Board;
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    #[test]
    fn bit_errors_come_at_their_rate_and_stay_in_place() {
        let stream = Board::new(1, 1.0).take(20_000);
        let a = transmit(&stream, &Line::bits(1e-3), &mut Pcg64Mcg::seed_from_u64(2));
        let bits = stream.bytes.len() * 8;
        let rate = a.flipped_bits as f64 / bits as f64;
        assert!((rate - 1e-3).abs() < 1e-4, "{rate}");
        assert_eq!(a.rx.bytes.len(), stream.bytes.len());
        let changed =
            a.rx.bytes
                .iter()
                .zip(&stream.bytes)
                .map(|(r, s)| (r ^ s).count_ones() as usize)
                .sum::<usize>();
        assert_eq!(changed, a.flipped_bits);
        assert!(a.rx.origin.iter().enumerate().all(|(j, o)| *o == Some(j)));
    }

    #[test]
    fn idle_noise_adds_bytes_between_frames_only() {
        let stream = Board::new(3, 1.0).take(5_000);
        let line = Line::noise(Noise {
            insert: 1e-3,
            ..Noise::default()
        });
        let a = transmit(&stream, &line, &mut Pcg64Mcg::seed_from_u64(4));
        let idle: usize = stream.gaps.iter().map(|g| g.byte_times).sum();
        let expected = idle as f64 * 1e-3;
        assert!(
            (a.idle_bytes as f64 - expected).abs() < 4.0 * expected.sqrt(),
            "{} {expected}",
            a.idle_bytes
        );
        // No spurious byte inside a frame the channel left alone.
        let mut inside = 0;
        for f in &stream.frames {
            if a.rx.untouched(f.start, f.end()) {
                let first =
                    a.rx.origin
                        .iter()
                        .position(|o| *o == Some(f.start))
                        .unwrap();
                let run = &a.rx.origin[first..first + f.len()];
                inside += usize::from(run.iter().enumerate().any(|(k, o)| *o != Some(f.start + k)));
            }
        }
        assert_eq!(inside, 0);
    }

    #[test]
    fn geometric_gaps_have_their_mean() {
        let mut rng = Pcg64Mcg::seed_from_u64(5);
        let n = 200_000;
        let mean = (0..n)
            .map(|_| geometric(&mut rng, 0.01) as f64)
            .sum::<f64>()
            / n as f64;
        // Mean (1 - p) / p = 99.
        assert!((mean - 99.0).abs() < 1.5, "{mean}");
    }
}
