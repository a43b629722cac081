//! A model of the board running the **v1.0.0** firmware (`7B … BCC 7D`, `PROTOCOL-V1.md`):
//! what it was told in, a 32-byte telemetry frame out every [`SimConfig::telemetry_period_ms`],
//! a reply to each readback request. Same line as the 2020 [`Board`](super::Board) (115 200
//! bps pacing, [`Faults`]), same rules: `no_std`, no allocation, no panic on any input.
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
//! # Behaviour, and the decisions where `PROTOCOL-V1.md` is silent
//!
//! * **Telemetry** every 45 ms (22 Hz, 711 B/s; users measured 20–24 Hz, ~640 B/s), the first
//!   45 ms after power-up. Measured body velocity = the commanded one; gyro z = wz (mrad/s);
//!   gyro x, y and accel x, y are 0; accel z is [`GRAVITY_RAW`] (the scale is unknown: 1000
//!   raw = 1 g, i.e. milli-g, chosen). No sensor noise: every value is what was commanded.
//! * **Yaw** integrates the measured wz every ms (µrad), kept in (-π, π]; the quaternion is the
//!   rotation about z by it, × 1000: (cos yaw/2, 0, 0, sin yaw/2), so w ≥ 0.
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

use super::line::Line;
use super::{Faults, Simulated};
use crate::v1::{
    BodyVelocity, COMMAND_LEN, Command, Geometry, MotorVelocity, PAYLOAD_LEN, Pid, Readback, Reply,
    Stats, SystemSettings, Telemetry, UplinkParser,
};
use heapless::{Deque, HistoryBuf};

#[cfg(test)]
mod tests;

/// The system settings at power-up: the vendor example's 0, 10, 3600, 2100, 165.
pub const FACTORY_SYSTEM: SystemSettings = SystemSettings {
    motor_directions: 0,
    encoder_directions: 10,
    pwm_max: 3_600,
    pwm_min: 2_100,
    encoder_ppr: 165,
};

/// The geometry at power-up: the vendor example's 110, 110, 55, 60.
pub const FACTORY_GEOMETRY: Geometry = Geometry {
    wheel_spacing_mm: 110,
    axle_spacing_mm: 110,
    gear_ratio: 55,
    wheel_diameter_mm: 60,
};

/// The PID gains at power-up: the vendor example's 3000, 1050, 0, 3000, 1050.
pub const FACTORY_PID: Pid = Pid {
    position_kp: 3_000,
    position_ki: 1_050,
    position_kd: 0,
    velocity_kp: 3_000,
    velocity_ki: 1_050,
};

/// Accelerometer z at rest: 1 g as 1000 raw (the board's scale is unknown; milli-g chosen).
pub const GRAVITY_RAW: i16 = 1_000;

/// Battery voltage at power-up, mV.
pub const START_MV: i16 = 12_000;

/// How many of the last commands [`Board::received`] keeps.
pub const RECEIVED_LOG: usize = 32;

/// The master → board codes, in the order of [`Board::received_count`]'s counters.
const CODES: [u8; 10] = [0x23, 0x24, 0x25, 0x26, 0x33, 0x34, 0x35, 0x36, 0x40, 0x50];

/// π and 2π in µrad.
const PI_URAD: i64 = 3_141_593;
const TWO_PI_URAD: i64 = 6_283_185;

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

/// What the wheels were last told: the body (`0x25`) or each motor (`0x26`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Drive {
    Body(BodyVelocity),
    Motors(MotorVelocity),
}

/// The simulated v1.0.0 board.
#[derive(Clone, Debug)]
pub struct Board {
    config: SimConfig,
    line: Line,
    uplink: UplinkParser,
    now_ms: u64,
    system: SystemSettings,
    geometry: Geometry,
    pid: Pid,
    drive: Drive,
    yaw_urad: i64,
    battery_mv: i16,
    next_telemetry_ms: u64,
    quiet_until_ms: u64,
    last_command_ms: Option<u64>,
    replies: Deque<(u64, Reply), 8>,
    received: HistoryBuf<Command, RECEIVED_LOG>,
    counts: [u32; CODES.len()],
    commands: u32,
    forced_stops: u32,
    telemetry_sent: u32,
    telemetry_dropped: u32,
}

