//! Board → master frames ("downlink"): three telemetry streams sent unprompted, and replies.
//!
//! | header | frame | length | rate | module |
//! |---|---|---|---|---|
//! | `FF FA` | [`Imu`] | 15 | 100 Hz | [`imu`] |
//! | `FF FB` | [`Encoders`] | 11 | 25 Hz | [`encoders`] |
//! | `FF FC` | [`Battery`] | 7 | 1 Hz | [`battery`] |
//! | `23` + code | [`Reply`] | 6 | once per read | [`reply`] |
//!
//! Each telemetry frame ends in a rolling count byte, one counter per [`Stream`].

pub mod battery;
pub mod encoders;
pub mod imu;
pub mod reply;

pub use battery::Battery;
pub use encoders::Encoders;
pub use imu::Imu;
pub use reply::Reply;

use crate::bytes::FrameBytes;
use crate::command::Register;
use crate::error::Error;

/// The longest board → master frame ([`Imu`]).
pub const MAX_LEN: usize = Imu::LEN;

/// The encoded bytes of a [`Downlink`] frame.
pub type DownlinkBytes = FrameBytes<MAX_LEN>;

/// Checks the length and two-byte header of a telemetry frame.
fn check_frame(bytes: &[u8], header: &[u8; 2], len: usize) -> Result<(), Error> {
    if bytes.len() != len {
        return Err(Error::Length);
    }
    if bytes.get(..2) != Some(&header[..]) {
        return Err(Error::Header);
    }
    Ok(())
}

/// What the three telemetry frames have alike, written once: the header and length, `encode`
/// (the header, the frame's own fields by its `write`, the count) and `decode` (length and
/// header checked, then its `read`). Used in each frame's module, whose `field` offsets it
/// names.
macro_rules! telemetry_frame {
    ($frame:ident, $header:expr, $len:literal, $what:literal) => {
        impl $frame {
            /// The frame's first two bytes.
            pub const HEADER: [u8; 2] = $header;
            /// Length of the frame on the wire.
            pub const LEN: usize = $len;

            #[doc = concat!("The ", stringify!($len), " bytes of this frame.")]
            #[must_use]
            pub fn encode(&self) -> [u8; Self::LEN] {
                let mut buf = [0u8; Self::LEN];
                $crate::wire::put(&mut buf, field::HEADER, &Self::HEADER);
                self.write(&mut buf);
                $crate::wire::put_u8(&mut buf, field::SEQ, self.seq);
                buf
            }

            #[doc = concat!("Decodes exactly one ", $what, " frame.")]
            pub fn decode(bytes: &[u8]) -> Result<Self, $crate::error::Error> {
                super::check_frame(bytes, &Self::HEADER, Self::LEN)?;
                bytes
                    .first_chunk()
                    .map(Self::read)
                    .ok_or($crate::error::Error::Length)
            }
        }
    };
}
use telemetry_frame;

/// One of the three telemetry streams, each with its own rolling count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Stream {
    /// `FF FA`, 100 Hz.
    Imu,
    /// `FF FB`, 25 Hz.
    Encoders,
    /// `FF FC`, 1 Hz.
    Battery,
}

impl Stream {
    /// The three streams, in header order; `Stream::ALL[s.index()] == s`.
    pub const ALL: [Stream; 3] = [Stream::Imu, Stream::Encoders, Stream::Battery];

    /// 0, 1, 2 for IMU, encoders, battery: an index for per-stream arrays.
    #[must_use]
    pub const fn index(self) -> usize {
        match self {
            Stream::Imu => 0,
            Stream::Encoders => 1,
            Stream::Battery => 2,
        }
    }

    /// Where a frame of this stream holds its count byte.
    #[must_use]
    pub(crate) const fn seq_at(self) -> usize {
        match self {
            Stream::Imu => imu::field::SEQ,
            Stream::Encoders => encoders::field::SEQ,
            Stream::Battery => battery::field::SEQ,
        }
    }

    /// The nominal rate in hertz.
    #[must_use]
    pub const fn rate_hz(self) -> u16 {
        match self {
            Stream::Imu => 100,
            Stream::Encoders => 25,
            Stream::Battery => 1,
        }
    }
}

