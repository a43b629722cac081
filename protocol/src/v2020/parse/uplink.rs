//! The master → board streaming parser: commands out of a byte stream, for the board simulator
//! and for sniffing a link.
//!
//! # Rules
//!
//! A candidate starts with `FF FE` and a mode byte the spec defines (`01`, `02`, `03`, `80`),
//! which fixes its length (10 or 12); a settings frame must also have `80` as byte 3. A
//! candidate that breaks a rule is rejected one byte at a time and the scan starts again at the
//! byte after its first, over the bytes already held: a real frame overlapped by a false
//! candidate is still found.
//!
//! # The trade-off chosen
//!
//! A complete candidate is emitted **on its last byte**, with no look-ahead: a master sends
//! commands when it pleases, often one and then silence, and the board must act on each at once.
//! The evidence is weaker than downstream (no count byte, no following header), but the uplink is
//! also far cleaner: command payloads are magnitudes and register values, where `FF FE` followed
//! by a valid mode byte is rare, and telemetry never flows this way.
//!
//! # Panics
//!
//! Never, on any input.

use super::stats::UplinkStats;
use super::window::Window;
use crate::command::{self, Command, HEADER};

/// Byte 3 of a settings frame.
use crate::command::settings::{FIXED as SETTINGS_FIXED, FIXED_AT as SETTINGS_FIXED_AT};

/// The master → board streaming parser.
///
/// ```
/// use chassis_protocol::{Command, UplinkParser, Velocity};
///
/// let mut parser = UplinkParser::new();
/// let mut stream = vec![0x00, 0xFF];
/// stream.extend_from_slice(&Velocity::new(0, 120, 0).encode());
/// let commands: Vec<Command> = parser.frames(&stream).collect();
/// assert_eq!(commands, [Command::Velocity(Velocity::new(0, 120, 0))]);
/// assert_eq!(parser.stats().discarded, 2);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UplinkParser {
    window: Window<{ command::MAX_LEN }>,
    /// Bytes were thrown away since the last frame.
    skipping: bool,
    stats: UplinkStats,
}

const _: () = assert!(core::mem::size_of::<Window<{ command::MAX_LEN }>>() <= 16);

/// What the window says about the candidate at its front.
enum Verdict {
    NeedMore,
    Reject,
    Accept(Command, usize),
}

impl Default for UplinkParser {
    fn default() -> Self {
        Self::new()
    }
}

impl UplinkParser {
    /// A parser that has seen nothing.
    #[must_use]
    pub const fn new() -> Self {
        UplinkParser {
            window: Window::new(),
            skipping: false,
            stats: UplinkStats::new(),
        }
    }

    /// Feeds one byte; returns the command it completes, if any. Rejected bytes are rescanned
    /// within this call, so at most one command can complete per byte.
    pub fn push(&mut self, byte: u8) -> Option<Command> {
        if self.window.is_full() {
            self.reject();
        }
        self.window.extend(&[byte]);
        self.poll()
    }

