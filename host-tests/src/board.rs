//! A realistic board → master byte stream: telemetry at the board's rates, with the payloads of a
//! chassis at rest or moving slowly (so gyro and accel values sit around zero, and `FF FA`..`FF FC`
//! turn up inside payloads as on the real board), and `#` replies interleaved.
//!
//! Time runs at 115 200 bps (11 520 bytes/s); frames are written back to back, with no idle
//! line between them: the hardest case for resynchronisation, since a quiet line would mark
//! every boundary.

use crate::replies::Replies;
use chassis_protocol::{Battery, Downlink, Encoders, Imu, Register, Reply};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// One frame as sent: where it starts in the byte stream, and what it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SentFrame {
    /// Offset of its first byte in the sent stream.
    pub start: usize,
    /// The frame.
    pub frame: Downlink,
}

impl SentFrame {
    /// Offset one past its last byte.
    pub fn end(&self) -> usize {
        self.start + self.frame.encode().len()
    }
}

/// What the telemetry values look like.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Payload {
    /// A chassis at rest or moving slowly: values around zero, so `FF FA`..`FF FC` turn up as
    /// a gyro or accel reads -6..-4 (about a tenth of the 16-bit values).
    Rest,
    /// Written to fool a parser: about a third of all 16-bit fields read `FF FA`..`FF FC`, a
    /// third `23` and a reply code; reply values likewise.
    Adversarial,
    /// Every payload byte (values and counts aside) drawn from `FF FA FB FC 23` and the reply
    /// codes: lookalike headers and `#`s everywhere, far denser than [`Adversarial`](Self::Adversarial).
    Headers,
    /// Every telemetry value reads -6..-4 (`FF FA`..`FF FC`): a telemetry header at every
    /// other byte of every payload, and a count byte (`FA`..`FC`) at every byte after one.
    Lookalikes,
}

/// What the count byte counts (A10: the vendor does not say).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CountModel {
    /// One counter per stream, each stepping by its own amount (IMU, encoders, battery).
    PerStream([u8; 3]),
    /// One counter shared by all three streams, +1 per telemetry frame.
    Shared,
    /// A 10 ms time tick: IMU +1, encoders +4, battery +100.
    Tick,
    /// One counter shared by all three streams, stepping by this constant per telemetry frame.
    SharedStep(u8),
}

impl CountModel {
    /// The models the parser must work under.
    pub const ALL: [(&'static str, CountModel); 4] = [
        ("per stream +1", CountModel::PerStream([1, 1, 1])),
        ("per stream +2/+3/+5", CountModel::PerStream([2, 3, 5])),
        ("one shared counter", CountModel::Shared),
        ("10 ms tick", CountModel::Tick),
    ];
}

/// A quiet stretch of line before the frame that starts at `offset`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Gap {
    /// Offset of the first byte after the quiet stretch.
    pub offset: usize,
    /// How long the line was quiet, in ms (at least 1).
    pub ms: u32,
}

/// A stream with its timing: what [`BoardStream::take_timed`] gives.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Timed {
    /// The bytes, frames back to back as sent.
    pub bytes: Vec<u8>,
    /// Each frame with its offset.
    pub sent: Vec<SentFrame>,
    /// The quiet stretches of the line.
    pub gaps: Vec<Gap>,
    /// When each frame's first byte went out, µs from the start (one per frame of `sent`).
    pub start_us: Vec<u64>,
}

impl Timed {
    /// When each byte has arrived whole at the receiver, µs (86.8 µs per byte at 115 200 bps).
    pub fn byte_done_us(&self) -> Vec<u64> {
        let mut done = Vec::with_capacity(self.bytes.len());
        for (frame, start_us) in self.sent.iter().zip(&self.start_us) {
            for i in 1..=frame.frame.encode().len() as u64 {
                done.push(start_us + i * 1_000_000 / 11_520);
            }
        }
        done
    }
}

/// A read the master sent, as the master knows it: its reply is awaited from the sent byte at
/// `from` until the one at `until` (the reply timeout), unless it comes first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Read {
    /// Offset in the sent stream from which the reply is awaited.
    pub from: usize,
    /// Offset in the sent stream at which the master gives up waiting.
    pub until: usize,
    /// The register read.
    pub register: Register,
}