#[cfg(feature = "defmt")]
impl defmt::Format for Board {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "v1::Board {{ now_ms: {=u64}, velocity: {}, queued: {=usize} }}",
            self.now_ms,
            self.velocity(),
            self.line.queued()
        );
    }
}

impl Board {
    /// A board just powered up with the factory settings, at time 0, standing still.
    #[must_use]
    pub fn new(config: SimConfig) -> Self {
        Board {
            config,
            line: Line::new(config.seed),
            uplink: UplinkParser::new(),
            now_ms: 0,
            system: FACTORY_SYSTEM,
            geometry: FACTORY_GEOMETRY,
            pid: FACTORY_PID,
            drive: Drive::Body(BodyVelocity::FORCED_STOP),
            yaw_urad: 0,
            battery_mv: START_MV,
            next_telemetry_ms: u64::from(config.telemetry_period_ms),
            quiet_until_ms: 0,
            last_command_ms: None,
            replies: Deque::new(),
            received: HistoryBuf::new(),
            counts: [0; CODES.len()],
            commands: 0,
            forced_stops: 0,
            telemetry_sent: 0,
            telemetry_dropped: 0,
        }
    }

    /// Sets the faults to inject from now on.
    pub fn set_faults(&mut self, faults: Faults) {
        self.line.faults = faults;
    }

    /// Bytes from the master, taken at the board's current time.
    pub fn receive(&mut self, bytes: &[u8]) {
        for byte in bytes {
            let mut found = self.uplink.push(*byte);
            while let Some(command) = found {
                self.execute(command);
                found = self.uplink.poll();
            }
        }
    }

    /// Moves the board's time forward to `now_ms` (ms since power-up): the chassis turns,
    /// replies and telemetry fall due. Time never goes back.
    pub fn advance(&mut self, now_ms: u64) {
        while self.now_ms < now_ms {
            self.now_ms = self.now_ms.saturating_add(1);
            self.step_one_ms();
        }
    }

    /// Copies bytes for the master into `buf`, with the faults applied; returns how many.
    pub fn transmit(&mut self, buf: &mut [u8]) -> usize {
        self.line.transmit(self.now_ms, buf)
    }

    /// Whether a byte for the master has crossed the wire by now.
    #[must_use]
    pub fn byte_arrived(&self) -> bool {
        self.line.byte_arrived(self.now_ms)
    }

    /// The board's time in ms.
    #[must_use]
    pub const fn now_ms(&self) -> u64 {
        self.now_ms
    }

    /// The body-velocity state, as `0x35` answers it: the last `0x25` frame as received, or
    /// after a `0x26` its `ctl` and type with the body velocity its wheel speeds give.
    #[must_use]
    pub fn velocity(&self) -> BodyVelocity {
        match self.drive {
            Drive::Body(v) => v,
            Drive::Motors(m) => {
                let [vx_mm_s, vy_mm_s, wz_mrad_s] = self.measured_velocity();
                BodyVelocity {
                    ctl: m.ctl,
                    kind: m.kind,
                    vx_mm_s,
                    vy_mm_s,
                    wz_mrad_s,
                }
            }
        }
    }

    /// The wheel speeds, as `0x36` answers them: the last `0x26` command's (0 unless its `ctl`
    /// drives), or those the body velocity gives, with the `0x25` frame's `ctl` and type.
    #[must_use]
    pub fn motor_speeds(&self) -> MotorVelocity {
        match self.drive {
            Drive::Motors(m) if m.ctl == BodyVelocity::DRIVE => m,
            Drive::Motors(m) => MotorVelocity {
                speeds: [0; 4],
                ..m
            },
            Drive::Body(v) => MotorVelocity {
                ctl: v.ctl,
                kind: v.kind,
                speeds: wheels(self.measured_velocity(), self.lever_mm()),
            },
        }
    }

