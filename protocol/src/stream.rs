//! What every streaming parser of the crate offers, whichever the firmware generation and the
//! direction: [`Parser`], implemented by the 2020 [`DownlinkParser`](crate::DownlinkParser) and
//! [`UplinkParser`](crate::UplinkParser) and by v1.0.0's
//! [`v1::DownlinkParser`](crate::v1::DownlinkParser) and
//! [`v1::UplinkParser`](crate::v1::UplinkParser). Code written against it (a decoder, a test
//! harness, a bridge) serves both generations.
//!
//! ```
//! use chassis_protocol::stream::Parser;
//! use chassis_protocol::{DownlinkParser, Imu, v1};
//!
//! /// The frames of a burst of `bytes` with the line quiet before and after it.
//! fn decode<P: Parser>(parser: &mut P, bytes: &[u8]) -> Vec<P::Frame> {
//!     let mut frames: Vec<P::Frame> = core::iter::from_fn(|| parser.quiet(5)).collect();
//!     frames.extend(parser.frames(bytes));
//!     frames.extend(core::iter::from_fn(|| parser.quiet(5)));
//!     frames
//! }
//!
//! let imu = |seq| Imu { accel: [0, 0, 16_384], gyro: [0, 0, 1], seq };
//! let line: Vec<u8> = (0..3).flat_map(|seq| imu(seq).encode()).collect();
//! assert_eq!(decode(&mut DownlinkParser::new(), &line).len(), 3);
//! let t = v1::Telemetry { battery_mv: 12_000, ..v1::Telemetry::default() };
//! assert_eq!(decode(&mut v1::DownlinkParser::new(), &t.encode()).len(), 1);
//! ```

/// A streaming parser of one direction: bytes in, one at a time or a slice at a time, frames
/// out. None allocates or panics; none reads a clock (the caller says when the line goes quiet).
pub trait Parser {
    /// What it finds.
    type Frame;

    /// Feeds one byte: the frame it completes (or proves), if any. At most one frame comes out
    /// per call; more decided at once come out of the next calls, never lost.
    fn push(&mut self, byte: u8) -> Option<Self::Frame>;

    /// A frame already decided among the bytes held, without a new byte.
    fn poll(&mut self) -> Option<Self::Frame>;

    /// The line has been quiet for `ms` more milliseconds (a gap of two or three characters'
    /// time is one): a whole frame that waited for what follows is judged with the quiet as
    /// what follows, a frame cut short is thrown away, and no frame spans the quiet. Call it
    /// until it returns `None`.
    fn quiet(&mut self, ms: u32) -> Option<Self::Frame>;

    /// Bytes held, not yet given out as a frame or thrown away.
    fn buffered(&self) -> usize;

    /// Feeds bytes until a frame comes out: it, and the bytes not yet consumed (none is ever
    /// dropped between calls).
    fn push_slice<'a>(&mut self, bytes: &'a [u8]) -> (Option<Self::Frame>, &'a [u8]) {
        if let Some(frame) = self.poll() {
            return (Some(frame), bytes);
        }
        let mut rest = bytes;
        while let Some((byte, tail)) = rest.split_first() {
            rest = tail;
            if let Some(frame) = self.push(*byte) {
                return (Some(frame), rest);
            }
        }
        (None, rest)
    }

    /// Feeds bytes from the front of `bytes` until a frame comes out; `bytes` keeps the rest.
    /// What [`frames`](Parser::frames) iterates with: [`push_slice`](Parser::push_slice) in
    /// place, without a pair to return. The default pushes each byte; every parser of the crate
    /// gives its own slice path here (the v1.0.0 ones check and decode a frame whole in `bytes`
    /// where it lies, and hold only the start of one cut by the end of `bytes`).
    fn take_frame(&mut self, bytes: &mut &[u8]) -> Option<Self::Frame> {
        if let Some(frame) = self.poll() {
            return Some(frame);
        }
        while let Some((byte, rest)) = bytes.split_first() {
            *bytes = rest;
            if let Some(frame) = self.push(*byte) {
                return Some(frame);
            }
        }
        None
    }

    /// Every frame of `bytes`, in order; every byte is consumed by the time it ends.
    fn frames<'p, 'b>(&'p mut self, bytes: &'b [u8]) -> Frames<'p, 'b, Self>
    where
        Self: Sized,
    {
        Frames {
            parser: self,
            bytes,
        }
    }
}

/// The frames of a slice, in order ([`Parser::frames`]).
#[derive(Debug)]
pub struct Frames<'p, 'b, P> {
    parser: &'p mut P,
    bytes: &'b [u8],
}

impl<P: Parser> Iterator for Frames<'_, '_, P> {
    type Item = P::Frame;

    fn next(&mut self) -> Option<P::Frame> {
        self.parser.take_frame(&mut self.bytes)
    }
}

