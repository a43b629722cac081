//! Streaming parsers, one per direction, and their counters.
//!
//! | parser | direction | emits | state |
//! |---|---|---|---|
//! | [`DownlinkParser`] | board → master | [`Downlink`](crate::Downlink) | 228 bytes (a 96-byte window, learnt counts, counters) |
//! | [`UplinkParser`] | master → board | [`Command`](crate::Command) | 28 bytes |
//!
//! Both are `const fn new()`, take bytes one at a time ([`push`](DownlinkParser::push)) or a
//! slice at a time ([`push_slice`](DownlinkParser::push_slice), which returns the bytes not yet
//! consumed so none is ever dropped between calls), never allocate and never panic. Neither
//! reads a clock: a caller that can tell when the line goes quiet says so (`quiet(ms)` on the
//! downlink parser, `idle()` on the uplink one).

pub mod downlink;
pub mod stats;
pub mod uplink;
mod window;

pub use downlink::{DownlinkFrames, DownlinkParser, Lock};
pub use stats::{DownlinkStats, UplinkStats};
pub use uplink::{UplinkFrames, UplinkParser};
