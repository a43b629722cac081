//! Host-side test support for `chassis-protocol`: a model of the board's telemetry stream, a
//! noisy UART channel, and the scoring of a parser against what was sent. Shared by the
//! integration tests, the property tests, the fuzz targets, the noise sweep and the demo. The
//! same for the v1.0.0 firmware's board → master stream: [`v1`].
//!
//! Everything is seeded: the same seed gives the same bytes, so every figure repeats.

pub mod board;
pub mod channel;
pub mod cold;
pub mod models;
pub mod qemu;
mod replies;
pub mod score;
pub mod splice;
pub mod sweep;
pub mod usb;
pub mod v1;

pub use board::{BoardStream, CountModel, Gap, Payload, Read, SentFrame, reads_behind};
pub use channel::{Noise, Received};
pub use score::{
    FalseFrame, Score, Startup, score_downlink, score_downlink_listening, score_downlink_traced,
    score_downlink_with_gaps, startup, startup_with_idle,
};

/// Cuts `bytes` into consecutive pieces whose lengths are taken from `lengths` in turn (each at
/// least 1; the whole rest at once if `lengths` is empty): the reads a UART driver might see.
pub fn pieces<'a>(bytes: &'a [u8], lengths: &'a [usize]) -> impl Iterator<Item = &'a [u8]> + 'a {
    let mut rest = bytes;
    let mut lengths = lengths.iter().cycle();
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        let n = lengths
            .next()
            .map_or(rest.len(), |n| (*n).max(1))
            .min(rest.len());
        let (piece, later) = rest.split_at(n);
        rest = later;
        Some(piece)
    })
}