/// The kind of a board → master frame, as its header tells it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Kind {
    /// A telemetry frame of this stream.
    Telemetry(Stream),
    /// A `#` reply.
    Reply,
}

impl Kind {
    /// The kind whose header is `first`, `second`. Replies count only with a reply code the
    /// spec defines ([`Register::from_reply_code`]), which is what a streaming parser wants:
    /// `23` is an ordinary byte in payloads.
    #[must_use]
    pub const fn from_header(first: u8, second: u8) -> Option<Kind> {
        // The headers are the frame modules' own constants: written once.
        match [first, second] {
            Imu::HEADER => Some(Kind::Telemetry(Stream::Imu)),
            Encoders::HEADER => Some(Kind::Telemetry(Stream::Encoders)),
            Battery::HEADER => Some(Kind::Telemetry(Stream::Battery)),
            [Reply::HEADER, code] if Register::from_reply_code(code).is_some() => Some(Kind::Reply),
            _ => None,
        }
    }

    /// Whether `first` can start a frame (`FF` or `23`).
    #[must_use]
    pub const fn may_start(first: u8) -> bool {
        let [sync, _] = Imu::HEADER;
        first == sync || first == Reply::HEADER
    }

    /// The frame's length on the wire.
    #[must_use]
    pub const fn len(self) -> usize {
        match self {
            Kind::Telemetry(Stream::Imu) => Imu::LEN,
            Kind::Telemetry(Stream::Encoders) => Encoders::LEN,
            Kind::Telemetry(Stream::Battery) => Battery::LEN,
            Kind::Reply => Reply::LEN,
        }
    }

    /// Always `false` (here for symmetry with [`Kind::len`]).
    #[must_use]
    pub const fn is_empty(self) -> bool {
        false
    }
}

/// Any board → master frame: one of the three telemetry streams, or a reply. Named for the
/// direction: a reply is not telemetry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Downlink {
    /// `FF FA`.
    Imu(Imu),
    /// `FF FB`.
    Encoders(Encoders),
    /// `FF FC`.
    Battery(Battery),
    /// `23`.
    Reply(Reply),
}

impl Downlink {
    /// The frame's kind.
    #[must_use]
    pub const fn kind(&self) -> Kind {
        match self {
            Downlink::Imu(_) => Kind::Telemetry(Stream::Imu),
            Downlink::Encoders(_) => Kind::Telemetry(Stream::Encoders),
            Downlink::Battery(_) => Kind::Telemetry(Stream::Battery),
            Downlink::Reply(_) => Kind::Reply,
        }
    }

    /// The rolling count, for telemetry; `None` for a reply.
    #[must_use]
    pub const fn seq(&self) -> Option<u8> {
        match self {
            Downlink::Imu(f) => Some(f.seq),
            Downlink::Encoders(f) => Some(f.seq),
            Downlink::Battery(f) => Some(f.seq),
            Downlink::Reply(_) => None,
        }
    }

    /// The frame's bytes.
    #[must_use]
    pub fn encode(&self) -> DownlinkBytes {
        match self {
            Downlink::Imu(f) => DownlinkBytes::new(&f.encode()),
            Downlink::Encoders(f) => DownlinkBytes::new(&f.encode()),
            Downlink::Battery(f) => DownlinkBytes::new(&f.encode()),
            Downlink::Reply(f) => DownlinkBytes::new(&f.encode()),
        }
    }

    /// Decodes exactly one frame of any kind. Unlike [`Kind::from_header`], a reply with an
    /// unknown code decodes (it is kept, not rejected).
    pub fn decode(bytes: &[u8]) -> Result<Self, Error> {
        match bytes {
            [first, second, ..] => match [*first, *second] {
                Imu::HEADER => Imu::decode(bytes).map(Downlink::Imu),
                Encoders::HEADER => Encoders::decode(bytes).map(Downlink::Encoders),
                Battery::HEADER => Battery::decode(bytes).map(Downlink::Battery),
                [Reply::HEADER, _] => Reply::decode(bytes).map(Downlink::Reply),
                _ => Err(Error::Header),
            },
            [Reply::HEADER] => Reply::decode(bytes).map(Downlink::Reply),
            [first] if Kind::may_start(*first) => Err(Error::Length),
            [] => Err(Error::Length),
            _ => Err(Error::Header),
        }
    }
}