/// The driver's reply timeout at 115 200 bps (55 ms), in bytes of line time (11.52 per ms).
pub const READ_TIMEOUT_BYTES: usize = 55 * 11_520 / 1_000;

/// The reads behind the replies in `sent`, as the master that sent them knows them (what the
/// driver tells its parser, and what a capture decoded with its master → board side shows).
/// Each reply is awaited from the start of the frame sent before it (the board finishes the
/// frame it is sending, then answers), until [`READ_TIMEOUT_BYTES`] after that.
pub fn reads_behind(sent: &[SentFrame]) -> Vec<Read> {
    let mut reads = Vec::new();
    let mut before = 0usize;
    for f in sent {
        if let Downlink::Reply(reply) = f.frame {
            if let Some(register) = reply.register() {
                reads.push(Read {
                    from: before,
                    until: before + READ_TIMEOUT_BYTES,
                    register,
                });
            }
        }
        before = f.start;
    }
    reads
}

/// The board's telemetry generator.
#[derive(Clone, Debug)]
pub struct BoardStream {
    payload: Payload,
    counts: CountModel,
    shared: u8,
    rng: Pcg64Mcg,
    /// Time in microseconds.
    now_us: u64,
    next_imu_us: u64,
    next_encoders_us: u64,
    next_battery_us: u64,
    replies: Replies,
    seq: [u8; 3],
    wheel_speed: [i16; 4],
    wheel_total: [i16; 4],
    centivolts: u16,
}

impl BoardStream {
    /// A board that starts at a random phase, with `replies_per_second` replies on average.
    pub fn new(seed: u64, replies_per_second: f64) -> Self {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let seq = [rng.random(), rng.random(), rng.random()];
        BoardStream {
            payload: Payload::Rest,
            counts: CountModel::PerStream([1, 1, 1]),
            shared: 0,
            next_imu_us: rng.random_range(0..10_000),
            next_encoders_us: rng.random_range(0..40_000),
            next_battery_us: rng.random_range(0..1_000_000),
            replies: Replies::new(&mut rng, replies_per_second),
            rng,
            now_us: 0,
            seq,
            wheel_speed: [0; 4],
            wheel_total: [0; 4],
            centivolts: 1_240,
        }
    }

    /// The same board with other payloads and another count model.
    pub fn with_models(mut self, payload: Payload, counts: CountModel) -> Self {
        self.payload = payload;
        self.counts = counts;
        self.shared = self.rng.random();
        self
    }

    /// A small value around zero, as a sensor at rest reads; with adversarial payloads, often a
    /// header or `#` and a reply code instead.
    fn around_zero(&mut self, spread: i16) -> i16 {
        if self.payload == Payload::Adversarial {
            match self.rng.random_range(0..3) {
                0 => return self.rng.random_range(-6..=-4),
                1 => return self.hash_and_code() as i16,
                _ => {}
            }
        }
        self.rng.random_range(-spread..=spread)
    }

    /// `23` followed by a reply code the spec defines, as a 16-bit value.
    fn hash_and_code(&mut self) -> u16 {
        let codes = [0x01, 0x06, 0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x20];
        0x2300 | codes[self.rng.random_range(0..codes.len())]
    }

    /// A byte that starts or continues a lookalike: `FF`, `FA`..`FC`, `23` or a reply code.
    fn header_byte(&mut self) -> u8 {
        const BYTES: [u8; 14] = [
            0xFF, 0xFA, 0xFB, 0xFC, 0x23, 0x01, 0x06, 0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x20,
        ];
        BYTES[self.rng.random_range(0..BYTES.len())]
    }

    /// Two [`header_byte`](Self::header_byte)s as a big-endian 16-bit value.
    fn header_word(&mut self) -> u16 {
        u16::from_be_bytes([self.header_byte(), self.header_byte()])
    }

    /// A telemetry frame or reply whose payload is header bytes only ([`Payload::Headers`]).
    fn headers_frame(&mut self, frame: Downlink) -> Downlink {
        match frame {
            Downlink::Reply(reply) => {
                let value = (u32::from(self.header_word()) << 16) | u32::from(self.header_word());
                Downlink::Reply(Reply {
                    code: reply.code,
                    value,
                })
            }
            telemetry => with_values(telemetry, || self.header_word() as i16),
        }
    }