    /// The body velocity the chassis moves at (what telemetry reports): vx, vy (mm/s), wz
    /// (mrad/s); 0 unless the last command's `ctl` drives.
    #[must_use]
    pub fn measured_velocity(&self) -> [i16; 3] {
        match self.drive {
            Drive::Body(v) if v.ctl == BodyVelocity::DRIVE => [v.vx_mm_s, v.vy_mm_s, v.wz_mrad_s],
            Drive::Motors(m) if m.ctl == BodyVelocity::DRIVE => body(m.speeds, self.lever_mm()),
            Drive::Body(_) | Drive::Motors(_) => [0; 3],
        }
    }

    /// The heading, in µrad in (-π, π]: wz integrated since power-up.
    #[must_use]
    pub const fn yaw_urad(&self) -> i64 {
        self.yaw_urad
    }

    /// The system settings (last written, or the factory's).
    #[must_use]
    pub const fn system(&self) -> SystemSettings {
        self.system
    }

    /// The geometry (last written, or the factory's).
    #[must_use]
    pub const fn geometry(&self) -> Geometry {
        self.geometry
    }

    /// The PID gains (last written, or the factory's).
    #[must_use]
    pub const fn pid(&self) -> Pid {
        self.pid
    }

    /// The battery voltage, mV.
    #[must_use]
    pub const fn battery_mv(&self) -> i16 {
        self.battery_mv
    }

    /// Whether telemetry is paused (a settings frame arrived less than
    /// [`SimConfig::settings_pause_ms`] ago).
    #[must_use]
    pub const fn telemetry_paused(&self) -> bool {
        self.now_ms < self.quiet_until_ms
    }

    /// Commands taken so far (of every kind).
    #[must_use]
    pub const fn total_commands(&self) -> u32 {
        self.commands
    }

    /// Commands with code `code` taken so far (0 for a code that is no command).
    #[must_use]
    pub fn received_count(&self, code: u8) -> u32 {
        CODES
            .iter()
            .position(|c| *c == code)
            .and_then(|i| self.counts.get(i))
            .copied()
            .unwrap_or(0)
    }

