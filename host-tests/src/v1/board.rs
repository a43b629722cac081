//! A v1.0.0 board's output: 32-byte telemetry at about 22 Hz and, now and then, a 14-byte
//! readback reply, each frame sent when it falls due, with the line idle in between.
//!
//! The values are those of a chassis being driven: the commanded body velocity changes every few
//! seconds (stops, straight runs, turns, sideways moves), the measured one follows it under an
//! acceleration limit, the IMU's unit quaternion (× 1000) turns with the integrated heading and
//! tilts with the acceleration, the gyro's z reads the turn rate, the battery sags under load and
//! discharges (a fresh pack goes in when it is flat). Time runs at 115 200 bps, 8N1: 11 520
//! bytes a second, 86.8 µs a byte.

use crate::replies::Replies;
use chassis_protocol::v1::{Downlink, Readback, Reply, Telemetry};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Bytes a second on the line (115 200 bps, 8N1).
pub const BYTES_PER_SECOND: u64 = 11_520;

/// The telemetry period: 22 frames a second (users measured 20–24 Hz).
pub const TELEMETRY_PERIOD_US: u64 = 1_000_000 / 22;

/// One frame as sent: where it starts in the byte stream, and what it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SentFrame {
    /// Offset of its first byte in the sent stream.
    pub start: usize,
    /// The frame.
    pub frame: Downlink,
}

impl SentFrame {
    /// Its length in bytes (32 or 14).
    pub fn len(&self) -> usize {
        self.frame.encode().len()
    }

    /// Whether it has no bytes (never: every frame has 14 or 32).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Offset one past its last byte.
    pub fn end(&self) -> usize {
        self.start + self.len()
    }
}

/// The idle line before the frame that starts at `offset`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Gap {
    /// Offset, in the sent stream, of the first byte after the idle stretch.
    pub offset: usize,
    /// How long the line was idle, in byte times (86.8 µs each).
    pub byte_times: usize,
}

/// Frames as the board sent them.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Stream {
    /// The bytes, frame after frame.
    pub bytes: Vec<u8>,
    /// Each frame and where it starts in `bytes`.
    pub frames: Vec<SentFrame>,
    /// The idle stretches between frames.
    pub gaps: Vec<Gap>,
}

/// The board: a driven chassis' telemetry and the replies to reads.
#[derive(Clone, Debug)]
pub struct Board {
    rng: Pcg64Mcg,
    /// Time in microseconds: the line is free from here on.
    now_us: u64,
    next_telemetry_us: u64,
    last_telemetry_us: u64,
    replies: Replies,
    /// Commanded vx, vy (mm/s), wz (mrad/s).
    target: [f64; 3],
    /// The chassis' actual vx, vy, wz.
    actual: [f64; 3],
    /// Body acceleration x, y, mm/s², over the last period.
    accel: [f64; 2],
    /// Heading, rad.
    yaw: f64,
    /// Roll, pitch, rad.
    tilt: [f64; 2],
    /// Battery charge, 1 (full) to 0 (flat).
    charge: f64,
    /// The pack's voltage when full, mV.
    full_mv: f64,
}

impl Board {
    /// A board that starts at a random phase and heading, at rest, with `replies_per_second`
    /// replies on average (0: none).
    pub fn new(seed: u64, replies_per_second: f64) -> Self {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        Board {
            now_us: 0,
            next_telemetry_us: rng.random_range(0..TELEMETRY_PERIOD_US),
            last_telemetry_us: 0,
            replies: Replies::new(&mut rng, replies_per_second),
            target: [0.0; 3],
            actual: [0.0; 3],
            accel: [0.0; 2],
            yaw: rng.random_range(-std::f64::consts::PI..std::f64::consts::PI),
            tilt: [0.0; 2],
            charge: rng.random_range(0.3..1.0),
            full_mv: rng.random_range(12_450.0..12_650.0),
            rng,
        }
    }

    /// `count` frames: the bytes, each frame with its offset, the idle stretches.
    pub fn take(&mut self, count: usize) -> Stream {
        let mut stream = Stream {
            bytes: Vec::with_capacity(count * 32),
            frames: Vec::with_capacity(count),
            gaps: Vec::with_capacity(count),
        };
        for _ in 0..count {
            let (frame, idle_us) = self.next_frame();
            let byte_times = (idle_us * BYTES_PER_SECOND / 1_000_000) as usize;
            if byte_times > 0 {
                stream.gaps.push(Gap {
                    offset: stream.bytes.len(),
                    byte_times,
                });
            }
            stream.frames.push(SentFrame {
                start: stream.bytes.len(),
                frame,
            });
            stream.bytes.extend_from_slice(&frame.encode());
        }
        stream
    }

