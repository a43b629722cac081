//! A noisy UART: byte substitution, byte drop (overrun), byte insertion, bursts of garbage and
//! dropouts (runs of bytes lost: a USB-UART bridge or a busy receiver losing a whole buffer),
//! each at its own rate per byte. It records where every received byte came from, so a score can
//! tell a frame emitted at its place from a false one.

use rand::Rng;

/// The noise of a channel: probabilities per sent byte.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Noise {
    /// The byte arrives as another value.
    pub substitute: f64,
    /// The byte is lost (receiver overrun).
    pub drop: f64,
    /// A spurious byte arrives before this one.
    pub insert: f64,
    /// A burst starts here: this byte and the next `burst_len - 1` arrive as garbage.
    pub burst: f64,
    /// A dropout starts here: this byte and the next `burst_len - 1` are lost.
    pub dropout: f64,
    /// Length of a burst or a dropout in bytes.
    pub burst_len: usize,
}

impl Noise {
    /// Substitution, drop and insertion, each a third of `rate`.
    pub fn mixed(rate: f64) -> Self {
        Noise {
            substitute: rate / 3.0,
            drop: rate / 3.0,
            insert: rate / 3.0,
            ..Noise::default()
        }
    }

    /// Bursts of `len` garbage bytes, starting at `rate` per byte.
    pub fn bursts(rate: f64, len: usize) -> Self {
        Noise {
            burst: rate,
            burst_len: len,
            ..Noise::default()
        }
    }

    /// Dropouts of `len` bytes lost in a row, starting at `rate` per byte.
    pub fn dropouts(rate: f64, len: usize) -> Self {
        Noise {
            dropout: rate,
            burst_len: len,
            ..Noise::default()
        }
    }
}

/// What arrived, and where each byte came from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Received {
    /// The bytes as received.
    pub bytes: Vec<u8>,
    /// For each received byte, the offset of the sent byte it is (possibly changed), or `None`
    /// for an inserted byte.
    pub origin: Vec<Option<usize>>,
    /// For each sent byte: changed or lost on the way, or a byte was inserted right before it.
    pub touched: Vec<bool>,
    /// Error events (a burst counts once).
    pub errors: usize,
    /// For each sent byte: it arrived, unchanged.
    pub kept: Vec<bool>,
}

impl Received {
    /// Whether the channel left the sent bytes `start..end` alone (an insertion right before
    /// `start` does not touch them: it falls between frames).
    pub fn untouched(&self, start: usize, end: usize) -> bool {
        match (self.touched.get(start..end), self.kept.get(start)) {
            (Some([first_touched, rest @ ..]), Some(first_kept)) => {
                !rest.iter().any(|t| *t) && (!first_touched || *first_kept)
            }
            _ => false,
        }
    }
}

/// Sends `sent` through the channel.
pub fn transmit(sent: &[u8], noise: &Noise, rng: &mut impl Rng) -> Received {
    let mut rx = Received {
        bytes: Vec::with_capacity(sent.len() + sent.len() / 100),
        origin: Vec::with_capacity(sent.len()),
        touched: vec![false; sent.len()],
        errors: 0,
        kept: vec![true; sent.len()],
    };
    // The bytes left in the current dropout or burst, and whether they are lost (a dropout) or
    // turned into garbage (a burst).
    let mut run_left = 0usize;
    let mut run_lost = false;
    for (i, &byte) in sent.iter().enumerate() {
        if run_left == 0 {
            for (rate, lost) in [(noise.dropout, true), (noise.burst, false)] {
                if rate > 0.0 && rng.random_bool(rate) {
                    run_left = noise.burst_len.max(1);
                    run_lost = lost;
                    rx.errors += 1;
                    break;
                }
            }
        }
        if run_left > 0 {
            run_left -= 1;
            rx.touched[i] = true;
            rx.kept[i] = false;
            if !run_lost {
                rx.bytes.push(rng.random());
                rx.origin.push(Some(i));
            }
            continue;
        }
        if noise.insert > 0.0 && rng.random_bool(noise.insert) {
            rx.errors += 1;
            rx.touched[i] = true;
            rx.bytes.push(rng.random());
            rx.origin.push(None);
        }
        if noise.drop > 0.0 && rng.random_bool(noise.drop) {
            rx.errors += 1;
            rx.touched[i] = true;
            rx.kept[i] = false;
            continue;
        }
        if noise.substitute > 0.0 && rng.random_bool(noise.substitute) {
            rx.errors += 1;
            rx.touched[i] = true;
            rx.kept[i] = false;
            rx.bytes.push(byte ^ rng.random_range(1..=255u8));
            rx.origin.push(Some(i));
            continue;
        }
        rx.bytes.push(byte);
        rx.origin.push(Some(i));
    }
    rx
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    #[test]
    fn a_clean_channel_changes_nothing() {
        let sent: Vec<u8> = (0..=255).collect();
        let rx = transmit(&sent, &Noise::default(), &mut Pcg64Mcg::seed_from_u64(1));
        assert_eq!(rx.bytes, sent);
        assert!(rx.untouched(0, 256));
        assert_eq!(rx.errors, 0);
    }

    #[test]
    fn rates_are_per_byte_and_origins_are_kept() {
        let sent = vec![0x55u8; 200_000];
        let rx = transmit(&sent, &Noise::mixed(3e-2), &mut Pcg64Mcg::seed_from_u64(2));
        let rate = rx.errors as f64 / sent.len() as f64;
        assert!((rate - 3e-2).abs() < 3e-3, "{rate}");
        let inserted = rx.origin.iter().filter(|o| o.is_none()).count();
        let dropped = sent.len() - (rx.origin.len() - inserted);
        assert!(inserted > 1500 && dropped > 1500, "{inserted} {dropped}");
        let changed = rx
            .bytes
            .iter()
            .zip(&rx.origin)
            .filter(|(b, o)| o.is_some() && **b != 0x55)
            .count();
        assert!(changed > 1500, "{changed}");
    }

    #[test]
    fn a_dropout_loses_a_run_of_bytes_and_nothing_else() {
        let sent: Vec<u8> = (0..100_000u32).map(|i| (i % 251) as u8).collect();
        let rx = transmit(
            &sent,
            &Noise::dropouts(1e-3, 32),
            &mut Pcg64Mcg::seed_from_u64(3),
        );
        assert!(rx.errors > 50 && rx.errors < 150, "{}", rx.errors);
        assert_eq!(rx.bytes.len(), sent.len() - 32 * rx.errors);
        // What arrives is sent bytes, unchanged and in order.
        let mut last = None;
        for (b, o) in rx.bytes.iter().zip(&rx.origin) {
            let o = o.expect("a dropout inserts nothing");
            assert_eq!(*b, sent[o]);
            assert!(last < Some(o));
            last = Some(o);
        }
        assert_eq!(rx.kept.iter().filter(|k| !**k).count(), 32 * rx.errors);
    }

    #[test]
    fn an_insertion_before_a_frame_leaves_it_untouched() {
        let sent = [1u8, 2, 3, 4];
        let mut rx = Received {
            bytes: vec![1, 2, 9, 3, 4],
            origin: vec![Some(0), Some(1), None, Some(2), Some(3)],
            touched: vec![false, false, true, false],
            errors: 1,
            kept: vec![true; 4],
        };
        assert!(rx.untouched(2, 4));
        assert!(!rx.untouched(0, 4));
        rx.kept[2] = false;
        assert!(!rx.untouched(2, 4));
        let _ = sent;
    }
}
