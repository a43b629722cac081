//! Byte-at-a-time parsers of v1.0.0 frames, one per direction. Each holds at most one frame's
//! bytes. A frame is taken when it is whole and its start, end and BCC check; otherwise its
//! first byte is dropped and the next `7B` inside what is held is tried (so a frame that
//! began inside a damaged one is never lost). A byte that cannot start a frame is discarded at
//! once: the parser is never stuck, and never holds more than 32 bytes.

use super::{COMMAND_LEN, Command, Downlink, END, START, TELEMETRY_LEN, bcc};
use crate::stream::Parser;

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

/// Moves `buf[from..len]` to the front, byte by byte: no `memmove` and no panic path (a
/// firmware's link-time no-panic proof must see none).
fn shift_down<const N: usize>(buf: &mut [u8; N], from: usize, len: usize) {
    for (to, at) in (from..len.min(N)).enumerate() {
        if let Some(byte) = buf.get(at).copied() {
            if let Some(slot) = buf.get_mut(to) {
                *slot = byte;
            }
        }
    }
}

/// The bytes of at most one frame, and the rules to find one.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Framer<const N: usize> {
    buf: [u8; N],
    len: usize,
    stats: Stats,
}

impl<const N: usize> Framer<N> {
    const fn new() -> Self {
        Framer {
            buf: [0; N],
            len: 0,
            stats: Stats {
                frames: 0,
                bad_checksum: 0,
                bad_end: 0,
                refused: 0,
                discarded: 0,
            },
        }
    }

    /// Drops the first `n` held bytes.
    fn drop_front(&mut self, n: usize) {
        let n = n.min(self.len);
        shift_down(&mut self.buf, n, self.len);
        self.len = self.len.saturating_sub(n);
        self.stats.discarded = self
            .stats
            .discarded
            .saturating_add(u32::try_from(n).unwrap_or(u32::MAX));
    }

    /// Takes `byte` in (room is always left by [`next`](Self::next)).
    fn push(&mut self, byte: u8) {
        if self.len >= N {
            // Not reached: `next` leaves fewer than N bytes held. Kept safe all the same.
            self.drop_front(1);
        }
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = byte;
            self.len = self.len.saturating_add(1);
        }
    }

    /// The next whole, checked frame among the held bytes: its length (its bytes are
    /// `buf[..len]`; [`consume`](Self::consume) them once used). `len_of` gives a frame's
    /// length from its code byte (`None`: no frame has this code).
    fn next(
        &mut self,
        len_of: impl Fn(u8) -> Option<usize>,
        accept: impl Fn(&[u8]) -> bool,
    ) -> Option<usize> {
        loop {
            // A frame starts with 7B.
            let skip = self
                .buf
                .get(..self.len)
                .and_then(|held| held.iter().position(|b| *b == START))
                .unwrap_or(self.len);
            if skip > 0 {
                self.drop_front(skip);
            }
            let code = *self.buf.get(..self.len)?.get(1)?;
            let Some(need) = len_of(code).filter(|n| *n <= N) else {
                self.drop_front(1);
                continue;
            };
            if self.len < need {
                return None;
            }
            let frame = self.buf.get(..need)?;
            let (body, tail) = frame.split_at(need.saturating_sub(2));
            match tail {
                [sum, END] if *sum == bcc(body) => {
                    if accept(frame) {
                        self.stats.frames = self.stats.frames.saturating_add(1);
                        return Some(need);
                    }
                    self.stats.refused = self.stats.refused.saturating_add(1);
                }
                [_, END] => self.stats.bad_checksum = self.stats.bad_checksum.saturating_add(1),
                _ => self.stats.bad_end = self.stats.bad_end.saturating_add(1),
            }
            // Not a frame: a frame may start at the next 7B inside it.
            self.drop_front(1);
        }
    }

    /// The line was quiet: whatever is held is the start of a frame cut short (a frame's bytes
    /// come back to back), never to be completed by what comes next. Thrown away, counted.
    fn quiet(&mut self) {
        let held = self.len;
        self.drop_front(held);
    }

    /// Forgets the `n` bytes of a frame taken (not counted as discarded).
    fn consume(&mut self, n: usize) {
        let n = n.min(self.len);
        shift_down(&mut self.buf, n, self.len);
        self.len = self.len.saturating_sub(n);
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
    pub fn push(&mut self, byte: u8) -> Option<Downlink> {
        self.framer.push(byte);
        self.poll()
    }

    /// A frame already whole among the held bytes, if any.
    pub fn poll(&mut self) -> Option<Downlink> {
        let len = self
            .framer
            .next(Downlink::len_of, |f| Downlink::decode(f).is_ok())?;
        let frame = Downlink::decode(self.framer.buf.get(..len).unwrap_or(&[])).ok();
        self.framer.consume(len);
        frame
    }

    /// What it has seen.
    #[must_use]
    pub const fn stats(&self) -> Stats {
        self.framer.stats
    }

    /// Bytes held, waiting for the rest of a frame.
    #[must_use]
    pub const fn buffered(&self) -> usize {
        self.framer.len
    }

    /// The line has been quiet (no byte for longer than any gap inside a frame: 2 ms on a
    /// UART, 40 ms behind a USB-UART adapter). A frame's bytes come back to back, so the bytes
    /// held are the start of a frame cut short: they are thrown away (counted as discarded),
    /// and no frame is ever made of bytes from both sides of a quiet line. Without it, a run of
    /// exactly one frame's length lost across a frame boundary (a UART overrun) can join the
    /// start of one frame to the end of the next with a BCC that matches
    /// (`docs/v1-measurements.md`). Telling it is optional; the driver does.
    pub fn quiet(&mut self) {
        self.framer.quiet();
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
        self.framer.push(byte);
        self.poll()
    }

    /// A command already whole among the held bytes, if any.
    pub fn poll(&mut self) -> Option<Command> {
        let len_of = |code: u8| Command::is_code(code).then_some(COMMAND_LEN);
        let len = self.framer.next(len_of, |f| Command::decode(f).is_ok())?;
        let command = Command::decode(self.framer.buf.get(..len).unwrap_or(&[])).ok();
        self.framer.consume(len);
        command
    }

    /// Bytes held, waiting for the rest of a frame.
    #[must_use]
    pub const fn buffered(&self) -> usize {
        self.framer.len
    }

    /// What it has seen.
    #[must_use]
    pub const fn stats(&self) -> Stats {
        self.framer.stats
    }

    /// The line has been quiet: as [`DownlinkParser::quiet`].
    pub fn quiet(&mut self) {
        self.framer.quiet();
    }
}

impl Parser for DownlinkParser {
    type Frame = Downlink;
    fn push(&mut self, byte: u8) -> Option<Downlink> {
        DownlinkParser::push(self, byte)
    }
    fn poll(&mut self) -> Option<Downlink> {
        DownlinkParser::poll(self)
    }
    fn quiet(&mut self, _ms: u32) -> Option<Downlink> {
        // A frame's bytes come back to back: the start of one cut short by the quiet goes.
        DownlinkParser::quiet(self);
        DownlinkParser::poll(self)
    }
    fn buffered(&self) -> usize {
        DownlinkParser::buffered(self)
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
        UplinkParser::quiet(self);
        UplinkParser::poll(self)
    }
    fn buffered(&self) -> usize {
        UplinkParser::buffered(self)
    }
}
