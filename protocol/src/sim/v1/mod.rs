//! A model of the board running the **v1.0.0** firmware (`7B … BCC 7D`, `docs/protocol-v1.md`):
//! what it was told in, a 32-byte telemetry frame out every [`SimConfig::telemetry_period_ms`],
//! a reply to each readback request. Same line as the 2020 [`Board`](super::Board) (115 200
//! bps pacing, [`Faults`](super::Faults)), same rules: `no_std`, no allocation, no panic on any input.
//!
//! ```
//! use chassis_protocol::sim::v1::{Board, SimConfig};
//! use chassis_protocol::v1::{BodyVelocity, Command, Downlink, DownlinkParser, Parser, Readback};
//!
//! let mut board = Board::new(SimConfig::default());
//! board.receive(&Command::BodyVelocity(BodyVelocity::new(0, 300, 0)).encode());
//! board.receive(&Command::Readback(Readback::Geometry).encode());
//! let (mut parser, mut buf, mut frames) = (DownlinkParser::new(), [0u8; 64], Vec::new());
//! for ms in 1..=1_000 {
//!     board.advance(ms);
//!     let n = board.transmit(&mut buf);
//!     frames.extend(parser.frames(&buf[..n]));
//! }
//! let replies: Vec<_> = frames.iter().filter_map(|f| match f {
//!     Downlink::Reply(r) => r.geometry(),
//!     Downlink::Telemetry(_) => None,
//! }).collect();
//! assert_eq!(replies[0].wheel_diameter_mm, 60); // the vendor's example, the factory default
//! assert!(frames.iter().any(|f| matches!(f, Downlink::Telemetry(t) if t.velocity[1] == 300)));
//! ```
//!
//! # Behaviour, and the decisions where the protocol is silent
//!
//! * **Telemetry** every 45 ms (22 Hz, 711 B/s; users measured 20–24 Hz, ~640 B/s), the first
//!   45 ms after power-up. Measured body velocity = the commanded one; gyro z = wz (mrad/s);
//!   gyro x, y and accel x, y are 0; accel z is [`GRAVITY_RAW`] (the scale is unknown: 1000
//!   raw = 1 g, i.e. milli-g, chosen). No sensor noise: every value is what was commanded.
//! * **Yaw** integrates the measured wz every ms (µrad), kept in (-π, π]; the quaternion is the
//!   rotation about z by it, × 1000: (cos yaw/2, 0, 0, sin yaw/2), so w ≥ 0.
//! * **True pose** ([`Board::pose`]): the measured body velocity integrated every ms in f64,
//!   in REP-103 axes (x forward = the board's vy, y left = −vx, yaw counter-clockwise = wz).
//! * **Battery** starts at [`START_MV`] and drains 1 mV every 2 s while moving, every 20 s
//!   standing.
//! * **No watchdog**, as none is documented: the last velocity is kept until another command.
//! * **`ctl`**: `0x25` or `0x26` with `ctl` other than `0x02` stands the chassis still (measured
//!   velocity 0); the frame is kept as the state `0x35` reports. The forced stop (`ctl` 0, all 0)
//!   is one such frame, and is counted ([`Board::forced_stops`]).
//! * **Kinematics** (mecanum; wheel order and signs are not documented, chosen): vx to the
//!   right, vy forward, wz counter-clockwise; wheel rim speeds in mm/s ("mm/s or 1000·r":
//!   mm/s chosen) with the lever L = (wheel spacing + axle spacing) / 2 mm:
//!   M1 front-left = vy + vx − L·wz, M2 front-right = vy − vx + L·wz, M3 rear-left =
//!   vy − vx − L·wz, M4 rear-right = vy + vx + L·wz (wz in rad/s). A `0x26` command drives
//!   the wheels as given, and the body velocity is worked back from them (the inverse).
//! * **Readbacks** are answered [`SimConfig::reply_delay_ms`] after they arrive: `0x33`,
//!   `0x34`, `0x50` with the last written settings (factory defaults: the vendor example's,
//!   [`FACTORY_SYSTEM`], [`FACTORY_GEOMETRY`], [`FACTORY_PID`]), `0x35` with the body-velocity
//!   state ([`Board::velocity`]), `0x36` with the wheel speeds ([`Board::motor_speeds`]).
//! * **Settings** (`0x23`, `0x24`, `0x40`) are stored (not across power-ups: nothing says how
//!   the board keeps them) and get no reply; each pauses telemetry for
//!   [`SimConfig::settings_pause_ms`] (100 ms: users report the vendor's start-up needs its
//!   0.1 s pauses between them).
//! * **Dropped telemetry**: a frame due within [`SimConfig::telemetry_period_ms`] after a
//!   command (of any kind) is dropped with probability [`SimConfig::busy_drop_per_million`]
//!   (6 %; at 20 commands/s about 90 % of the frames are so placed: 5.4 % lost, users report
//!   ~6 %). Never while no command arrives. The random numbers come from the seed (xorshift).

