//! Which firmware a board runs: the 2020 one (`FF FE` commands, `FF FA/FB/FC` telemetry) or
//! v1.0.0 (`7B … BCC 7D`), told from what it sends.
//!
//! [`Detector`] is sans-IO: feed it what the line brings, and it says which generation the
//! frames belong to once one has clearly more ([`Detector::verdict`]). With the `driver`
//! feature, `detect()` runs it on a UART: it **listens first**, and only if that does not
//! decide, sends two **harmless probes** ([`PROBE_2020`], [`PROBE_V1`]: a register read of each
//! generation, never a motion, settings or action frame), then listens again.
//!
//! A probe is harmless to the other generation too: its bytes, alone or between the frames of
//! the other generation's commands, decode as nothing in that generation's master → board
//! parser, and every frame around them decodes as sent (`host-tests/tests/detect.rs`).
//!
//! ```
//! use chassis_protocol::detect::{Detector, Firmware};
//! use chassis_protocol::v1::Telemetry;
//!
//! let mut detector = Detector::new();
//! for _ in 0..3 {
//!     detector.feed(&Telemetry { battery_mv: 11_800, ..Telemetry::default() }.encode());
//! }
//! assert_eq!(detector.verdict(), Some(Firmware::V1_0_0));
//! ```

use crate::command::Register;
use crate::{DownlinkParser, v1};

/// A firmware generation of the board.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Firmware {
    /// The 2020 firmware: `FF FE` commands, `FF FA/FB/FC` telemetry, `#` replies, no checksum.
    V2020,
    /// Firmware v1.0.0 (2023): `7B … BCC 7D` frames.
    V1_0_0,
}

impl Firmware {
    /// Every generation, oldest first.
    pub const ALL: [Firmware; 2] = [Firmware::V2020, Firmware::V1_0_0];

    /// Its name as owners know it: `2020` or `v1.0.0`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Firmware::V2020 => "2020",
            Firmware::V1_0_0 => "v1.0.0",
        }
    }

    /// The generation `name` names: `2020`, `v1.0.0` or `v1` (as [`Firmware::name`] writes it,
    /// and v1.0.0's short form). Nothing else: `None`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Firmware> {
        match name {
            "2020" => Some(Firmware::V2020),
            "v1.0.0" | "v1" => Some(Firmware::V1_0_0),
            _ => None,
        }
    }

    /// How its frames look.
    #[must_use]
    pub const fn framing(self) -> &'static str {
        match self {
            Firmware::V2020 => "FF FE / FF FA-FC frames",
            Firmware::V1_0_0 => "7B … BCC 7D frames",
        }
    }
}

/// The 2020 probe: a read of the motor voltage (2C: `FF FE 80 80 1B 00 00 00 00 00`). The
/// board answers with a `#` reply; nothing moves, nothing is written.
pub const PROBE_2020: [u8; 10] = [0xFF, 0xFE, 0x80, 0x80, 0x1B, 0, 0, 0, 0, 0];

/// The v1.0.0 probe: the readback request of the system settings, as the vendor sends it
/// (`7B 33`, ten `00`, BCC `48`, `7D`). The board answers with a 14-byte reply.
pub const PROBE_V1: [u8; v1::COMMAND_LEN] = [0x7B, 0x33, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x48, 0x7D];

/// The register [`PROBE_2020`] reads.
pub const PROBE_2020_REGISTER: Register = Register::MotorVoltage;

/// Frames of one generation that decide, when the other has none (a 2020 board sends about
/// 126 a second, a v1.0.0 board 20–24): v1.0.0 frames carry a BCC, so two suffice.
const DECIDING_2020: u32 = 3;
const DECIDING_V1: u32 = 2;

/// What the line brought, by generation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Heard {
    /// Bytes in all.
    pub bytes: u32,
    /// 2020 frames (telemetry and replies).
    pub frames_2020: u32,
    /// v1.0.0 frames (telemetry and replies), each with its BCC right.
    pub frames_v1: u32,
    /// Of them, replies (to the probes).
    pub replies_2020: u32,
    /// Of them, replies (to the probes).
    pub replies_v1: u32,
    /// v1.0.0 frames whose BCC was wrong (a noisy line, or bytes of neither).
    pub bad_checksum_v1: u32,
}

/// Both generations' board → master parsers side by side, counting what each finds.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Detector {
    ff: DownlinkParser,
    v1: v1::DownlinkParser,
    heard: Heard,
}

impl Detector {
    /// A detector that has heard nothing.
    #[must_use]
    pub const fn new() -> Self {
        Detector {
            ff: DownlinkParser::new(),
            v1: v1::DownlinkParser::new(),
            heard: Heard {
                bytes: 0,
                frames_2020: 0,
                frames_v1: 0,
                replies_2020: 0,
                replies_v1: 0,
                bad_checksum_v1: 0,
            },
        }
    }