    /// The last [`RECEIVED_LOG`] commands taken, oldest first.
    pub fn received(&self) -> impl Iterator<Item = &Command> + '_ {
        self.received.oldest_ordered()
    }

    /// Forced stops taken (`0x25` with `ctl` 0 and everything 0).
    #[must_use]
    pub const fn forced_stops(&self) -> u32 {
        self.forced_stops
    }

    /// Whole frames from the master refused: BCC or end byte wrong, or a readback request
    /// whose payload is not ten `00` (the parser's [`Stats`]: `bad_checksum + bad_end +
    /// refused`).
    #[must_use]
    pub fn bad_frames(&self) -> u32 {
        let s = self.uplink.stats();
        s.bad_checksum
            .saturating_add(s.bad_end)
            .saturating_add(s.refused)
    }

    /// What the board's parser of the master's bytes has seen.
    #[must_use]
    pub fn uplink_stats(&self) -> Stats {
        self.uplink.stats()
    }

    /// Telemetry frames sent.
    #[must_use]
    pub const fn telemetry_sent(&self) -> u32 {
        self.telemetry_sent
    }

    /// Telemetry frames dropped for a command that arrived just before
    /// ([`SimConfig::busy_drop_per_million`]).
    #[must_use]
    pub const fn telemetry_dropped(&self) -> u32 {
        self.telemetry_dropped
    }

    /// Frames dropped because the line's buffer was full (nobody read them).
    #[must_use]
    pub const fn overflowed_frames(&self) -> u32 {
        self.line.dropped_frames
    }

    fn execute(&mut self, command: Command) {
        self.commands = self.commands.wrapping_add(1);
        self.last_command_ms = Some(self.now_ms);
        self.received.write(command);
        if let Some(count) = CODES
            .iter()
            .position(|c| *c == command.code())
            .and_then(|i| self.counts.get_mut(i))
        {
            *count = count.wrapping_add(1);
        }
        match command {
            Command::BodyVelocity(v) => {
                if v.is_forced_stop() {
                    self.forced_stops = self.forced_stops.wrapping_add(1);
                }
                self.drive = Drive::Body(v);
            }
            Command::MotorVelocity(m) => self.drive = Drive::Motors(m),
            Command::System(s) => {
                self.system = s;
                self.pause_telemetry();
            }
            Command::Geometry(g) => {
                self.geometry = g;
                self.pause_telemetry();
            }
            Command::Pid(p) => {
                self.pid = p;
                self.pause_telemetry();
            }
            Command::Readback(request) => {
                let frame = match request {
                    Readback::System => Command::System(self.system),
                    Readback::Geometry => Command::Geometry(self.geometry),
                    Readback::BodyVelocity => Command::BodyVelocity(self.velocity()),
                    Readback::MotorSpeeds => Command::MotorVelocity(self.motor_speeds()),
                    Readback::Pid => Command::Pid(self.pid),
                }
                .encode();
                let reply = Reply {
                    request,
                    payload: payload_of(&frame),
                };
                let due = self
                    .now_ms
                    .saturating_add(u64::from(self.config.reply_delay_ms));
                // More than eight requests unanswered: the newest is lost.
                let _ = self.replies.push_back((due, reply));
            }
        }
    }

    fn pause_telemetry(&mut self) {
        self.quiet_until_ms = self
            .now_ms
            .saturating_add(u64::from(self.config.settings_pause_ms));
    }

    fn step_one_ms(&mut self) {
        let now = self.now_ms;
        let [_, _, wz] = self.measured_velocity();
        // mrad/s for 1 ms: µrad.
        self.yaw_urad = wrap_yaw(self.yaw_urad.saturating_add(i64::from(wz)));
        let moving = self.measured_velocity() != [0; 3];
        let drain_every = if moving { 2_000 } else { 20_000 };
        if now.checked_rem(drain_every) == Some(0) {
            self.battery_mv = self.battery_mv.saturating_sub(1).max(0);
        }
        while let Some((due, reply)) = self.replies.front().copied() {
            if due > now {
                break;
            }
            let _ = self.replies.pop_front();
            if !self.line.faults.replies_stopped {
                self.line.send(now, &reply.encode());
            }
        }
        self.send_due_telemetry(now);
    }

    /// Sends the telemetry frame due at `now`, unless telemetry is stopped or paused or the
    /// frame is dropped; the clock goes on either way.
    fn send_due_telemetry(&mut self, now: u64) {
        if now < self.next_telemetry_ms {
            return;
        }
        let period = u64::from(self.config.telemetry_period_ms.max(1));
        self.next_telemetry_ms = self.next_telemetry_ms.saturating_add(period);
        if self.line.faults.telemetry_stopped || self.telemetry_paused() {
            return;
        }
        let busy = self
            .last_command_ms
            .is_some_and(|t| now.saturating_sub(t) <= period);
        if busy && self.line.chance(self.config.busy_drop_per_million) {
            self.telemetry_dropped = self.telemetry_dropped.wrapping_add(1);
            return;
        }
        let [_, _, wz] = self.measured_velocity();
        let frame = Telemetry {
            velocity: self.measured_velocity(),
            accel: [0, 0, GRAVITY_RAW],
            gyro: [0, 0, wz],
            quaternion: quaternion(self.yaw_urad),
            battery_mv: self.battery_mv,
        };
        self.line.send(now, &frame.encode());
        self.telemetry_sent = self.telemetry_sent.wrapping_add(1);
    }

    /// The lever of the rotation on each wheel: (wheel spacing + axle spacing) / 2, mm.
    fn lever_mm(&self) -> i32 {
        (i32::from(self.geometry.wheel_spacing_mm)
            .saturating_add(i32::from(self.geometry.axle_spacing_mm)))
            / 2
    }
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

