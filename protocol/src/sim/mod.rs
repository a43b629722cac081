//! A model of the board (feature `sim`): registers, kinematics, the telemetry clock, replies and
//! fault injection, with no I/O and no clock of its own. `no_std`, allocation-free: a master can
//! be tested against it on the host, and it can run on a spare MCU as a fake chassis.
//!
//! ```
//! use chassis_protocol::sim::{Board, SimConfig};
//! use chassis_protocol::{DownlinkParser, Register, Setting, Telemetry};
//!
//! let mut board = Board::new(SimConfig::default());
//! board.receive(&Setting::Read(Register::MotorVoltage).encode());
//! let mut parser = DownlinkParser::new();
//! let mut buf = [0u8; 64];
//! let mut reply = None;
//! for ms in 0..100 {
//!     board.advance(ms);
//!     let n = board.transmit(&mut buf);
//!     let mut frames: Vec<Telemetry> = parser.frames(&buf[..n]).collect();
//!     if n == 0 {
//!         // A quiet millisecond: the telemetry is paused while settings are made.
//!         frames.extend(core::iter::from_fn(|| parser.idle()));
//!     }
//!     for frame in frames {
//!         if let Telemetry::Reply(r) = frame { reply = Some(r); }
//!     }
//! }
//! assert_eq!(reply.map(|r| r.value), Some(1_200)); // 12.00 V, the factory default
//! ```
//!
//! # Behaviour, and the decisions where the spec is silent
//!
//! * **Registers** have a live copy and a stored copy. [`Action::Store`] copies live to stored,
//!   except system-mode bit 3 (gyro compensation), which the spec says is not stored;
//!   [`Action::LoadStored`] and [`Action::LoadDefaults`] copy back.
//! * **Gyro calibration** takes 30 s (10 s to settle, 20 s still) once compensation is switched
//!   on, by action, system-mode write or a write of 0xFFFF to the calibration register. While it
//!   runs, the calibration register reads 0xFFFF; then it reads the calibrated value.
//! * **Angle mode accumulates**, exactly as the spec warns: every frame with the angle bit adds
//!   its angle to the pending turn; the chassis turns at 90°/s until the pending angle is 0.
//!   [`Board::total_turn_commanded`] tells a test what was asked in all.
//! * **Telemetry pauses while settings are made** (A6): every settings frame stops it, and it
//!   resumes [`SimConfig::resume_after_ms`] (100 ms) after the last one. Counts carry on from
//!   where they stopped (they count frames sent).
//! * Replies go out [`SimConfig::reply_delay_ms`] after the read arrives.
//! * Telemetry: IMU at 100 Hz, encoders at 25 Hz, battery at 1 Hz, each with its rolling count;
//!   simple kinematics for omni, mecanum and differential chassis move the encoders and gyro Z;
//!   the battery drains.

use crate::command::{Action, Command, DriveType, Register, Setting, SystemMode, Write};
use crate::parse::UplinkParser;
use crate::registers::Settings;
use crate::telemetry::{Battery, Encoders, Imu, Reply, Telemetry};
use heapless::Deque;

#[cfg(feature = "driver")]
mod adapters;
#[cfg(feature = "std")]
mod serve;

#[cfg(feature = "async")]
pub use adapters::SimDelay;
#[cfg(feature = "driver")]
pub use adapters::{SimClock, SimUart};
#[cfg(feature = "std")]
pub use serve::serve;

/// Bytes the board's line can hold for the master before it drops telemetry: a second of
/// telemetry (1 782 bytes) fits, as it does in a host's serial buffer, so a master that reads
/// once a second loses nothing.
pub const OUT_CAPACITY: usize = 2_048;

/// How the simulated board behaves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimConfig {
    /// Seed of the sensor noise and of the fault injection.
    pub seed: u64,
    /// Delay between a read arriving and its reply going out, in ms.
    pub reply_delay_ms: u32,
    /// Telemetry resumes this long after the last settings frame, in ms.
    pub resume_after_ms: u32,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            seed: 1,
            reply_delay_ms: 2,
            resume_after_ms: 100,
        }
    }
}

/// Faults to inject into what the board sends; rates are per million bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Faults {
    /// A byte is lost.
    pub drop_per_million: u32,
    /// A byte arrives changed.
    pub corrupt_per_million: u32,
    /// A spurious byte arrives.
    pub insert_per_million: u32,
    /// The board sends no telemetry at all (a dead link, or a hung board).
    pub telemetry_stopped: bool,
    /// The board sends no replies.
    pub replies_stopped: bool,
}