impl Downlink {
    /// The frame of `kind` whose header starts `bytes` (the caller has checked it): a reply's
    /// bytes exactly; a telemetry frame's first, if all of it is there (bytes after it are left
    /// alone). The parser's way in: no second look at a telemetry header, its fields read
    /// through fixed-size arrays. (Out of line: inlined into the judgement, its decoders cost
    /// flash twice.)
    #[inline(never)]
    pub(crate) fn read(kind: Kind, bytes: &[u8]) -> Option<Downlink> {
        match kind {
            Kind::Telemetry(stream) => Downlink::read_telemetry(stream, bytes),
            Kind::Reply => Reply::decode(bytes.get(..Reply::LEN)?)
                .ok()
                .map(Downlink::Reply),
        }
    }

    /// [`read`](Self::read) for a telemetry frame of `stream`.
    #[inline]
    pub(crate) fn read_telemetry(stream: Stream, bytes: &[u8]) -> Option<Downlink> {
        match stream {
            Stream::Imu => bytes.first_chunk().map(Imu::read).map(Downlink::Imu),
            Stream::Encoders => bytes
                .first_chunk()
                .map(Encoders::read)
                .map(Downlink::Encoders),
            Stream::Battery => bytes
                .first_chunk()
                .map(Battery::read)
                .map(Downlink::Battery),
        }
    }
}

impl From<Imu> for Downlink {
    fn from(f: Imu) -> Self {
        Downlink::Imu(f)
    }
}

impl From<Encoders> for Downlink {
    fn from(f: Encoders) -> Self {
        Downlink::Encoders(f)
    }
}

impl From<Battery> for Downlink {
    fn from(f: Battery) -> Self {
        Downlink::Battery(f)
    }
}

impl From<Reply> for Downlink {
    fn from(f: Reply) -> Self {
        Downlink::Reply(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_from_headers() {
        assert_eq!(
            Kind::from_header(0xFF, 0xFA),
            Some(Kind::Telemetry(Stream::Imu))
        );
        assert_eq!(
            Kind::from_header(0xFF, 0xFB),
            Some(Kind::Telemetry(Stream::Encoders))
        );
        assert_eq!(
            Kind::from_header(0xFF, 0xFC),
            Some(Kind::Telemetry(Stream::Battery))
        );
        assert_eq!(Kind::from_header(0xFF, 0xFE), None);
        assert_eq!(Kind::from_header(0xFF, 0xFD), None);
        assert_eq!(Kind::from_header(0x23, 0x20), Some(Kind::Reply));
        assert_eq!(Kind::from_header(0x23, 0x02), None);
        let lens =
            [Stream::Imu, Stream::Encoders, Stream::Battery].map(|s| Kind::Telemetry(s).len());
        assert_eq!(lens, [15, 11, 7]);
        assert_eq!(Kind::Reply.len(), 6);
    }

    #[test]
    fn decode_any() {
        let battery = [0xFF, 0xFC, 0x04, 0x4C, 0x00, 0x57, 0x03];
        let frame = Downlink::decode(&battery).unwrap();
        assert_eq!(frame.kind(), Kind::Telemetry(Stream::Battery));
        assert_eq!(frame.seq(), Some(3));
        assert_eq!(frame.encode().as_slice(), &battery);
        assert_eq!(Downlink::decode(&[0xFF]), Err(Error::Length));
        assert_eq!(
            Downlink::decode(&[0xFF, 0xFE, 0, 0, 0, 0, 0]),
            Err(Error::Header)
        );
        assert_eq!(
            Downlink::decode(&[0x23, 0x99, 0, 0, 0, 0]).map(|f| f.seq()),
            Ok(None)
        );
    }

    #[test]
    fn stream_indexes() {
        for (i, s) in Stream::ALL.iter().enumerate() {
            assert_eq!(s.index(), i);
        }
    }
}
