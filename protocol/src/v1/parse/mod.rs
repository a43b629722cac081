//! Streaming parsers of v1.0.0 frames, one per direction, fed a byte at a time (`push`) or a
//! slice at a time (`push_slice`, `frames()` of [`Parser`]). Each holds at most one frame's
//! bytes. A frame is taken when it is whole and its start, end and BCC check; otherwise its
//! first byte is dropped and the next `7B` inside it is tried (so a frame that began inside a
//! damaged one is never lost). A byte that cannot start a frame is discarded at once: the
//! parser is never stuck, and never holds more than 32 bytes. The rules, and how each way in
//! follows them at little cost, are in [`framer`]; either way, and in any chunking, the frames
//! and the counters are the same.

mod framer;

use super::{COMMAND_LEN, Command, Downlink, TELEMETRY_LEN};
use crate::stream::Parser;
use framer::{Direction, Framer};

/// What a parser has seen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stats {
    /// Frames taken.
    pub frames: u32,
    /// Whole frames whose BCC did not match.
    pub bad_checksum: u32,
    /// Whole frames whose last byte was not `7D`.
    pub bad_end: u32,
    /// Whole frames, start, end and BCC right, whose content is no frame of this direction
    /// (a readback request with a payload that is not ten `00`).
    pub refused: u32,
    /// Bytes thrown away (not part of a frame taken).
    pub discarded: u32,
}

/// Board → master: telemetry (32 bytes) and replies (14).
#[derive(Clone, Copy, Debug)]
struct BoardToMaster;

impl Direction for BoardToMaster {
    type Frame = Downlink;
    #[inline]
    fn len_of(code: u8) -> Option<usize> {
        Downlink::len_of(code)
    }
    #[inline]
    fn accepts(_: &[u8]) -> bool {
        // A candidate is as long as its code says, and every code with a length is a frame's:
        // telemetry, or a reply to a readback (`Downlink::from_frame` decodes any).
        true
    }
    fn decode(bytes: &[u8]) -> Option<Downlink> {
        Downlink::from_frame(bytes)
    }
}

/// Master → board: commands (14 bytes).
#[derive(Clone, Copy, Debug)]
struct MasterToBoard;

impl Direction for MasterToBoard {
    type Frame = Command;
    #[inline]
    fn len_of(code: u8) -> Option<usize> {
        Command::is_code(code).then_some(COMMAND_LEN)
    }
    fn accepts(bytes: &[u8]) -> bool {
        // A readback request with a payload, say.
        Command::decode(bytes).is_ok()
    }
    fn decode(bytes: &[u8]) -> Option<Command> {
        Command::decode(bytes).ok()
    }
}

/// The board → master parser: [`Downlink`] frames (32-byte telemetry, 14-byte replies) from
/// bytes in any chunking.
///
/// ```
/// use chassis_protocol::v1::{Downlink, DownlinkParser, Telemetry};
///
/// let frame = Telemetry { battery_mv: 11_800, ..Telemetry::default() }.encode();
/// let mut parser = DownlinkParser::new();
/// let mut found = None;
/// for byte in [0x00, 0x7B].iter().chain(frame.iter()) {
///     if let Some(f) = parser.push(*byte) {
///         found = Some(f);
///     }
/// }
/// assert!(matches!(found, Some(Downlink::Telemetry(t)) if t.battery_mv == 11_800));
/// assert_eq!(parser.stats().discarded, 2);
/// ```
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DownlinkParser {
    framer: Framer<TELEMETRY_LEN>,
}

impl Default for DownlinkParser {
    fn default() -> Self {
        Self::new()
    }
}

impl DownlinkParser {
    /// A parser holding nothing.
    #[must_use]
    pub const fn new() -> Self {
        DownlinkParser {
            framer: Framer::new(),
        }
    }

    /// Takes one byte; the frame it completes, if any. A byte can complete at most one frame;
    /// call [`poll`](Self::poll) after a frame until `None` (a frame found inside a damaged one
    /// may follow).
    #[inline]
    pub fn push(&mut self, byte: u8) -> Option<Downlink> {
        self.framer.push::<BoardToMaster>(byte)
    }

    /// A frame already whole among the held bytes, if any.
    pub fn poll(&mut self) -> Option<Downlink> {
        self.framer.poll::<BoardToMaster>()
    }

    /// What it has seen.
    #[must_use]
    pub const fn stats(&self) -> Stats {
        self.framer.stats()
    }