use super::Port;
use crate::v1::{COMMAND_LEN, Command, PAYLOAD_LEN, Readback, Reply, Stats, UplinkParser};
use heapless::{Deque, HistoryBuf};

mod motion;
mod registers;
mod telemetry;
#[cfg(test)]
mod tests;

pub use motion::START_MV;
use motion::{Chassis, Drive};
use registers::Registers;
pub use registers::{FACTORY_GEOMETRY, FACTORY_PID, FACTORY_SYSTEM};
pub use telemetry::GRAVITY_RAW;
use telemetry::Streams;

/// How many of the last commands [`Board::received`] keeps.
pub const RECEIVED_LOG: usize = 32;

/// The master → board codes, in the order of [`Board::received_count`]'s counters.
const CODES: [u8; 10] = [0x23, 0x24, 0x25, 0x26, 0x33, 0x34, 0x35, 0x36, 0x40, 0x50];

/// How the simulated v1.0.0 board behaves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimConfig {
    /// Seed of the fault injection and of the dropped telemetry.
    pub seed: u64,
    /// A telemetry frame every this many ms (45: 22 Hz).
    pub telemetry_period_ms: u32,
    /// Delay between a readback request arriving and its reply going out, in ms.
    pub reply_delay_ms: u32,
    /// Telemetry pauses this long after each settings frame, in ms.
    pub settings_pause_ms: u32,
    /// Chance, per million, that a telemetry frame due within a period after a command is
    /// dropped (60 000: 6 %; 0: never).
    pub busy_drop_per_million: u32,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            seed: 1,
            telemetry_period_ms: 45,
            reply_delay_ms: 3,
            settings_pause_ms: 100,
            busy_drop_per_million: 60_000,
        }
    }
}

/// The simulated v1.0.0 board.
#[derive(Clone, Debug)]
pub struct Board {
    config: SimConfig,
    port: Port<UplinkParser>,
    /// The settings it keeps.
    registers: Registers,
    /// What the chassis does.
    chassis: Chassis,
    /// The telemetry clock.
    streams: Streams,
    replies: Deque<(u64, Reply), 8>,
    /// What it was sent.
    log: Received,
}

/// What the board was sent: the last commands, a count per code, and in all.
#[derive(Clone, Debug)]
struct Received {
    /// The last [`RECEIVED_LOG`] commands.
    commands: HistoryBuf<Command, RECEIVED_LOG>,
    /// Commands taken, per code of [`CODES`].
    per_code: [u32; CODES.len()],
    /// Commands taken, of every kind.
    total: u32,
    /// Forced stops taken.
    forced_stops: u32,
}

#[cfg(feature = "defmt")]
impl defmt::Format for Board {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "v1::Board {{ now_ms: {=u64}, velocity: {}, queued: {=usize} }}",
            self.port.now_ms,
            self.velocity(),
            self.port.line.queued()
        );
    }
}

impl Board {
    /// A board just powered up with the factory settings, at time 0, standing still.
    #[must_use]
    pub fn new(config: SimConfig) -> Self {
        Board {
            config,
            port: Port::new(config.seed, UplinkParser::new()),
            registers: Registers::new(),
            chassis: Chassis::new(),
            streams: Streams::new(config.telemetry_period_ms),
            replies: Deque::new(),
            log: Received {
                commands: HistoryBuf::new(),
                per_code: [0; CODES.len()],
                total: 0,
                forced_stops: 0,
            },
        }
    }