    /// A telemetry frame whose values all read -6..-4 ([`Payload::Lookalikes`]); a reply as
    /// it is.
    fn lookalikes_frame(&mut self, frame: Downlink) -> Downlink {
        with_values(frame, || self.rng.random_range(-6..=-4i16))
    }

    fn next_seq(&mut self, stream: usize) -> u8 {
        match self.counts {
            CountModel::PerStream(steps) => {
                let slot = &mut self.seq[stream];
                *slot = slot.wrapping_add(steps[stream]);
                *slot
            }
            CountModel::Shared => {
                self.shared = self.shared.wrapping_add(1);
                self.shared
            }
            CountModel::SharedStep(step) => {
                self.shared = self.shared.wrapping_add(step);
                self.shared
            }
            CountModel::Tick => (self.now_us / 10_000) as u8,
        }
    }

    fn imu(&mut self) -> Downlink {
        let accel = [
            self.around_zero(40),
            self.around_zero(40),
            16_384 + self.around_zero(40),
        ];
        let gyro = [
            self.around_zero(8),
            self.around_zero(8),
            self.around_zero(8),
        ];
        Downlink::Imu(Imu {
            accel,
            gyro,
            seq: self.next_seq(0),
        })
    }

    fn encoders(&mut self) -> Downlink {
        for wheel in 0..4 {
            let change = self.around_zero(3);
            self.wheel_speed[wheel] = (self.wheel_speed[wheel] + change).clamp(-40, 40);
            self.wheel_total[wheel] = self.wheel_total[wheel].wrapping_add(self.wheel_speed[wheel]);
        }
        Downlink::Encoders(Encoders {
            ticks: self.wheel_total,
            seq: self.next_seq(1),
        })
    }

    fn battery(&mut self) -> Downlink {
        self.centivolts = self.centivolts.saturating_sub(self.rng.random_range(0..2));
        let percent = (self.centivolts.saturating_sub(1_050) / 2).min(100);
        Downlink::Battery(Battery {
            centivolts: self.centivolts,
            percent,
            seq: self.next_seq(2),
        })
    }

    fn reply(&mut self) -> Downlink {
        let register = Register::ALL[self.rng.random_range(0..Register::ALL.len())];
        let value = match register {
            Register::PendingAngle => self.rng.random_range(-1_800i32..=1_800) as u32,
            Register::SystemMode => self.rng.random_range(0..0x1000),
            Register::BatteryRange => 0x7FFF_7FFF,
            Register::MotorVoltage => 1_200,
            _ => self.rng.random_range(0..100_000),
        };
        let value = if self.payload == Payload::Adversarial && self.rng.random_bool(0.5) {
            let high = match self.rng.random_range(0..2) {
                0 => 0xFFFA + self.rng.random_range(0..3),
                _ => self.hash_and_code(),
            };
            (u32::from(high) << 16) | (value & 0xFFFF)
        } else {
            value
        };
        Downlink::Reply(Reply::new(register, value))
    }

    /// The next frame the board sends, and advances time past it.
    pub fn next_frame(&mut self) -> Downlink {
        self.next_frame_after_quiet().0
    }

    /// The next frame, and how long the line was quiet before it, in µs.
    fn next_frame_after_quiet(&mut self) -> (Downlink, u64) {
        let due = self
            .next_imu_us
            .min(self.next_encoders_us)
            .min(self.next_battery_us)
            .min(self.replies.next_us());
        let quiet_us = due.saturating_sub(self.now_us);
        self.now_us = self.now_us.max(due);
        let frame = if due == self.next_imu_us {
            self.next_imu_us += 10_000;
            self.imu()
        } else if due == self.next_encoders_us {
            self.next_encoders_us += 40_000;
            self.encoders()
        } else if due == self.next_battery_us {
            self.next_battery_us += 1_000_000;
            self.battery()
        } else {
            self.replies.sent(&mut self.rng);
            self.reply()
        };
        let frame = match self.payload {
            Payload::Headers => self.headers_frame(frame),
            Payload::Lookalikes => self.lookalikes_frame(frame),
            _ => frame,
        };
        // 86.8 us per byte at 115 200 bps, 8N1.
        self.now_us += frame.encode().len() as u64 * 1_000_000 / 11_520;
        (frame, quiet_us)
    }

