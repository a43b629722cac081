//! Host-side test support for `chassis-protocol`: a model of the board's telemetry stream, a
//! noisy UART channel, and the scoring of a parser against what was sent. Shared by the
//! integration tests, the property tests, the fuzz targets, the noise sweep and the demo.
//!
//! Everything is seeded: the same seed gives the same bytes, so every figure repeats.

pub mod board;
pub mod channel;
pub mod score;

pub use board::{BoardStream, SentFrame};
pub use channel::{Noise, Received};
pub use score::{Score, Startup, score_downlink, startup};