    /// Commands taken so far (of every kind).
    #[must_use]
    pub const fn total_commands(&self) -> u32 {
        self.log.total
    }

    /// Commands with code `code` taken so far (0 for a code that is no command).
    #[must_use]
    pub fn received_count(&self, code: u8) -> u32 {
        CODES
            .iter()
            .position(|c| *c == code)
            .and_then(|i| self.log.per_code.get(i))
            .copied()
            .unwrap_or(0)
    }

    /// The last [`RECEIVED_LOG`] commands taken, oldest first.
    pub fn received(&self) -> impl Iterator<Item = &Command> + '_ {
        self.log.commands.oldest_ordered()
    }

    /// Forced stops taken (`0x25` with `ctl` 0 and everything 0).
    #[must_use]
    pub const fn forced_stops(&self) -> u32 {
        self.log.forced_stops
    }

    /// Whole frames from the master refused: BCC or end byte wrong, or a readback request
    /// whose payload is not ten `00` (the parser's [`Stats`]: `bad_checksum + bad_end +
    /// refused`).
    #[must_use]
    pub fn bad_frames(&self) -> u32 {
        let s = self.port.uplink.stats();
        s.bad_checksum
            .saturating_add(s.bad_end)
            .saturating_add(s.refused)
    }

    /// What the board's parser of the master's bytes has seen.
    #[must_use]
    pub fn uplink_stats(&self) -> Stats {
        self.port.uplink.stats()
    }

    /// Frames dropped because the line's buffer was full (nobody read them).
    #[must_use]
    pub const fn overflowed_frames(&self) -> u32 {
        self.port.line.dropped_frames
    }

    fn execute(&mut self, command: Command) {
        self.log.total = self.log.total.wrapping_add(1);
        self.streams.last_command_ms = Some(self.port.now_ms);
        self.log.commands.write(command);
        if let Some(count) = CODES
            .iter()
            .position(|c| *c == command.code())
            .and_then(|i| self.log.per_code.get_mut(i))
        {
            *count = count.wrapping_add(1);
        }
        match command {
            Command::BodyVelocity(v) => {
                if v.is_forced_stop() {
                    self.log.forced_stops = self.log.forced_stops.wrapping_add(1);
                }
                self.chassis.drive = Drive::Body(v);
            }
            Command::MotorVelocity(m) => self.chassis.drive = Drive::Motors(m),
            Command::System(s) => {
                self.registers.system = s;
                self.pause_telemetry();
            }
            Command::Geometry(g) => {
                self.registers.geometry = g;
                self.pause_telemetry();
            }
            Command::Pid(p) => {
                self.registers.pid = p;
                self.pause_telemetry();
            }
            Command::Readback(request) => {
                let frame = match request {
                    Readback::System => Command::System(self.registers.system),
                    Readback::Geometry => Command::Geometry(self.registers.geometry),
                    Readback::BodyVelocity => Command::BodyVelocity(self.velocity()),
                    Readback::MotorSpeeds => Command::MotorVelocity(self.motor_speeds()),
                    Readback::Pid => Command::Pid(self.registers.pid),
                }
                .encode();
                let reply = Reply {
                    request,
                    payload: payload_of(&frame),
                };
                let due = self
                    .port
                    .now_ms
                    .saturating_add(u64::from(self.config.reply_delay_ms));
                // More than eight requests unanswered: the newest is lost.
                let _ = self.replies.push_back((due, reply));
            }
        }
    }

    fn step_one_ms(&mut self) {
        let now = self.port.now_ms;
        self.move_chassis(now);
        while let Some((due, reply)) = self.replies.front().copied() {
            if due > now {
                break;
            }
            let _ = self.replies.pop_front();
            if !self.port.line.faults.replies_stopped {
                self.port.line.send(now, &reply.encode());
            }
        }
        self.send_due_telemetry(now);
    }
}

/// The ten payload bytes of a 14-byte frame.
fn payload_of(frame: &[u8; COMMAND_LEN]) -> [u8; PAYLOAD_LEN] {
    let mut payload = [0u8; PAYLOAD_LEN];
    for (to, from) in payload.iter_mut().zip(frame.iter().skip(2)) {
        *to = *from;
    }
    payload
}

super::wire_side!();
