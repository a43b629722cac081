//! The one place the decoder turns a firmware generation into the code that decodes it. Each
//! generation's decoding is written once, behind [`Generation`] ([`crate::v2020`],
//! [`crate::v1`]); [`of`] picks each generation's decoder, and nothing else in the crate
//! asks which generation a capture holds.

use crate::found::Side;
use crate::read::Capture;
use chassis_protocol::detect::Firmware;

/// What decodes the captures of one generation.
pub(crate) trait Generation: Sync {
    /// The board → master side: its frames and the summary of its parser's counters.
    fn downlink(&self, capture: &Capture) -> Side;

    /// The master → board side.
    fn uplink(&self, capture: &Capture) -> Side;

    /// Both sides of one capture, both time-stamped: the board side, the master side, and what
    /// the summary says after them (`; …`, or nothing).
    fn both(&self, board: &Capture, master: &Capture) -> (Side, Side, String) {
        (self.downlink(board), self.uplink(master), String::new())
    }

    /// How many frames this generation's master → board parser finds in `capture` (how the
    /// master side's generation is detected).
    fn uplink_frames(&self, capture: &Capture) -> u32;
}

/// Every generation, each with what decodes it, in [`Firmware::ALL`]'s order (2020 first,
/// then v1.0.0): the order in which [`crate::Detection::NotRecognised`] counts their frames.
pub(crate) fn all() -> [(Firmware, &'static dyn Generation); Firmware::ALL.len()] {
    Firmware::ALL.map(|firmware| (firmware, of(firmware)))
}

/// The generation a capture is decoded as when nothing decides (2020).
pub(crate) const UNDECIDED: Firmware = Firmware::ALL[0];

/// What decodes a capture of `firmware` (exhaustive: a third generation does not build
/// until it has a decoder).
pub(crate) fn of(firmware: Firmware) -> &'static dyn Generation {
    match firmware {
        Firmware::V2020 => &crate::v2020::V2020,
        Firmware::V1_0_0 => &crate::v1::V1,
    }
}
