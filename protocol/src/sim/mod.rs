//! A model of the board (feature `sim`): registers, kinematics, the telemetry clock, replies and
//! fault injection, with no I/O and no clock of its own. `no_std`, allocation-free: a master can
//! be tested against it on the host, and it can run on a spare MCU as a fake chassis.
//!
//! ```
//! use chassis_protocol::sim::{Board, SimConfig};
//! use chassis_protocol::{DownlinkParser, Register, Setting, Downlink};
//!
//! let mut board = Board::new(SimConfig::default());
//! board.receive(&Setting::Read(Register::MotorVoltage).encode());
//! let mut parser = DownlinkParser::new();
//! let mut buf = [0u8; 64];
//! let mut reply = None;
//! for ms in 0..100 {
//!     board.advance(ms);
//!     let n = board.transmit(&mut buf);
//!     let mut frames: Vec<Downlink> = parser.frames(&buf[..n]).collect();
//!     if n == 0 {
//!         // A quiet millisecond: the telemetry is paused while settings are made.
//!         frames.extend(core::iter::from_fn(|| parser.idle()));
//!     }
//!     for frame in frames {
//!         if let Downlink::Reply(r) = frame { reply = Some(r); }
//!     }
//! }
//! assert_eq!(reply.map(|r| r.value), Some(1_200)); // 12.00 V, the factory default
//! ```
//!
//! | file | what |
//! |---|---|
//! | `mod.rs` | [`Board`]: commands in, time on, the configuration ([`SimConfig`]) |
//! | `registers.rs` | live and stored registers, [`FACTORY`] defaults, actions, calibration |
//! | `motion.rs` | [`Motion`], wheel speeds per drive type, encoders, gyro, turns, battery drain |
//! | `telemetry.rs` | the telemetry clock and frames |
//! | `line.rs` | the line to the master: pacing at 115 200 bps, its buffer, [`Faults`] |
//! | `adapters.rs` | (feature `driver`) in-memory UART, clock and delay on shared simulated time |
//! | `serve.rs` | (feature `std`) the board in real time on an OS byte stream |
//! | `v1.rs` | [`v1::Board`]: the v1.0.0 firmware's board (`7B … BCC 7D`), on the same line |
//!
//! Both boards implement [`Simulated`], which is all the adapters and `serve` need of them.
//!
//! # Behaviour, and the decisions where the spec is silent
//!
//! * **Registers** have a live copy and a stored copy. [`Action::Store`](crate::Action::Store) copies live to stored,
//!   except system-mode bit 3 (gyro compensation), which the spec says is not stored;
//!   [`Action::LoadStored`](crate::Action::LoadStored) and [`Action::LoadDefaults`](crate::Action::LoadDefaults) copy back.
//! * **Gyro calibration** takes 30 s (10 s to settle, 20 s still) once compensation is switched
//!   on, by action, system-mode write or a write of 0xFFFF to the calibration register. While it
//!   runs, the calibration register reads 0xFFFF; then it reads the calibrated value.
//! * **Angle mode accumulates**, exactly as the spec warns: every frame with the angle bit adds
//!   its angle to the pending turn; the chassis turns at 90°/s until the pending angle is 0.
//!   [`Board::total_turn_commanded`] tells a test what was asked in all.
//! * **Downlink pauses while settings are made** (A6): every settings frame stops it, and it
//!   resumes [`SimConfig::resume_after_ms`] (100 ms by default: a parameter, since the vendor
//!   does not say, A13) after the last one. Counts carry on from
//!   where they stopped (they count frames sent).
//! * Replies go out [`SimConfig::reply_delay_ms`] after the read arrives.
//! * Downlink: IMU at 100 Hz, encoders at 25 Hz, battery at 1 Hz, each with its rolling count;
//!   simple kinematics for omni, mecanum and differential chassis move the encoders and gyro Z;
//!   the battery drains.

use crate::command::Command;
use crate::parse::UplinkParser;
use crate::registers::Snapshot;
use crate::telemetry::Reply;
use heapless::Deque;

#[cfg(feature = "driver")]
mod adapters;
mod line;
mod motion;
mod registers;
#[cfg(feature = "std")]
mod serve;
mod telemetry;
pub mod v1;

#[cfg(feature = "async")]
pub use adapters::SimDelay;
#[cfg(feature = "driver")]
pub use adapters::{SimClock, SimUart};
use line::Line;
pub use line::{Faults, OUT_CAPACITY};
pub use motion::Motion;
pub use registers::FACTORY;
#[cfg(feature = "std")]
pub use serve::serve;

/// What the adapters ([`SimUart`], with feature `driver`) and [`serve`] (feature `std`) need
/// of a simulated board: both generations, [`Board`] (2020) and [`v1::Board`] (v1.0.0),
/// implement it (each method is the board's own, of the same name).
pub trait Simulated {
    /// Bytes from the master, taken at the board's current time.
    fn receive(&mut self, bytes: &[u8]);
    /// Moves the board's time forward to `now_ms` (ms since power-up); time never goes back.
    fn advance(&mut self, now_ms: u64);
    /// Copies bytes for the master that have crossed the wire by now into `buf`; how many.
    fn transmit(&mut self, buf: &mut [u8]) -> usize;
    /// Whether a byte for the master has crossed the wire by now.
    fn byte_arrived(&self) -> bool;
    /// The board's time in ms.
    fn now_ms(&self) -> u64;
}

impl Simulated for Board {
    fn receive(&mut self, bytes: &[u8]) {
        Board::receive(self, bytes);
    }
    fn advance(&mut self, now_ms: u64) {
        Board::advance(self, now_ms);
    }
    fn transmit(&mut self, buf: &mut [u8]) -> usize {
        Board::transmit(self, buf)
    }
    fn byte_arrived(&self) -> bool {
        Board::byte_arrived(self)
    }
    fn now_ms(&self) -> u64 {
        Board::now_ms(self)
    }
}

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

/// The simulated board.
#[derive(Clone, Debug)]
pub struct Board {
    config: SimConfig,
    line: Line,
    uplink: UplinkParser,
    now_ms: u64,
    live: Snapshot,
    stored: Snapshot,
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
    commands: u32,
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
            self.line.queued()
        );
    }
}

impl Board {
    /// A board just powered up with factory settings, at time 0, standing still.
    #[must_use]
    pub fn new(config: SimConfig) -> Self {
        Board {
            config,
            line: Line::new(config.seed),
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
            commands: 0,
        }
    }

    /// Sets the faults to inject from now on.
    pub fn set_faults(&mut self, faults: Faults) {
        self.line.faults = faults;
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

    /// The board's time in ms.
    #[must_use]
    pub const fn now_ms(&self) -> u64 {
        self.now_ms
    }

    /// The live registers.
    #[must_use]
    pub const fn registers(&self) -> &Snapshot {
        &self.live
    }

    /// The stored registers.
    #[must_use]
    pub const fn stored_registers(&self) -> &Snapshot {
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

    /// Downlink frames dropped because the output buffer was full.
    #[must_use]
    pub const fn dropped_frames(&self) -> u32 {
        self.line.dropped_frames
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
            if !self.line.faults.replies_stopped {
                self.send(&reply.encode());
            }
        }
        self.send_due_telemetry(now);
    }
}

fn clamp_i32(v: i64) -> i32 {
    i32::try_from(v.clamp(i64::from(i32::MIN), i64::from(i32::MAX))).unwrap_or(0)
}