    /// Bytes held, waiting for the rest of a frame.
    #[must_use]
    pub const fn buffered(&self) -> usize {
        self.framer.len()
    }

    /// The line has been quiet (no byte for longer than any gap inside a frame: 2 ms on a
    /// UART, 40 ms behind a USB-UART adapter). A frame's bytes come back to back, so nothing
    /// that comes next completes the bytes held: a frame whole among them comes out (call it
    /// until `None`), the start of a frame cut short is thrown away (counted as discarded; a
    /// frame that began inside it is still found), and no frame is ever made of bytes from both
    /// sides of a quiet line. Without it, a run of exactly one frame's length lost across a
    /// frame boundary (a UART overrun) can join the start of one frame to the end of the next
    /// with a BCC that matches (`docs/v1-measurements.md`). Telling it is optional; the driver
    /// does.
    #[must_use = "a frame found among the bytes held comes out here: call it until None"]
    pub fn quiet(&mut self) -> Option<Downlink> {
        self.framer.quiet::<BoardToMaster>()
    }
}

/// The master → board parser: [`Command`] frames (14 bytes), for captures and the simulator.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UplinkParser {
    framer: Framer<COMMAND_LEN>,
}

impl Default for UplinkParser {
    fn default() -> Self {
        Self::new()
    }
}

impl UplinkParser {
    /// A parser holding nothing.
    #[must_use]
    pub const fn new() -> Self {
        UplinkParser {
            framer: Framer::new(),
        }
    }

    /// Takes one byte; the command it completes, if any (then [`poll`](Self::poll) until
    /// `None`).
    pub fn push(&mut self, byte: u8) -> Option<Command> {
        self.framer.push::<MasterToBoard>(byte)
    }

    /// A command already whole among the held bytes, if any.
    pub fn poll(&mut self) -> Option<Command> {
        self.framer.poll::<MasterToBoard>()
    }

    /// Bytes held, waiting for the rest of a frame.
    #[must_use]
    pub const fn buffered(&self) -> usize {
        self.framer.len()
    }

    /// What it has seen.
    #[must_use]
    pub const fn stats(&self) -> Stats {
        self.framer.stats()
    }

    /// The line has been quiet: as [`DownlinkParser::quiet`] (call it until `None`).
    #[must_use = "a command found among the bytes held comes out here: call it until None"]
    pub fn quiet(&mut self) -> Option<Command> {
        self.framer.quiet::<MasterToBoard>()
    }
}

impl Parser for DownlinkParser {
    type Frame = Downlink;
    #[inline]
    fn push(&mut self, byte: u8) -> Option<Downlink> {
        DownlinkParser::push(self, byte)
    }
    fn poll(&mut self) -> Option<Downlink> {
        DownlinkParser::poll(self)
    }
    fn quiet(&mut self, _ms: u32) -> Option<Downlink> {
        DownlinkParser::quiet(self)
    }
    fn buffered(&self) -> usize {
        DownlinkParser::buffered(self)
    }
    fn push_slice<'a>(&mut self, bytes: &'a [u8]) -> (Option<Downlink>, &'a [u8]) {
        let mut rest = bytes;
        let frame = self.framer.take_frame::<BoardToMaster>(&mut rest);
        (frame, rest)
    }
    fn take_frame(&mut self, bytes: &mut &[u8]) -> Option<Downlink> {
        self.framer.take_frame::<BoardToMaster>(bytes)
    }
}

impl Parser for UplinkParser {
    type Frame = Command;
    fn push(&mut self, byte: u8) -> Option<Command> {
        UplinkParser::push(self, byte)
    }
    fn poll(&mut self) -> Option<Command> {
        UplinkParser::poll(self)
    }
    fn quiet(&mut self, _ms: u32) -> Option<Command> {
        UplinkParser::quiet(self)
    }
    fn buffered(&self) -> usize {
        UplinkParser::buffered(self)
    }
    fn push_slice<'a>(&mut self, bytes: &'a [u8]) -> (Option<Command>, &'a [u8]) {
        let mut rest = bytes;
        let frame = self.framer.take_frame::<MasterToBoard>(&mut rest);
        (frame, rest)
    }
    fn take_frame(&mut self, bytes: &mut &[u8]) -> Option<Command> {
        self.framer.take_frame::<MasterToBoard>(bytes)
    }
}
