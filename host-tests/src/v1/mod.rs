//! The board's v1.0.0 firmware (`7B … BCC 7D`): a model of its board → master stream, the line
//! it crosses, and the scoring of `chassis_protocol::v1::DownlinkParser` against what was sent,
//! with what the XOR checksum is expected to miss and a plausibility check beside it. Used by
//! the example `v1_sweep` (`cargo xtask sweep`), the tests `v1_streams` and `v1_parsers` and the
//! benchmark.
//!
//! * [`board`]: 32-byte telemetry at 22 Hz with a driven chassis' values, a readback reply now
//!   and then, the line idle in between.
//! * [`line`](mod@line): the crate's noisy channel on the bytes sent, bit errors, spurious bytes on the
//!   idle line.
//! * [`score`]: every delivered frame traced to the bytes it was made of: recovered, damaged in
//!   place past the BCC, or made by the framing.
//! * [`expect`]: the probability that bit errors slip past the BCC, worked out.
//! * [`plausible`](mod@plausible): telemetry values a chassis cannot report.
//! * [`reference`]: the v1.0.0 parsers' rules written plainly, to check the crate's parsers
//!   against (`tests/v1_parsers.rs`).

pub mod board;
pub mod expect;
pub mod line;
pub mod plausible;
pub mod reference;
pub mod score;

pub use board::{Board, Gap, SentFrame, Stream};
pub use line::{Arrived, Line, transmit};
pub use plausible::{plausible, plausible_frame};
pub use score::{FalseFrame, QUIET_BYTE_TIMES, Score, Scorer, run, run_reporting_quiet, startup};

use crate::channel::Noise;

/// A row of the sweep: its name and its line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// What the line does.
    pub name: &'static str,
    /// The line.
    pub line: Line,
}

/// The rows of the sweep: bit errors at three rates, with and without bursts, and each of the
/// channel's models (drops, insertions, substitutions, bursts, dropouts), then all at once.
/// Rates are per bit for bit errors, per byte (per byte time on the idle line) for the rest.
pub fn rows() -> Vec<Row> {
    let bursts = |rate| Noise::bursts(rate, 8);
    let row = |name, line| Row { name, line };
    vec![
        row("clean", Line::default()),
        row("bit errors 1e-4", Line::bits(1e-4)),
        row("bit errors 1e-3", Line::bits(1e-3)),
        row("bit errors 1e-2", Line::bits(1e-2)),
        row(
            "bit errors 1e-4, bursts of 8 at 1e-4",
            Line::bits(1e-4).with(bursts(1e-4)),
        ),
        row(
            "bit errors 1e-3, bursts of 8 at 1e-4",
            Line::bits(1e-3).with(bursts(1e-4)),
        ),
        row(
            "bit errors 1e-2, bursts of 8 at 1e-4",
            Line::bits(1e-2).with(bursts(1e-4)),
        ),
        row(
            "drops 1e-3",
            Line::noise(Noise {
                drop: 1e-3,
                ..Noise::default()
            }),
        ),
        row(
            "insertions 1e-3",
            Line::noise(Noise {
                insert: 1e-3,
                ..Noise::default()
            }),
        ),
        row(
            "substitutions, drops, insertions 1e-3",
            Line::noise(Noise::mixed(1e-3)),
        ),
        row("bursts of 8 at 1e-3", Line::noise(bursts(1e-3))),
        row(
            "dropouts of 32 at 1e-4",
            Line::noise(Noise::dropouts(1e-4, 32)),
        ),
        row(
            "dropouts of 32 at 1e-3",
            Line::noise(Noise::dropouts(1e-3, 32)),
        ),
        // A run of lost bytes that is no frame's length.
        row(
            "dropouts of 20 at 1e-3",
            Line::noise(Noise::dropouts(1e-3, 20)),
        ),
        // The channel has one run length for bursts and dropouts: 8 here.
        row(
            "all: bit errors 1e-3, mixed 1e-3, bursts and dropouts of 8 at 1e-4",
            Line::bits(1e-3).with(Noise {
                burst: 1e-4,
                dropout: 1e-4,
                burst_len: 8,
                ..Noise::mixed(1e-3)
            }),
        ),
    ]
}