    /// Takes bytes from the line.
    pub fn feed(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.heard.bytes = self.heard.bytes.saturating_add(1);
            if let Some(frame) = self.ff.push(byte) {
                self.count_2020(&frame);
            }
            let mut next = self.v1.push(byte);
            while let Some(frame) = next {
                self.heard.frames_v1 = self.heard.frames_v1.saturating_add(1);
                if matches!(frame, v1::Downlink::Reply(_)) {
                    self.heard.replies_v1 = self.heard.replies_v1.saturating_add(1);
                }
                next = self.v1.poll();
            }
        }
        self.heard.bad_checksum_v1 = self.v1.stats().bad_checksum;
    }

    /// The line was quiet for `ms` (the 2020 parser judges a frame held for what follows).
    pub fn quiet(&mut self, ms: u32) {
        while let Some(frame) = self.ff.quiet(ms) {
            self.count_2020(&frame);
        }
    }

    /// [`PROBE_2020`] was sent: its reply is awaited.
    pub fn probed(&mut self) {
        self.ff.expect_reply(Some(PROBE_2020_REGISTER));
    }

    fn count_2020(&mut self, frame: &crate::Downlink) {
        self.heard.frames_2020 = self.heard.frames_2020.saturating_add(1);
        if matches!(frame, crate::Downlink::Reply(_)) {
            self.heard.replies_2020 = self.heard.replies_2020.saturating_add(1);
        }
    }

    /// What was heard so far.
    #[must_use]
    pub const fn heard(&self) -> Heard {
        self.heard
    }

    /// The generation whose frames were heard, once it is clear: at least two v1.0.0 frames
    /// (or one reply) and four times the 2020 ones, or three 2020 frames (or one reply) and
    /// none of v1.0.0.
    #[must_use]
    pub fn verdict(&self) -> Option<Firmware> {
        let h = &self.heard;
        let v1 = h.frames_v1 >= DECIDING_V1 || h.replies_v1 > 0;
        if v1 && h.frames_v1 >= h.frames_2020.saturating_mul(4) {
            return Some(Firmware::V1_0_0);
        }
        let ff = h.frames_2020 >= DECIDING_2020 || h.replies_2020 > 0;
        if ff && h.frames_v1 == 0 {
            return Some(Firmware::V2020);
        }
        None
    }
}

/// How [`detect`] ended.
#[cfg(feature = "driver")]
#[cfg_attr(docsrs, doc(cfg(feature = "driver")))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Detection {
    /// The generation, if the frames said.
    pub firmware: Option<Firmware>,
    /// What was heard.
    pub heard: Heard,
    /// Whether the probes were sent (the line said nothing clear while listening).
    pub probed: bool,
    /// How long it took, in ms.
    pub elapsed_ms: u64,
}

/// How long [`detect`] listens before it probes, and again after: a 2020 board sends about 50
/// frames in that time, a v1.0.0 board about 9.
#[cfg(feature = "driver")]
#[cfg_attr(docsrs, doc(cfg(feature = "driver")))]
pub const LISTEN_MS: u64 = 400;

/// Between the two probes, so that each is a frame of its own on the line.
#[cfg(feature = "driver")]
#[cfg_attr(docsrs, doc(cfg(feature = "driver")))]
pub const PROBE_GAP_MS: u64 = 20;

/// Polls in a row that see the clock stand still before [`detect`] gives up (a clock that never
/// moves would otherwise hang it).
#[cfg(feature = "driver")]
#[cfg_attr(docsrs, doc(cfg(feature = "driver")))]
pub const STALL_POLLS: u32 = 1_000_000;

/// A line that carried fewer bytes than this while [`detect`] listened is quiet (a glitch or
/// two at power-up); a board of either generation sends hundreds in that time.
#[cfg(feature = "driver")]
const QUIET_BELOW_BYTES: u32 = 16;