    /// [`take`](Self::take), with the quiet stretches of the line: the board sends each frame
    /// when it falls due, so the line is idle between most frames (about 85 % of the time).
    /// The bytes are the same as `take` gives; a master that watches the line sees the gaps.
    pub fn take_with_gaps(&mut self, count: usize) -> (Vec<u8>, Vec<SentFrame>, Vec<Gap>) {
        let timed = self.take_timed(count);
        (timed.bytes, timed.sent, timed.gaps)
    }

    /// [`take_with_gaps`](Self::take_with_gaps), with when each frame's first byte went out.
    pub fn take_timed(&mut self, count: usize) -> Timed {
        let mut timed = Timed {
            bytes: Vec::with_capacity(count * 15),
            sent: Vec::with_capacity(count),
            gaps: Vec::new(),
            start_us: Vec::with_capacity(count),
        };
        for _ in 0..count {
            let (frame, quiet_us) = self.next_frame_after_quiet();
            // Two characters' time or more is a gap a UART's idle-line detection sees.
            if quiet_us >= 200 && !timed.bytes.is_empty() {
                timed.gaps.push(Gap {
                    offset: timed.bytes.len(),
                    ms: (quiet_us / 1_000).max(1) as u32,
                });
            }
            let len = frame.encode().len() as u64;
            timed.start_us.push(self.now_us - len * 1_000_000 / 11_520);
            timed.sent.push(SentFrame {
                start: timed.bytes.len(),
                frame,
            });
            timed.bytes.extend_from_slice(&frame.encode());
        }
        timed
    }

    /// `count` frames, back to back: the bytes, and each frame with its offset.
    pub fn take(&mut self, count: usize) -> (Vec<u8>, Vec<SentFrame>) {
        let mut bytes = Vec::with_capacity(count * 15);
        let mut frames = Vec::with_capacity(count);
        for _ in 0..count {
            let frame = self.next_frame();
            frames.push(SentFrame {
                start: bytes.len(),
                frame,
            });
            bytes.extend_from_slice(&frame.encode());
        }
        (bytes, frames)
    }
}

/// `count` frames of the board simulator's own output ([`chassis_protocol::sim::Board`]): its
/// telemetry at real rates, and a register read every half second whose reply comes while
/// telemetry pauses (as the spec says it does during settings). Frame boundaries are found by
/// decoding the clean output in order.
pub fn simulator_stream(seed: u64, count: usize) -> (Vec<u8>, Vec<SentFrame>) {
    let (bytes, frames, _) = simulator_bursts(seed, count);
    (bytes, frames)
}

/// [`simulator_stream`], with where each burst of bytes ends: the board sends what falls due
/// back to back, at the line's pace, then the line is idle until the next frame is due
/// (telemetry takes about 15 % of the line). A burst ends after a millisecond with no byte;
/// every burst ends on a frame boundary.
pub fn simulator_bursts(seed: u64, count: usize) -> (Vec<u8>, Vec<SentFrame>, Vec<usize>) {
    use chassis_protocol::sim::{Board, SimConfig};
    use chassis_protocol::{Kind, Register, Setting};
    let mut burst_ends = Vec::new();
    let mut board = Board::new(SimConfig {
        seed,
        ..SimConfig::default()
    });
    let mut bytes = Vec::with_capacity(count * 15);
    let mut buf = [0u8; 256];
    let mut ms = 0u64;
    // About 126 frames a second; stop once enough bytes for `count` frames have come.
    while bytes.len() < count * 15 {
        ms += 1;
        if ms.is_multiple_of(500) {
            let register = Register::ALL[(ms / 500) as usize % Register::ALL.len()];
            board.receive(&Setting::Read(register).encode());
        }
        board.advance(ms);
        let n = board.transmit(&mut buf);
        bytes.extend_from_slice(&buf[..n]);
        // The simulated line carries bytes at 115 200 bps, so a frame spans two milliseconds;
        // a burst ends when a millisecond passes with no byte.
        if n == 0 && burst_ends.last() != Some(&bytes.len()) && !bytes.is_empty() {
            burst_ends.push(bytes.len());
        }
    }
    if burst_ends.last() != Some(&bytes.len()) {
        burst_ends.push(bytes.len());
    }
    let mut frames = Vec::with_capacity(count);
    let mut at = 0;
    while let [a, b, ..] = bytes[at..] {
        let Some(kind) = Kind::from_header(a, b) else {
            break;
        };
        let Some(raw) = bytes.get(at..at + kind.len()) else {
            break;
        };
        let Ok(frame) = Downlink::decode(raw) else {
            break;
        };
        frames.push(SentFrame { start: at, frame });
        at += kind.len();
        if frames.len() == count {
            break;
        }
    }
    bytes.truncate(at);
    burst_ends.retain(|end| *end <= at);
    (bytes, frames, burst_ends)
}