    /// The next frame the board sends, and how long the line was idle before it (µs).
    pub fn next_frame(&mut self) -> (Downlink, u64) {
        let due = self.next_telemetry_us.min(self.replies.next_us());
        // A frame due while another is on the line goes right after it.
        let start = due.max(self.now_us);
        let idle_us = start - self.now_us;
        let frame = if due == self.next_telemetry_us {
            let jitter = self.rng.random_range(0..1_500);
            self.next_telemetry_us += TELEMETRY_PERIOD_US - 750 + jitter;
            Downlink::Telemetry(self.telemetry(start))
        } else {
            self.replies.sent(&mut self.rng);
            Downlink::Reply(self.reply())
        };
        self.now_us = start + frame.encode().len() as u64 * 1_000_000 / BYTES_PER_SECOND;
        (frame, idle_us)
    }

    /// Moves the chassis on to `now_us` and reads its sensors.
    fn telemetry(&mut self, now_us: u64) -> Telemetry {
        let dt = (now_us.saturating_sub(self.last_telemetry_us) as f64 / 1e6).clamp(1e-3, 0.2);
        self.last_telemetry_us = now_us;
        self.drive(dt);
        let moving = self.actual.iter().any(|v| v.abs() > 1.0);

        // Measured body velocity: the encoders read exact zeros at rest.
        let mut velocity = [0i16; 3];
        for (out, v) in velocity.iter_mut().zip(self.actual) {
            let noise = if moving {
                self.rng.random_range(-4.0..=4.0)
            } else {
                0.0
            };
            *out = clamp_i16(v + noise);
        }

        // The quaternion of heading, pitch and roll (Z-Y-X), × 1000.
        let (sr, cr) = (self.tilt[0] / 2.0).sin_cos();
        let (sp, cp) = (self.tilt[1] / 2.0).sin_cos();
        let (sy, cy) = (self.yaw / 2.0).sin_cos();
        let q = [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ];
        let quaternion = q.map(|c| clamp_i16(c * 1_000.0));

        // Accelerometer, 16 384 a g: the body's acceleration and gravity through the tilt.
        let g = 16_384.0;
        let shake = if moving { 120.0 } else { 30.0 };
        let [roll, pitch] = self.tilt;
        let accel = [
            self.accel[0] / 9_806.65 * g - pitch.sin() * g,
            self.accel[1] / 9_806.65 * g + roll.sin() * pitch.cos() * g,
            roll.cos() * pitch.cos() * g,
        ]
        .map(|a| clamp_i16(a + self.rng.random_range(-shake..=shake)));

        // Gyro, read as mrad/s: z is the turn rate.
        let gyro = [
            self.rng.random_range(-6.0..=6.0),
            self.rng.random_range(-6.0..=6.0),
            self.actual[2] + self.rng.random_range(-8.0..=8.0),
        ]
        .map(clamp_i16);

        // Battery: a 3S pack, 10.8 V flat to about 12.6 V full, sagging with the load.
        let load = self.actual[0].hypot(self.actual[1]) / 1_000.0 + self.actual[2].abs() / 3_000.0;
        self.charge -= dt * (0.5 + 1.5 * load) / 7_200.0;
        if self.charge <= 0.0 {
            // A fresh pack.
            self.charge = 1.0;
            self.full_mv = self.rng.random_range(12_450.0..12_650.0);
        }
        let mv = 10_800.0 + (self.full_mv - 10_800.0) * self.charge - 250.0 * load
            + self.rng.random_range(-12.0..=12.0);

        Telemetry {
            velocity,
            accel,
            gyro,
            quaternion,
            battery_mv: clamp_i16(mv),
        }
    }