/// The factory defaults of the model (the vendor does not publish them; these are chosen).
pub const FACTORY: Settings = Settings {
    max_speed: 1_000,
    speed_kp: 300,
    speed_ki: 20,
    gyro_gain: 50_000,
    system_mode: SystemMode::new(DriveType::Mecanum),
    gyro_calibration: 0x0200,
    motor_centivolts: 1_200,
    battery_full_centivolts: 0x7FFF,
    battery_cutoff_centivolts: 0x7FFF,
};

/// What the chassis was last told to do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Motion {
    /// Body velocity (mode `01`, angle mode off).
    Velocity {
        /// X.
        x: i32,
        /// Y.
        y: i32,
        /// Z.
        z: i32,
    },
    /// Each motor (modes `02` / `03`).
    Motors([i32; 4]),
}

/// Time a byte takes on the wire at 115 200 bps, 8N1 (10 bits), in ns.
const BYTE_NS: u64 = 86_806;

/// Gyro calibration time: 10 s settle + 20 s still.
const CALIBRATION_MS: u64 = 30_000;
/// Turning speed in angle mode: 9 × 0.1° every 10 ms, 90°/s.
const TURN_DECI_DEGREES_PER_10_MS: i64 = 9;
/// Telemetry periods in ms: IMU, encoders, battery.
const PERIODS_MS: [u64; 3] = [10, 40, 1_000];

/// The simulated board.
#[derive(Clone, Debug)]
pub struct Board {
    config: SimConfig,
    faults: Faults,
    uplink: UplinkParser,
    now_ms: u64,
    live: Settings,
    stored: Settings,
    motion: Motion,
    pending_deci_degrees: i64,
    total_turn_deci_degrees: i64,
    turn_carry: i64,
    wheel_ticks: [i16; 4],
    tick_carry: [i32; 4],
    centivolts: u16,
    seq: [u8; 3],
    next_due_ms: [u64; 3],
    quiet_until_ms: u64,
    calibrating_until_ms: Option<u64>,
    replies: Deque<(u64, Reply), 8>,
    out: Deque<u8, OUT_CAPACITY>,
    /// The frames in `out` as (when their first byte starts on the wire in ns, length): bytes
    /// leave at the line's pace (10 bits a byte at 115 200 bps), a frame from the moment it is
    /// sent or the moment the one before it has left.
    on_wire: Deque<(u64, u16), 160>,
    /// Bytes of the front frame of `on_wire` already handed over.
    front_taken: u16,
    /// When the last byte queued will have left, in ns.
    line_free_ns: u64,
    rng: u64,
    commands: u32,
    dropped_frames: u32,
}

#[cfg(feature = "defmt")]
impl defmt::Format for Board {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "Board {{ now_ms: {=u64}, motion: {}, pending_deci_degrees: {=i64}, queued: {=usize} }}",
            self.now_ms,
            self.motion,
            self.pending_deci_degrees,
            self.out.len()
        );
    }
}

impl Board {
    /// A board just powered up with factory settings, at time 0, standing still.
    #[must_use]
    pub fn new(config: SimConfig) -> Self {
        Board {
            config,
            faults: Faults::default(),
            uplink: UplinkParser::new(),
            now_ms: 0,
            live: FACTORY,
            stored: FACTORY,
            motion: Motion::Velocity { x: 0, y: 0, z: 0 },
            pending_deci_degrees: 0,
            total_turn_deci_degrees: 0,
            turn_carry: 0,
            wheel_ticks: [0; 4],
            tick_carry: [0; 4],
            centivolts: 1_240,
            seq: [0; 3],
            next_due_ms: [0, 5, 500],
            quiet_until_ms: 0,
            calibrating_until_ms: None,
            replies: Deque::new(),
            out: Deque::new(),
            on_wire: Deque::new(),
            front_taken: 0,
            line_free_ns: 0,
            rng: config.seed | 1,
            commands: 0,
            dropped_frames: 0,
        }
    }

    /// Sets the faults to inject from now on.
    pub fn set_faults(&mut self, faults: Faults) {
        self.faults = faults;
    }

    /// Bytes from the master, taken at the board's current time.
    pub fn receive(&mut self, bytes: &[u8]) {
        let mut rest = bytes;
        loop {
            let (command, later) = self.uplink.push_slice(rest);
            rest = later;
            match command {
                Some(command) => self.execute(command),
                None => break,
            }
        }
    }

