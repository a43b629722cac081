//! Counters of the streaming parsers, kept apart from their parsing state.
//!
//! All counters wrap at `u32::MAX` (years of traffic at 115 200 bps).

use crate::telemetry::{Kind, Stream};

/// What the board → master parser has seen. Read it with
/// [`DownlinkParser::stats`](super::DownlinkParser::stats).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct DownlinkStats {
    /// Frames emitted, per kind: IMU, encoders, battery, reply (see [`DownlinkStats::frames`]).
    pub frames: [u32; 4],
    /// Bytes thrown away: rejected candidate starts and bytes that start no frame.
    pub discarded: u32,
    /// Times an aligned parser (locked or tentative) lost its alignment and went hunting.
    pub lock_losses: u32,
    /// Times a hunting parser found a frame and became aligned again.
    pub resyncs: u32,
    /// Per stream (IMU, encoders, battery): frames whose count did not follow the previous one
    /// where the line lost something since (bytes thrown away, or quiet as long as the
    /// stream's period). On a line that lost nothing, every byte was a frame taken: a count
    /// further on is the board's own step, learnt, not a gap.
    pub gaps: [u32; 3],
    /// Per stream: frames missing according to the count bytes, where `gaps` counts (a gap of
    /// 3 counts 2).
    pub missed: [u32; 3],
}

impl DownlinkStats {
    /// All counters at 0.
    pub const fn new() -> Self {
        DownlinkStats {
            frames: [0; 4],
            discarded: 0,
            lock_losses: 0,
            resyncs: 0,
            gaps: [0; 3],
            missed: [0; 3],
        }
    }

    /// Frames emitted of this kind.
    #[must_use]
    pub fn frames_of(&self, kind: Kind) -> u32 {
        self.frames.get(kind_index(kind)).copied().unwrap_or(0)
    }

    /// Frames emitted in all.
    #[must_use]
    pub fn total_frames(&self) -> u32 {
        self.frames.iter().fold(0u32, |sum, n| sum.wrapping_add(*n))
    }

    /// Count gaps seen on this stream.
    #[must_use]
    pub fn gaps_of(&self, stream: Stream) -> u32 {
        self.gaps.get(stream.index()).copied().unwrap_or(0)
    }

    /// Frames of this stream missing according to its count bytes.
    #[must_use]
    pub fn missed_of(&self, stream: Stream) -> u32 {
        self.missed.get(stream.index()).copied().unwrap_or(0)
    }

    pub(crate) fn count_frame(&mut self, kind: Kind) {
        if let Some(n) = self.frames.get_mut(kind_index(kind)) {
            *n = n.wrapping_add(1);
        }
    }

    pub(crate) fn count_gap(&mut self, stream: Stream, missing: u8) {
        let i = stream.index();
        if let Some(n) = self.gaps.get_mut(i) {
            *n = n.wrapping_add(1);
        }
        if let Some(n) = self.missed.get_mut(i) {
            *n = n.wrapping_add(u32::from(missing));
        }
    }
}

const fn kind_index(kind: Kind) -> usize {
    match kind {
        Kind::Telemetry(stream) => stream.index(),
        Kind::Reply => 3,
    }
}

/// What the master → board parser has seen. Read it with
/// [`UplinkParser::stats`](super::UplinkParser::stats).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct UplinkStats {
    /// Frames emitted.
    pub frames: u32,
    /// Bytes thrown away.
    pub discarded: u32,
    /// Times the parser threw bytes away after a frame and then found another frame.
    pub resyncs: u32,
}

impl UplinkStats {
    /// All counters at 0.
    pub const fn new() -> Self {
        UplinkStats {
            frames: 0,
            discarded: 0,
            resyncs: 0,
        }
    }
}