    /// The chassis over `dt` seconds: a new command now and then, the velocity following it
    /// under an acceleration limit, the heading and tilt following the velocity.
    fn drive(&mut self, dt: f64) {
        // A new command every three seconds on average.
        if self.rng.random_bool((dt / 3.0).min(1.0)) {
            self.target = if self.rng.random_bool(0.25) {
                [0.0; 3]
            } else {
                let mut pick = |limit: f64| {
                    if self.rng.random_bool(0.4) {
                        0.0
                    } else {
                        self.rng.random_range(-limit..=limit).round()
                    }
                };
                [pick(600.0), pick(1_000.0), pick(2_500.0)]
            };
        }
        // 1.5 m/s² and 5 rad/s² at most.
        let limits = [1_500.0 * dt, 1_500.0 * dt, 5_000.0 * dt];
        let before = self.actual;
        for ((v, t), limit) in self.actual.iter_mut().zip(self.target).zip(limits) {
            *v += (t - *v).clamp(-limit, limit);
        }
        self.accel = [
            (self.actual[0] - before[0]) / dt,
            (self.actual[1] - before[1]) / dt,
        ];
        self.yaw += self.actual[2] / 1_000.0 * dt;
        self.yaw = (self.yaw + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        // The body leans with the acceleration (about 2° at 1.5 m/s²) and shakes while moving.
        let moving = self.actual.iter().any(|v| v.abs() > 1.0);
        let shake = if moving { 0.004 } else { 0.0005 };
        self.tilt = [
            -self.accel[1] * 2.3e-5 + self.rng.random_range(-shake..=shake),
            self.accel[0] * 2.3e-5 + self.rng.random_range(-shake..=shake),
        ];
    }

    /// A reply to one of the five reads, with what the board would report.
    fn reply(&mut self) -> Reply {
        let request = Readback::ALL[self.rng.random_range(0..Readback::ALL.len())];
        let mut payload = [0u8; 10];
        let put = |payload: &mut [u8; 10], values: &[i16]| {
            for (i, v) in values.iter().enumerate() {
                payload[2 * i..2 * i + 2].copy_from_slice(&v.to_be_bytes());
            }
        };
        match request {
            // The vendor's example settings: directions 0 and 10, PWM 3600 / 2100, 165 ppr.
            Readback::System => put(&mut payload, &[10, 3_600, 2_100, 165]),
            Readback::Geometry => put(&mut payload, &[110, 110, 55, 60]),
            Readback::Pid => put(&mut payload, &[3_000, 1_050, 0, 3_000, 1_050]),
            Readback::BodyVelocity => {
                let driving = self.target.iter().any(|v| *v != 0.0);
                put(
                    &mut payload,
                    &[
                        0,
                        clamp_i16(self.target[0]),
                        clamp_i16(self.target[1]),
                        clamp_i16(self.target[2]),
                    ],
                );
                payload[0] = if driving { 2 } else { 0 };
                payload[1] = if driving { 4 } else { 0 };
            }
            Readback::MotorSpeeds => {
                // Mecanum wheels, half wheel spacing + half axle spacing = 110 mm.
                let [vx, vy, wz] = self.actual;
                let turn = 110.0 * wz / 1_000.0;
                let mut wheels = [
                    vy - vx - turn,
                    vy + vx + turn,
                    vy - vx + turn,
                    vy + vx - turn,
                ]
                .map(|w| clamp_i16(w + self.rng.random_range(-5.0..=5.0)));
                if !self.actual.iter().any(|v| v.abs() > 1.0) {
                    wheels = [0; 4];
                }
                put(
                    &mut payload,
                    &[0, wheels[0], wheels[1], wheels[2], wheels[3]],
                );
                payload[0] = 2;
                payload[1] = 4;
            }
        }
        Reply { request, payload }
    }
}

/// Rounds to the nearest `i16`, saturating.
fn clamp_i16(v: f64) -> i16 {
    v.round().clamp(f64::from(i16::MIN), f64::from(i16::MAX)) as i16
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stream_has_the_boards_rates_and_sizes() {
        let stream = Board::new(1, 1.0).take(22 * 600);
        let replies = stream
            .frames
            .iter()
            .filter(|f| matches!(f.frame, Downlink::Reply(_)))
            .count();
        let telemetry = stream.frames.len() - replies;
        // Ten minutes of telemetry at 22 Hz, about one reply a second.
        let seconds = telemetry as f64 / 22.0;
        assert!((replies as f64 / seconds - 1.0).abs() < 0.15, "{replies}");
        let idle: usize = stream.gaps.iter().map(|g| g.byte_times).sum();
        let busy = stream.bytes.len();
        // 22 × 32 + 14 bytes a second of 11 520: the line is idle about 94 % of the time.
        let share = idle as f64 / (idle + busy) as f64;
        assert!((0.92..0.96).contains(&share), "{share}");
        for f in &stream.frames {
            assert_eq!(
                Downlink::decode(&stream.bytes[f.start..f.end()]),
                Ok(f.frame)
            );
        }
    }

    #[test]
    fn values_move_and_stay_physical() {
        let stream = Board::new(2, 1.0).take(22 * 3_600);
        let mut speeds = std::collections::BTreeSet::new();
        let mut norms = (i64::MAX, i64::MIN);
        let mut battery = (i16::MAX, i16::MIN);
        for f in &stream.frames {
            if let Downlink::Telemetry(t) = f.frame {
                speeds.insert(t.velocity[1] / 100);
                let n: i64 = t.quaternion.iter().map(|q| i64::from(*q).pow(2)).sum();
                norms = (norms.0.min(n), norms.1.max(n));
                battery = (battery.0.min(t.battery_mv), battery.1.max(t.battery_mv));
            }
        }
        assert!(speeds.len() > 15, "{speeds:?}");
        // Rounding each component moves the norm by a few thousandths at most.
        assert!(norms.0 > 995_000 && norms.1 < 1_005_000, "{norms:?}");
        assert!(battery.0 > 10_000 && battery.1 < 12_700, "{battery:?}");
        // Bytes that are a frame's start and end turn up inside payloads.
        let starts = stream.bytes.iter().filter(|b| **b == 0x7B).count();
        assert!(starts > stream.frames.len() + 1_000, "{starts}");
    }
}