    /// Moves the board's time forward to `now_ms` (milliseconds since power-up): the chassis
    /// moves, calibration runs, replies and telemetry fall due. Time never goes back.
    pub fn advance(&mut self, now_ms: u64) {
        while self.now_ms < now_ms {
            self.now_ms = self.now_ms.saturating_add(1);
            self.step_one_ms();
        }
    }

    /// Copies bytes for the master into `buf`, with the faults applied; returns how many.
    pub fn transmit(&mut self, buf: &mut [u8]) -> usize {
        let mut n = 0;
        let now_ns = self.now_ms.saturating_mul(1_000_000);
        while n < buf.len() {
            // Only the bytes that have crossed the wire by now.
            let Some(&(start, len)) = self.on_wire.front() else {
                break;
            };
            let taken = self.front_taken.saturating_add(1);
            if start.saturating_add(u64::from(taken).saturating_mul(BYTE_NS)) > now_ns {
                break;
            }
            let Some(byte) = self.out.pop_front() else {
                break;
            };
            if taken >= len {
                let _ = self.on_wire.pop_front();
                self.front_taken = 0;
            } else {
                self.front_taken = taken;
            }
            if self.chance(self.faults.drop_per_million) {
                continue;
            }
            let byte = if self.chance(self.faults.corrupt_per_million) {
                byte ^ (self.next_random() as u8 | 1)
            } else {
                byte
            };
            if self.chance(self.faults.insert_per_million) {
                if let Some(slot) = buf.get_mut(n) {
                    *slot = self.next_random() as u8;
                    n = n.saturating_add(1);
                }
            }
            if let Some(slot) = buf.get_mut(n) {
                *slot = byte;
                n = n.saturating_add(1);
            } else {
                // No room left for it after an insertion: keep it for the next call.
                let _ = self.out.push_front(byte);
            }
        }
        n
    }

    /// Whether a byte for the master has crossed the wire by now (what a UART's "data ready"
    /// says).
    #[must_use]
    pub fn byte_arrived(&self) -> bool {
        let now_ns = self.now_ms.saturating_mul(1_000_000);
        self.on_wire.front().is_some_and(|&(start, _)| {
            let next = u64::from(self.front_taken.saturating_add(1));
            start.saturating_add(next.saturating_mul(BYTE_NS)) <= now_ns
        })
    }

    /// The board's time in ms.
    #[must_use]
    pub const fn now_ms(&self) -> u64 {
        self.now_ms
    }

    /// The live registers.
    #[must_use]
    pub const fn registers(&self) -> &Settings {
        &self.live
    }

    /// The stored registers.
    #[must_use]
    pub const fn stored_registers(&self) -> &Settings {
        &self.stored
    }

    /// What the chassis was last told to do.
    #[must_use]
    pub const fn motion(&self) -> Motion {
        self.motion
    }

    /// The turn still pending, in 0.1°.
    #[must_use]
    pub fn pending_deci_degrees(&self) -> i32 {
        clamp_i32(self.pending_deci_degrees)
    }

    /// Every angle ever commanded, added up, in 0.1°: what the board was told to turn in all.
    #[must_use]
    pub const fn total_turn_commanded(&self) -> i64 {
        self.total_turn_deci_degrees
    }

    /// Whether a gyro calibration is running.
    #[must_use]
    pub fn calibrating(&self) -> bool {
        self.calibrating_until_ms.is_some()
    }

    /// Whether telemetry is paused (settings being made).
    #[must_use]
    pub const fn telemetry_paused(&self) -> bool {
        self.now_ms < self.quiet_until_ms
    }

    /// Commands executed so far.
    #[must_use]
    pub const fn commands(&self) -> u32 {
        self.commands
    }

    /// Telemetry frames dropped because the output buffer was full.
    #[must_use]
    pub const fn dropped_frames(&self) -> u32 {
        self.dropped_frames
    }

    fn execute(&mut self, command: Command) {
        self.commands = self.commands.wrapping_add(1);
        match command {
            Command::Velocity(v) => {
                self.motion = Motion::Velocity {
                    x: v.x,
                    y: v.y,
                    z: v.z,
                };
            }
            Command::Turn(t) => {
                // The hazard the spec warns about: every angle frame adds up.
                self.motion = Motion::Velocity {
                    x: t.x,
                    y: t.y,
                    z: 0,
                };
                self.pending_deci_degrees = self
                    .pending_deci_degrees
                    .saturating_add(i64::from(t.deci_degrees));
                self.total_turn_deci_degrees = self
                    .total_turn_deci_degrees
                    .saturating_add(i64::from(t.deci_degrees));
            }
            Command::Motors(m) => self.motion = Motion::Motors(m.values),
            Command::Setting(setting) => self.setting(setting),
        }
    }