/// The ten payload bytes of a 14-byte frame.
fn payload_of(frame: &[u8; COMMAND_LEN]) -> [u8; PAYLOAD_LEN] {
    let mut payload = [0u8; PAYLOAD_LEN];
    for (to, from) in payload.iter_mut().zip(frame.iter().skip(2)) {
        *to = *from;
    }
    payload
}

fn saturate(v: i32) -> i16 {
    i16::try_from(v.clamp(i32::from(i16::MIN), i32::from(i16::MAX))).unwrap_or(0)
}

/// Mecanum wheel rim speeds (mm/s) of a body velocity (vx, vy mm/s, wz mrad/s): M1 front-left,
/// M2 front-right, M3 rear-left, M4 rear-right.
fn wheels([vx, vy, wz]: [i16; 3], lever_mm: i32) -> [i16; 4] {
    let (vx, vy) = (i32::from(vx), i32::from(vy));
    let turn = i32::from(wz).saturating_mul(lever_mm) / 1_000;
    [
        vy.saturating_add(vx).saturating_sub(turn),
        vy.saturating_sub(vx).saturating_add(turn),
        vy.saturating_sub(vx).saturating_sub(turn),
        vy.saturating_add(vx).saturating_add(turn),
    ]
    .map(saturate)
}

/// The body velocity of mecanum wheel speeds: the inverse of [`wheels`].
fn body(speeds: [i16; 4], lever_mm: i32) -> [i16; 3] {
    let [m1, m2, m3, m4] = speeds.map(i32::from);
    let vy = m1.saturating_add(m2).saturating_add(m3).saturating_add(m4) / 4;
    let vx = m1.saturating_add(m4).saturating_sub(m2).saturating_sub(m3) / 4;
    let turn = m2.saturating_add(m4).saturating_sub(m1).saturating_sub(m3);
    let wz = turn
        .saturating_mul(1_000)
        .checked_div(lever_mm.saturating_mul(4))
        .unwrap_or(0);
    [saturate(vx), saturate(vy), saturate(wz)]
}

/// `yaw` back into (-π, π] (it moves less than 2π a step).
fn wrap_yaw(yaw: i64) -> i64 {
    if yaw > PI_URAD {
        yaw.saturating_sub(TWO_PI_URAD)
    } else if yaw <= -PI_URAD {
        yaw.saturating_add(TWO_PI_URAD)
    } else {
        yaw
    }
}

/// The quaternion w, x, y, z (× 1000) of a rotation by `yaw_urad` (in (-π, π]) about z.
fn quaternion(yaw_urad: i64) -> [i16; 4] {
    let (sin, cos) = sin_cos(yaw_urad as f64 / 2_000_000.0);
    [milli(cos), 0, 0, milli(sin)]
}

/// Sine and cosine of `x` (|x| ≤ π/2) by their Taylor series to x¹⁵ and x¹⁴ (error < 1e-9;
/// `core` has no `sin`).
fn sin_cos(x: f64) -> (f64, f64) {
    let x2 = x * x;
    let (mut sin, mut cos) = (x, 1.0);
    let (mut sin_term, mut cos_term) = (x, 1.0);
    let mut k = 0.0;
    for _ in 0..7 {
        k += 2.0;
        cos_term *= -x2 / ((k - 1.0) * k);
        sin_term *= -x2 / (k * (k + 1.0));
        cos += cos_term;
        sin += sin_term;
    }
    (sin, cos)
}

/// `v` × 1000, rounded (half away from 0).
fn milli(v: f64) -> i16 {
    let r = v * 1_000.0;
    (if r < 0.0 { r - 0.5 } else { r + 0.5 }) as i16
}