    /// Feeds bytes until a command comes out; returns it and the bytes not yet consumed.
    pub fn push_slice<'a>(&mut self, mut bytes: &'a [u8]) -> (Option<Command>, &'a [u8]) {
        while !bytes.is_empty() {
            let step = self.bytes_before_decision().max(1).min(bytes.len());
            let (now, rest) = bytes.split_at_checked(step).unwrap_or((bytes, &[]));
            bytes = rest;
            for &byte in now {
                if self.window.is_full() {
                    self.reject();
                }
                self.window.extend(&[byte]);
            }
            if let Some(command) = self.poll() {
                return (Some(command), bytes);
            }
        }
        (None, bytes)
    }

    /// An iterator over the commands in `bytes`; every byte is consumed by the time it ends.
    pub fn frames<'p, 'b>(&'p mut self, bytes: &'b [u8]) -> UplinkFrames<'p, 'b> {
        UplinkFrames {
            parser: self,
            rest: bytes,
        }
    }

    /// The line has been quiet: an incomplete candidate is thrown away.
    pub fn idle(&mut self) {
        while !self.window.is_empty() {
            self.reject();
        }
    }

    /// Bytes held but not yet emitted or thrown away (at most 12).
    #[must_use]
    pub const fn buffered(&self) -> usize {
        self.window.len()
    }

    /// The counters.
    #[must_use]
    pub const fn stats(&self) -> &UplinkStats {
        &self.stats
    }

    /// Returns the counters and starts them again from 0.
    pub fn take_stats(&mut self) -> UplinkStats {
        core::mem::take(&mut self.stats)
    }

    fn bytes_before_decision(&self) -> usize {
        match self.window.as_slice() {
            [first, second, mode, ..] if [*first, *second] == HEADER => {
                match command::frame_len(*mode) {
                    // Stop at byte 3 of a settings frame to check it early.
                    Some(len) if self.window.len() <= SETTINGS_FIXED_AT => SETTINGS_FIXED_AT
                        .saturating_add(1)
                        .min(len)
                        .saturating_sub(self.window.len())
                        .max(1),
                    Some(len) => len.saturating_sub(self.window.len()).max(1),
                    None => 1,
                }
            }
            _ => 1,
        }
    }

    fn poll(&mut self) -> Option<Command> {
        loop {
            match self.judge() {
                Verdict::NeedMore => return None,
                Verdict::Reject => self.reject(),
                Verdict::Accept(command, len) => {
                    self.window.drop_front(len);
                    self.stats.frames = self.stats.frames.wrapping_add(1);
                    if self.skipping {
                        self.stats.resyncs = self.stats.resyncs.wrapping_add(1);
                        self.skipping = false;
                    }
                    return Some(command);
                }
            }
        }
    }

    fn judge(&self) -> Verdict {
        let buf = self.window.as_slice();
        let mode = match buf {
            [] => return Verdict::NeedMore,
            [first] | [first, _] if *first != HEADER[0] => return Verdict::Reject,
            [_] => return Verdict::NeedMore,
            [_, second] if *second != HEADER[1] => return Verdict::Reject,
            [_, _] => return Verdict::NeedMore,
            [first, second, mode, ..] => {
                if [*first, *second] != HEADER {
                    return Verdict::Reject;
                }
                *mode
            }
        };
        let Some(len) = command::frame_len(mode) else {
            return Verdict::Reject;
        };
        if mode == command::mode::SETTINGS
            && matches!(buf.get(SETTINGS_FIXED_AT), Some(b) if *b != SETTINGS_FIXED)
        {
            return Verdict::Reject;
        }
        let Some(bytes) = buf.get(..len) else {
            return Verdict::NeedMore;
        };
        match Command::decode(bytes) {
            Ok(command) => Verdict::Accept(command, len),
            Err(_) => Verdict::Reject,
        }
    }

    fn reject(&mut self) {
        self.window.drop_front(1);
        self.stats.discarded = self.stats.discarded.wrapping_add(1);
        self.skipping = true;
    }
}

/// Iterator over the commands of a byte slice: see [`UplinkParser::frames`].
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UplinkFrames<'p, 'b> {
    parser: &'p mut UplinkParser,
    rest: &'b [u8],
}

impl Iterator for UplinkFrames<'_, '_> {
    type Item = Command;

    fn next(&mut self) -> Option<Command> {
        let (command, rest) = self.parser.push_slice(self.rest);
        self.rest = rest;
        command
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Action, Motors, Register, Setting, Turn, Velocity};

    #[test]
    fn every_command_comes_out_on_its_last_byte() {
        let commands = [
            Command::from(Velocity::new(-1, 2, -3)),
            Command::from(Turn::by_deci_degrees(450)),
            Command::from(Motors::closed_loop([1, -2, 3, -4])),
            Command::from(Motors::open_loop_duty([10_000, 0, 0, -1])),
            Command::from(Setting::Action(Action::Store)),
            Command::from(Setting::Read(Register::PendingAngle)),
        ];
        let mut p = UplinkParser::new();
        for command in commands {
            let bytes = command.clone().encode();
            let (last, body) = bytes.split_last().unwrap();
            for b in body {
                assert_eq!(p.push(*b), None);
            }
            assert_eq!(p.push(*last), Some(command));
        }
        assert_eq!(p.stats().frames, 6);
        assert_eq!(p.stats().discarded, 0);
    }

    #[test]
    fn a_false_header_inside_a_frame_does_not_hide_the_next_one() {
        // A truncated settings frame whose value bytes hold FF FE 01: the false velocity candidate
        // overlaps the real frame after it.
        let mut stream = vec![0xFF, 0xFE, 0x80, 0x80, 0x06, 0xFF, 0xFE, 0x01];
        let next = Velocity::new(5, 5, 5);
        stream.extend_from_slice(&next.encode());
        stream.extend_from_slice(&next.encode());
        let mut p = UplinkParser::new();
        let out: Vec<Command> = p.frames(&stream).collect();
        // Without a checksum the truncated frame and the next frame's first two bytes read as one
        // (raw) settings frame; the bytes after it are rescanned and the next frame is found.
        assert!(out.ends_with(&[Command::Velocity(next)]));
        assert!(p.stats().discarded >= 5);
    }

    #[test]
    fn settings_need_the_fixed_byte() {
        let mut bytes = Setting::Read(Register::SpeedKp).encode();
        bytes[3] = 0x00;
        let mut p = UplinkParser::new();
        assert_eq!(p.frames(&bytes).count(), 0);
        p.idle();
        assert_eq!(p.buffered(), 0);
        assert_eq!(p.stats().discarded, 10);
    }
}