/// Finds the firmware generation of the board on `uart`: listens [`LISTEN_MS`]; if that does
/// not decide and the line was quiet (a few bytes at most), sends [`PROBE_2020`], then
/// [`PROBE_V1`] [`PROBE_GAP_MS`] later, and listens [`LISTEN_MS`] again. Bytes of neither
/// generation (another device, another baud rate) get no probe. Sends nothing else, ever. Returns within about a second (or once the
/// clock is found standing still); a transport error ends it with that error.
///
/// Run it on a driverless UART, before a driver takes it; `config.idle_ms` says how long a
/// quiet line is (2 ms on a UART, 40 behind a USB-UART adapter).
#[cfg(feature = "driver")]
#[cfg_attr(docsrs, doc(cfg(feature = "driver")))]
pub fn detect<U, C>(
    uart: &mut U,
    clock: &mut C,
    config: &crate::driver::Config,
) -> Result<Detection, U::Error>
where
    U: embedded_io::Read + embedded_io::Write + embedded_io::ReadReady,
    C: crate::driver::Clock,
{
    let start = clock.now_ms();
    let mut detector = Detector::new();
    let mut line = Listener {
        quiet_from_ms: start,
        idle_ms: u64::from(config.idle_ms),
    };
    let mut probed = false;
    if !line.listen(uart, clock, &mut detector, start, LISTEN_MS)?
        && detector.heard().bytes < QUIET_BELOW_BYTES
    {
        probed = true;
        write_all(uart, &PROBE_2020)?;
        detector.probed();
        let sent = clock.now_ms();
        line.listen(uart, clock, &mut detector, sent, PROBE_GAP_MS)?;
        write_all(uart, &PROBE_V1)?;
        let sent = clock.now_ms();
        line.listen(uart, clock, &mut detector, sent, LISTEN_MS)?;
    }
    Ok(Detection {
        firmware: detector.verdict(),
        heard: detector.heard(),
        probed,
        elapsed_ms: clock.now_ms().saturating_sub(start),
    })
}

#[cfg(feature = "driver")]
struct Listener {
    quiet_from_ms: u64,
    idle_ms: u64,
}

#[cfg(feature = "driver")]
impl Listener {
    /// Feeds `detector` until `for_ms` from `from` have passed or it has a verdict (`true`).
    fn listen<U, C>(
        &mut self,
        uart: &mut U,
        clock: &mut C,
        detector: &mut Detector,
        from: u64,
        for_ms: u64,
    ) -> Result<bool, U::Error>
    where
        U: embedded_io::Read + embedded_io::ReadReady,
        C: crate::driver::Clock,
    {
        let mut buf = [0u8; 64];
        let mut still = 0u32;
        let mut last = from;
        loop {
            let now = clock.now_ms();
            if detector.verdict().is_some() {
                return Ok(true);
            }
            if now.saturating_sub(from) >= for_ms {
                return Ok(false);
            }
            if now == last {
                still = still.saturating_add(1);
                if still >= STALL_POLLS {
                    return Ok(false);
                }
            } else {
                still = 0;
                last = now;
            }
            if uart.read_ready()? {
                let n = uart.read(&mut buf)?;
                detector.feed(buf.get(..n).unwrap_or(&[]));
                if n > 0 {
                    self.quiet_from_ms = now;
                }
            } else if now.saturating_sub(self.quiet_from_ms) >= self.idle_ms {
                let ms = u32::try_from(now.saturating_sub(self.quiet_from_ms)).unwrap_or(u32::MAX);
                self.quiet_from_ms = now;
                detector.quiet(ms);
            }
        }
    }
}

#[cfg(feature = "driver")]
fn write_all<U: embedded_io::Write>(uart: &mut U, mut bytes: &[u8]) -> Result<(), U::Error> {
    while !bytes.is_empty() {
        let n = uart.write(bytes)?;
        if n == 0 {
            // A UART that takes nothing: the probe is not sent; listening says the rest.
            return Ok(());
        }
        bytes = bytes.get(n..).unwrap_or(&[]);
    }
    uart.flush()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::Setting;

    #[test]
    fn the_probes_are_the_reads_they_claim() {
        assert_eq!(
            Setting::Read(PROBE_2020_REGISTER).encode(),
            PROBE_2020,
            "2C: FF FE 80 80 1B"
        );
        assert_eq!(
            v1::Command::decode(&PROBE_V1),
            Ok(v1::Command::Readback(v1::Readback::System))
        );
    }

    #[test]
    fn a_2020_stream_is_2020_and_a_v1_stream_is_v1() {
        // IMU frames every 10 ms, the line quiet between them, as a 2020 board sends them.
        let imu = |seq| {
            crate::Imu {
                seq,
                ..crate::Imu::default()
            }
            .encode()
        };
        let mut d = Detector::new();
        let mut fed = 0;
        while d.verdict().is_none() && fed < 40 {
            d.feed(&imu(fed));
            d.quiet(9);
            fed += 1;
        }
        assert_eq!(d.verdict(), Some(Firmware::V2020), "{:?}", d.heard());
        assert!(
            fed <= 5,
            "decided after {fed} frames (50 ms of a 2020 board)"
        );

        let mut d = Detector::new();
        d.feed(&v1::Telemetry::default().encode());
        assert_eq!(d.verdict(), None);
        d.feed(&v1::Telemetry::default().encode());
        assert_eq!(d.verdict(), Some(Firmware::V1_0_0));
    }

    #[test]
    fn bytes_of_neither_decide_nothing() {
        let mut d = Detector::new();
        let mut x = 0x1234_5678u32;
        for _ in 0..10_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            d.feed(&x.to_le_bytes());
        }
        d.quiet(50);
        assert_eq!(d.verdict(), None, "{:?}", d.heard());
        assert_eq!(d.heard().bytes, 40_000);
    }
}
