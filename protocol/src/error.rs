//! The crate's one error type, returned by every `decode`.

use core::fmt;

/// Why a byte slice is not the frame it was decoded as.
///
/// Decoding never panics; it returns one of these. Streaming parsers do not return errors:
/// they count rejected bytes in their statistics and keep scanning.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// The slice is not exactly the frame's length.
    Length,
    /// The first bytes are not this frame's header (`FF FE`, `FF FA`, `FF FB`, `FF FC` or `23`).
    Header,
    /// The mode or code byte selects another frame type (for example an angle-mode frame
    /// decoded as a plain velocity frame), or no frame type at all.
    Mode,
    /// A byte that the spec fixes has another value (the `80` after a settings mode byte).
    Fixed,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Error::Length => "wrong frame length",
            Error::Header => "not this frame's header",
            Error::Mode => "mode or code byte of another frame type",
            Error::Fixed => "a fixed byte has the wrong value",
        })
    }
}

impl core::error::Error for Error {}