    fn setting(&mut self, setting: Setting) {
        self.quiet_until_ms = self
            .now_ms
            .saturating_add(u64::from(self.config.resume_after_ms));
        match setting {
            Setting::Action(action) => self.action(action),
            Setting::Write(write) => {
                let compensation_was = self.live.system_mode.gyro_compensation();
                self.live.set(write);
                match write {
                    Write::GyroCalibration(0xFFFF) => self.start_calibration(),
                    Write::SystemMode(mode) if mode.gyro_compensation() && !compensation_was => {
                        self.start_calibration();
                    }
                    _ => {}
                }
            }
            Setting::Read(register) => {
                let value = match register {
                    Register::PendingAngle => self.pending_deci_degrees() as u32,
                    Register::GyroCalibration if self.calibrating() => 0xFFFF,
                    other => self.live.value(other).unwrap_or(0),
                };
                let due = self
                    .now_ms
                    .saturating_add(u64::from(self.config.reply_delay_ms));
                let _ = self.replies.push_back((due, Reply::new(register, value)));
            }
            Setting::Raw { .. } => {}
        }
    }

    fn action(&mut self, action: Action) {
        match action {
            Action::LoadStored => self.live = self.stored,
            Action::LoadDefaults => self.live = FACTORY,
            Action::Store => {
                // System-mode bit 3 is not stored.
                let compensation = self.stored.system_mode.gyro_compensation();
                self.stored = self.live;
                self.stored.system_mode =
                    self.stored.system_mode.with_gyro_compensation(compensation);
            }
            Action::GyroCompensationOff => {
                self.live.system_mode = self.live.system_mode.with_gyro_compensation(false);
            }
            Action::GyroCompensationOn | Action::RecalibrateGyro => {
                self.live.system_mode = self.live.system_mode.with_gyro_compensation(true);
                self.start_calibration();
            }
            Action::Unknown(_) => {}
        }
    }

    fn start_calibration(&mut self) {
        self.calibrating_until_ms = Some(self.now_ms.saturating_add(CALIBRATION_MS));
    }

    fn step_one_ms(&mut self) {
        let now = self.now_ms;
        if self.calibrating_until_ms.is_some_and(|end| now >= end) {
            self.calibrating_until_ms = None;
            self.live.gyro_calibration = 0x0100 | (self.next_random() as u16 & 0x00FF);
        }
        self.move_chassis();
        while let Some((due, reply)) = self.replies.front().copied() {
            if due > now {
                break;
            }
            let _ = self.replies.pop_front();
            if !self.faults.replies_stopped {
                self.send(&reply.encode());
            }
        }
        let sending = !self.faults.telemetry_stopped && !self.telemetry_paused();
        for stream in 0..3 {
            let (Some(due), Some(period)) = (
                self.next_due_ms.get(stream).copied(),
                PERIODS_MS.get(stream),
            ) else {
                continue;
            };
            if now < due {
                continue;
            }
            if let Some(slot) = self.next_due_ms.get_mut(stream) {
                *slot = due.saturating_add(*period);
            }
            if sending {
                let frame = self.telemetry(stream);
                self.send(&frame.encode());
            }
        }
    }

    /// Wheel speeds in encoder ticks per second for the current motion.
    fn wheel_speeds(&self) -> [i32; 4] {
        match self.motion {
            Motion::Motors(values) => values,
            Motion::Velocity { x, y, z } => match self.live.system_mode.drive_type() {
                DriveType::Omni | DriveType::Mecanum => [
                    y.saturating_add(x).saturating_add(z),
                    y.saturating_sub(x).saturating_sub(z),
                    y.saturating_add(x).saturating_sub(z),
                    y.saturating_sub(x).saturating_add(z),
                ],
                DriveType::Differential => {
                    let (left, right) = (y.saturating_sub(z), y.saturating_add(z));
                    [left, right, right, left]
                }
                // No encoders to move.
                DriveType::DifferentialOpenLoop | DriveType::Reserved(_) => [0; 4],
            },
        }
    }