/// A telemetry frame with every value drawn from `value`, in the order of the fields (its count
/// kept); a reply as it is.
fn with_values(frame: Downlink, mut value: impl FnMut() -> i16) -> Downlink {
    match frame {
        Downlink::Imu(imu) => Downlink::Imu(Imu {
            accel: [value(), value(), value()],
            gyro: [value(), value(), value()],
            seq: imu.seq,
        }),
        Downlink::Encoders(encoders) => Downlink::Encoders(Encoders {
            ticks: [value(), value(), value(), value()],
            seq: encoders.seq,
        }),
        Downlink::Battery(battery) => Downlink::Battery(Battery {
            centivolts: value() as u16,
            percent: value() as u16,
            seq: battery.seq,
        }),
        reply @ Downlink::Reply(_) => reply,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chassis_protocol::{Kind, Stream};

    #[test]
    fn rates_and_counts_are_the_boards() {
        let mut board = BoardStream::new(1, 2.0);
        let (bytes, frames) = board.take(10_000);
        let count = |k: Kind| frames.iter().filter(|f| f.frame.kind() == k).count() as f64;
        let imu = count(Kind::Telemetry(Stream::Imu));
        let encoders = count(Kind::Telemetry(Stream::Encoders));
        let battery = count(Kind::Telemetry(Stream::Battery));
        assert!((encoders / imu - 0.25).abs() < 0.01, "{encoders} / {imu}");
        assert!((battery / imu - 0.01).abs() < 0.002, "{battery} / {imu}");
        assert!(count(Kind::Reply) > 0.0);
        // Each stream's count runs on by one.
        for stream in Stream::ALL {
            let seqs: Vec<u8> = frames
                .iter()
                .filter(|f| f.frame.kind() == Kind::Telemetry(stream))
                .filter_map(|f| f.frame.seq())
                .collect();
            assert!(seqs.windows(2).all(|w| w[1] == w[0].wrapping_add(1)));
        }
        // Payloads are full of false headers, as the spec warns.
        let starts: std::collections::HashSet<usize> = frames.iter().map(|f| f.start).collect();
        let false_headers = bytes
            .windows(2)
            .enumerate()
            .filter(|(i, w)| w[0] == 0xFF && (0xFA..=0xFC).contains(&w[1]) && !starts.contains(i))
            .count();
        // "About a tenth of all 16-bit values look like a header" (`docs/protocol-2020.md`, "No checksum").
        assert!(
            false_headers as f64 > 0.4 * imu,
            "{false_headers} false headers in {imu} IMU frames"
        );
    }

    #[test]
    fn the_simulators_stream_is_whole_frames_back_to_back() {
        let (bytes, frames) = simulator_stream(3, 2_000);
        assert_eq!(frames.len(), 2_000);
        assert_eq!(frames.last().map(SentFrame::end), Some(bytes.len()));
        assert!(frames.iter().any(|f| f.frame.kind() == Kind::Reply));
    }

    #[test]
    fn same_seed_same_bytes() {
        assert_eq!(
            BoardStream::new(7, 1.0).take(500),
            BoardStream::new(7, 1.0).take(500)
        );
        assert_ne!(
            BoardStream::new(7, 1.0).take(500).0,
            BoardStream::new(8, 1.0).take(500).0
        );
    }
}
