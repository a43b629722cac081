//! Stream models the 2020 parser was never developed against, for the noise sweep's last
//! section and its test: payloads full of header bytes ([`Payload::Headers`]), a counter shared
//! by all streams stepping by +1 or by a constant drawn per seed, and the line delivered
//! through a USB-UART adapter in packets ([`crate::usb`]) to a host that reports the quiet line
//! from the gaps between packets, or (the naive read loop) `idle()` after every packet.

use crate::board::{BoardStream, CountModel, Payload};
use crate::channel::{Noise, transmit};
use crate::score::{Score, score_downlink_with_gaps};
use crate::usb::{Adapter, Host, packets, received_us, score_packets};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// How the received bytes reach the parser.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Delivery {
    /// One byte at a time, the line's quiet stretches reported (`true`) or not.
    Bytes(bool),
    /// In the packets of a USB-UART adapter, to a host.
    Usb(Adapter, Host),
}

/// The deliveries of the sweep's section, with their names: the host that watches the gaps
/// between packets reports quiet only after two packets' time with no byte (2 ms for the
/// adapter that sends every 1 ms, 32 ms for the one whose timer is 16 ms).
pub const DELIVERIES: [(&str, Delivery); 6] = [
    ("bytes, no quiet", Delivery::Bytes(false)),
    ("bytes, quiet reported", Delivery::Bytes(true)),
    (
        "USB 1 ms, quiet after >2 ms",
        Delivery::Usb(Adapter::EVERY_MS, Host::QuietAfter(2)),
    ),
    (
        "USB 16 ms timer, quiet after >32 ms",
        Delivery::Usb(Adapter::LATENCY_16_MS, Host::QuietAfter(32)),
    ),
    (
        "BAD HOST: USB 1 ms, idle() after every packet",
        Delivery::Usb(Adapter::EVERY_MS, Host::IdleEveryPacket),
    ),
    (
        "BAD HOST: USB 16 ms timer, idle() after every packet",
        Delivery::Usb(Adapter::LATENCY_16_MS, Host::IdleEveryPacket),
    ),
];

/// The error rates per byte of the section (mixed channel; 0: a clean line).
pub const RATES: [f64; 4] = [0.0, 1e-4, 1e-3, 1e-2];

/// The payloads of the section, with their names.
pub const PAYLOADS: [(&str, Payload); 2] = [
    ("at rest", Payload::Rest),
    ("header bytes only", Payload::Headers),
];

/// The step of the shared counter for `seed`: a constant in 1..=7.
pub fn shared_step(seed: u64) -> u8 {
    Pcg64Mcg::seed_from_u64(seed ^ 0x5_7E9).random_range(1..=7)
}

/// Every count model of [`CountModel::ALL`] and the shared counter stepping by
/// [`shared_step`], with their names.
pub fn count_models(seed: u64) -> Vec<(String, CountModel)> {
    let mut models: Vec<(String, CountModel)> = CountModel::ALL
        .iter()
        .map(|(name, model)| (name.to_string(), *model))
        .collect();
    let step = shared_step(seed);
    models.push((
        format!("one shared counter +{step}"),
        CountModel::SharedStep(step),
    ));
    models
}

/// Scores of `frames` frames of one stream model through a mixed channel at each of `rates`,
/// delivered each of `deliveries`' ways: `scores[delivery][rate]`.
pub fn run_model(
    seed: u64,
    frames: usize,
    (payload, counts): (Payload, CountModel),
    deliveries: &[Delivery],
    rates: &[f64],
) -> Vec<Vec<Score>> {
    let timed = BoardStream::new(seed, 2.0)
        .with_models(payload, counts)
        .take_timed(frames);
    let mut scores = vec![Vec::with_capacity(rates.len()); deliveries.len()];
    for rate in rates {
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x5EED);
        let rx = transmit(&timed.bytes, &Noise::mixed(*rate), &mut rng);
        let times = received_us(&timed, &rx);
        for (delivery, row) in deliveries.iter().zip(scores.iter_mut()) {
            let score = match delivery {
                Delivery::Bytes(quiet) => {
                    let gaps = if *quiet { &timed.gaps[..] } else { &[] };
                    score_downlink_with_gaps(&timed.sent, &rx, gaps)
                }
                Delivery::Usb(adapter, host) => {
                    score_packets(&timed.sent, &rx, &packets(*adapter, &times), *host)
                }
            };
            row.push(score);
        }
    }
    scores
}
