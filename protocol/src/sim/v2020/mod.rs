//! The board running the **2020** firmware (`FF FE` frames): what it was told, its registers,
//! its chassis and its telemetry clock. See [the module above](super) for the behaviour and
//! the decisions where the spec is silent.

use super::Port;
use crate::command::Command;
use crate::parse::UplinkParser;
use crate::registers::Snapshot;
use crate::telemetry::Reply;
use heapless::Deque;

mod motion;
mod registers;
mod telemetry;
#[cfg(test)]
mod tests;

use motion::Chassis;
pub use motion::Motion;
pub use registers::FACTORY;
use registers::Registers;
use telemetry::Streams;

/// How the simulated board behaves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimConfig {
    /// Seed of the sensor noise and of the fault injection.
    pub seed: u64,
    /// Delay between a read arriving and its reply going out, in ms.
    pub reply_delay_ms: u32,
    /// Downlink resumes this long after the last settings frame, in ms.
    pub resume_after_ms: u32,
    /// Encoder ticks per metre a wheel's rim travels (1 000). The raw velocity units are wheel
    /// ticks per second, so on a mecanum chassis 1 m/s forward is Y = `ticks_per_m`.
    pub ticks_per_m: u32,
    /// From the centre to the front and rear axles, mm (100).
    pub half_wheelbase_mm: u16,
    /// From the centre to a wheel sideways, mm (120; a differential chassis: half its track).
    pub half_track_mm: u16,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            seed: 1,
            reply_delay_ms: 2,
            resume_after_ms: 100,
            ticks_per_m: 1_000,
            half_wheelbase_mm: 100,
            half_track_mm: 120,
        }
    }
}

/// The simulated board.
#[derive(Clone, Debug)]
pub struct Board {
    config: SimConfig,
    port: Port<UplinkParser>,
    /// Its registers.
    registers: Registers,
    /// What the chassis does.
    chassis: Chassis,
    /// The telemetry clock.
    streams: Streams,
    replies: Deque<(u64, Reply), 8>,
    commands: u32,
}

#[cfg(feature = "defmt")]
impl defmt::Format for Board {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "Board {{ now_ms: {=u64}, motion: {}, pending_deci_degrees: {=i64}, queued: {=usize} }}",
            self.port.now_ms,
            self.chassis.motion,
            self.chassis.pending_deci_degrees,
            self.port.line.queued()
        );
    }
}

impl Board {
    /// A board just powered up with factory settings, at time 0, standing still.
    #[must_use]
    pub fn new(config: SimConfig) -> Self {
        Board {
            config,
            port: Port::new(config.seed, UplinkParser::new()),
            registers: Registers::new(),
            chassis: Chassis::new(),
            streams: Streams::new(),
            replies: Deque::new(),
            commands: 0,
        }
    }

    /// The live registers.
    #[must_use]
    pub const fn registers(&self) -> &Snapshot {
        &self.registers.live
    }

    /// The stored registers.
    #[must_use]
    pub const fn stored_registers(&self) -> &Snapshot {
        &self.registers.stored
    }

    /// What the chassis was last told to do.
    #[must_use]
    pub const fn motion(&self) -> Motion {
        self.chassis.motion
    }

    /// Where the chassis truly is: x, y (m) and yaw (rad, in (-π, π]) since power-up, REP-103
    /// axes (x forward, y left, yaw counter-clockwise): the body motion its wheels make,
    /// integrated every ms with the geometry of [`SimConfig`]. What an odometry built on the
    /// encoders is measured against.
    #[must_use]
    pub const fn pose(&self) -> (f64, f64, f64) {
        self.chassis.pose.get()
    }

    /// The encoders' running totals (wrapping 16-bit), MOTO1..MOTO4: what the next encoder
    /// frame will carry.
    #[must_use]
    pub const fn wheel_ticks(&self) -> [i16; 4] {
        self.chassis.wheel_ticks
    }

    /// The turn still pending, in 0.1°.
    #[must_use]
    pub fn pending_deci_degrees(&self) -> i32 {
        clamp_i32(self.chassis.pending_deci_degrees)
    }

    /// Every angle ever commanded, added up, in 0.1°: what the board was told to turn in all.
    #[must_use]
    pub const fn total_turn_commanded(&self) -> i64 {
        self.chassis.total_turn_deci_degrees
    }

    /// Whether a gyro calibration is running.
    #[must_use]
    pub fn calibrating(&self) -> bool {
        self.registers.calibrating_until_ms.is_some()
    }

    /// Whether telemetry is paused (settings being made).
    #[must_use]
    pub const fn telemetry_paused(&self) -> bool {
        self.port.now_ms < self.streams.quiet_until_ms
    }

    /// Commands executed so far.
    #[must_use]
    pub const fn commands(&self) -> u32 {
        self.commands
    }

    /// Downlink frames dropped because the output buffer was full.
    #[must_use]
    pub const fn dropped_frames(&self) -> u32 {
        self.port.line.dropped_frames
    }

    fn execute(&mut self, command: Command) {
        self.commands = self.commands.wrapping_add(1);
        match command {
            Command::Velocity(v) => {
                self.chassis.motion = Motion::Velocity {
                    x: v.x,
                    y: v.y,
                    z: v.z,
                };
            }
            Command::Turn(t) => {
                // The hazard the spec warns about: every angle frame adds up.
                self.chassis.motion = Motion::Velocity {
                    x: t.x,
                    y: t.y,
                    z: 0,
                };
                self.chassis.pending_deci_degrees = self
                    .chassis
                    .pending_deci_degrees
                    .saturating_add(i64::from(t.deci_degrees));
                self.chassis.total_turn_deci_degrees = self
                    .chassis
                    .total_turn_deci_degrees
                    .saturating_add(i64::from(t.deci_degrees));
            }
            Command::Motors(m) => self.chassis.motion = Motion::Motors(m.values),
            Command::Setting(setting) => self.setting(setting),
        }
    }

    fn step_one_ms(&mut self) {
        let now = self.port.now_ms;
        if self
            .registers
            .calibrating_until_ms
            .is_some_and(|end| now >= end)
        {
            self.registers.calibrating_until_ms = None;
            self.registers.live.gyro_calibration = 0x0100 | (self.next_random() as u16 & 0x00FF);
        }
        self.move_chassis();
        while let Some((due, reply)) = self.replies.front().copied() {
            if due > now {
                break;
            }
            let _ = self.replies.pop_front();
            if !self.port.line.faults.replies_stopped {
                self.send(&reply.encode());
            }
        }
        self.send_due_telemetry(now);
    }
}

fn clamp_i32(v: i64) -> i32 {
    i32::try_from(v.clamp(i64::from(i32::MIN), i64::from(i32::MAX))).unwrap_or(0)
}

impl Board {
    fn send(&mut self, bytes: &[u8]) {
        self.port.line.send(self.port.now_ms, bytes);
    }

    fn next_random(&mut self) -> u64 {
        self.port.line.next_random()
    }
}

super::wire_side!();