impl Parser for crate::DownlinkParser {
    type Frame = crate::Downlink;
    fn push(&mut self, byte: u8) -> Option<crate::Downlink> {
        crate::DownlinkParser::push(self, byte)
    }
    fn poll(&mut self) -> Option<crate::Downlink> {
        crate::DownlinkParser::poll(self)
    }
    fn quiet(&mut self, ms: u32) -> Option<crate::Downlink> {
        crate::DownlinkParser::quiet(self, ms)
    }
    fn buffered(&self) -> usize {
        crate::DownlinkParser::buffered(self)
    }
    fn push_slice<'a>(&mut self, bytes: &'a [u8]) -> (Option<crate::Downlink>, &'a [u8]) {
        crate::DownlinkParser::push_slice(self, bytes)
    }
    fn take_frame(&mut self, bytes: &mut &[u8]) -> Option<crate::Downlink> {
        let (frame, rest) = crate::DownlinkParser::push_slice(self, bytes);
        *bytes = rest;
        frame
    }
}

impl Parser for crate::UplinkParser {
    type Frame = crate::Command;
    fn push(&mut self, byte: u8) -> Option<crate::Command> {
        crate::UplinkParser::push(self, byte)
    }
    fn poll(&mut self) -> Option<crate::Command> {
        // A command comes out on the byte that completes it: nothing waits for a later call.
        None
    }
    fn quiet(&mut self, _ms: u32) -> Option<crate::Command> {
        crate::UplinkParser::idle(self);
        None
    }
    fn buffered(&self) -> usize {
        crate::UplinkParser::buffered(self)
    }
    fn push_slice<'a>(&mut self, bytes: &'a [u8]) -> (Option<crate::Command>, &'a [u8]) {
        crate::UplinkParser::push_slice(self, bytes)
    }
    fn take_frame(&mut self, bytes: &mut &[u8]) -> Option<crate::Command> {
        let (frame, rest) = crate::UplinkParser::push_slice(self, bytes);
        *bytes = rest;
        frame
    }
}

#[cfg(test)]
mod tests {
    use super::Parser;
    use crate::v1;

    /// Every frame of `bytes` through the trait alone, in chunks of `chunk` bytes, then what
    /// the quiet line after them lets out.
    fn through<P: Parser>(parser: &mut P, bytes: &[u8], chunk: usize) -> Vec<P::Frame> {
        let mut out = Vec::new();
        for piece in bytes.chunks(chunk) {
            out.extend(parser.frames(piece));
        }
        out.extend(core::iter::from_fn(|| parser.quiet(5)));
        out
    }

    #[test]
    fn the_four_parsers_give_the_same_frames_through_the_trait_in_any_chunking() {
        let velocities = [crate::Velocity::new(0, 300, 0), crate::Velocity::STOP];
        let commands_2020 = velocities.map(crate::Command::Velocity);
        let commands_v1 = [
            v1::Command::BodyVelocity(v1::BodyVelocity::new(0, 300, 0)),
            v1::Command::Readback(v1::Readback::Geometry),
        ];
        let telemetry_v1 = [
            v1::Downlink::Telemetry(v1::Telemetry {
                battery_mv: 12_000,
                ..v1::Telemetry::default()
            }),
            v1::Downlink::Telemetry(v1::Telemetry {
                velocity: [0, 300, 0],
                ..v1::Telemetry::default()
            }),
        ];
        let up_2020: Vec<u8> = velocities.iter().flat_map(|v| v.encode()).collect();
        let up_v1: Vec<u8> = commands_v1.iter().flat_map(|c| c.encode()).collect();
        let down_v1: Vec<u8> = telemetry_v1
            .iter()
            .flat_map(|f| f.encode().to_vec())
            .collect();
        for chunk in [1, 3, 7, 64] {
            let got = through(&mut crate::UplinkParser::new(), &up_2020, chunk);
            assert_eq!(got, commands_2020, "2020 uplink, chunks of {chunk}");
            let got = through(&mut v1::UplinkParser::new(), &up_v1, chunk);
            assert_eq!(got, commands_v1, "v1.0.0 uplink, chunks of {chunk}");
            let got = through(&mut v1::DownlinkParser::new(), &down_v1, chunk);
            assert_eq!(got, telemetry_v1, "v1.0.0 downlink, chunks of {chunk}");
        }
    }

    #[test]
    fn a_frame_cut_short_by_a_quiet_line_is_thrown_away_by_each_parser() {
        let mut v1_down = v1::DownlinkParser::new();
        let cut = v1::Telemetry::default().encode();
        assert!(Parser::push_slice(&mut v1_down, &cut[..20]).0.is_none());
        assert_eq!(Parser::quiet(&mut v1_down, 5), None);
        assert_eq!(Parser::buffered(&v1_down), 0);
        let mut up = crate::UplinkParser::new();
        let velocity = crate::Velocity::new(0, 300, 0).encode();
        assert!(Parser::push_slice(&mut up, &velocity[..6]).0.is_none());
        assert_eq!(Parser::quiet(&mut up, 5), None);
        assert_eq!(Parser::buffered(&up), 0);
    }
}