    fn move_chassis(&mut self) {
        let speeds = self.wheel_speeds();
        for ((ticks, carry), speed) in self
            .wheel_ticks
            .iter_mut()
            .zip(&mut self.tick_carry)
            .zip(speeds)
        {
            // Ticks per second → per ms, carrying the remainder.
            let total = carry.saturating_add(speed);
            let whole = total / 1_000;
            *carry = total % 1_000;
            *ticks = ticks.wrapping_add(whole as i16);
        }
        if self.pending_deci_degrees != 0 {
            // The rate (0.1° per 10 ms) goes to the gyro every ms; the angle moves on every 10.
            let rate = self
                .pending_deci_degrees
                .clamp(-TURN_DECI_DEGREES_PER_10_MS, TURN_DECI_DEGREES_PER_10_MS);
            if self.now_ms.checked_rem(10) == Some(0) {
                self.pending_deci_degrees = self.pending_deci_degrees.saturating_sub(rate);
            }
            self.turn_carry = rate;
        } else {
            self.turn_carry = 0;
        }
        let moving = speeds.iter().any(|s| *s != 0) || self.turn_carry != 0;
        let drain_every = if moving { 10_000 } else { 60_000 };
        if self.now_ms.checked_rem(drain_every) == Some(0) {
            self.centivolts = self.centivolts.saturating_sub(1);
        }
    }

    fn telemetry(&mut self, stream: usize) -> Telemetry {
        let seq = match self.seq.get_mut(stream) {
            Some(s) => {
                *s = s.wrapping_add(1);
                *s
            }
            None => 0,
        };
        match stream {
            0 => {
                let noise = |b: &mut Board| ((b.next_random() % 9) as i16).wrapping_sub(4);
                let rotation = match self.motion {
                    Motion::Velocity { z, .. } => z,
                    Motion::Motors(_) => 0,
                };
                let turning = clamp_i32(self.turn_carry.saturating_mul(10));
                let gyro_z = rotation.saturating_add(turning).clamp(-32_768, 32_767) as i16;
                Telemetry::Imu(Imu {
                    accel: [
                        noise(self),
                        noise(self),
                        16_384i16.wrapping_add(noise(self)),
                    ],
                    gyro: [noise(self), noise(self), gyro_z.saturating_add(noise(self))],
                    seq,
                })
            }
            1 => Telemetry::Encoders(Encoders {
                ticks: self.wheel_ticks,
                seq,
            }),
            _ => {
                let (full, cutoff) = match (
                    self.live.battery_full_centivolts,
                    self.live.battery_cutoff_centivolts,
                ) {
                    (0x7FFF, _) | (_, 0x7FFF) => (1_260, 1_050),
                    (full, cutoff) => (full, cutoff),
                };
                let span = u32::from(full.saturating_sub(cutoff)).max(1);
                let above = u32::from(self.centivolts.saturating_sub(cutoff));
                let percent = above
                    .saturating_mul(100)
                    .checked_div(span)
                    .unwrap_or(0)
                    .min(100) as u16;
                Telemetry::Battery(Battery {
                    centivolts: self.centivolts,
                    percent,
                    seq,
                })
            }
        }
    }

    fn send(&mut self, bytes: &[u8]) {
        let room = self.out.capacity().saturating_sub(self.out.len());
        let (Ok(len), false) = (u16::try_from(bytes.len()), room < bytes.len()) else {
            self.dropped_frames = self.dropped_frames.wrapping_add(1);
            return;
        };
        let start = self.line_free_ns.max(self.now_ms.saturating_mul(1_000_000));
        if self.on_wire.push_back((start, len)).is_err() {
            self.dropped_frames = self.dropped_frames.wrapping_add(1);
            return;
        }
        self.line_free_ns = start.saturating_add(u64::from(len).saturating_mul(BYTE_NS));
        for b in bytes {
            let _ = self.out.push_back(*b);
        }
    }

    fn chance(&mut self, per_million: u32) -> bool {
        per_million > 0 && (self.next_random() % 1_000_000) < u64::from(per_million)
    }

    /// xorshift64: enough for noise and faults, and the same on every target.
    fn next_random(&mut self) -> u64 {
        let mut x = self.rng;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.rng = x;
        x
    }
}

fn clamp_i32(v: i64) -> i32 {
    i32::try_from(v.clamp(i64::from(i32::MIN), i64::from(i32::MAX))).unwrap_or(0)
}
