//! The v1.0.0 board's telemetry clock: a 32-byte frame every
//! [`SimConfig::telemetry_period_ms`](super::SimConfig::telemetry_period_ms), paused while
//! settings are made, now and then dropped right after a command.

use super::Board;
use super::motion::quaternion;
use crate::v1::Telemetry;

/// Accelerometer z at rest: 1 g as 1000 raw (the board's scale is unknown; milli-g chosen).
pub const GRAVITY_RAW: i16 = 1_000;

/// The telemetry clock: the next frame, a pause, the last command (a frame right after one
/// may be dropped), and what was sent and dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Streams {
    /// The next frame is due then, ms.
    pub(super) next_telemetry_ms: u64,
    /// Telemetry is paused until then, ms.
    pub(super) quiet_until_ms: u64,
    /// When the last command came, ms.
    pub(super) last_command_ms: Option<u64>,
    /// Frames sent.
    pub(super) telemetry_sent: u32,
    /// Frames dropped for a command that came just before.
    pub(super) telemetry_dropped: u32,
}

impl Streams {
    /// The clock at power-up: the first frame one period in.
    pub(super) fn new(period_ms: u32) -> Self {
        Streams {
            next_telemetry_ms: u64::from(period_ms),
            quiet_until_ms: 0,
            last_command_ms: None,
            telemetry_sent: 0,
            telemetry_dropped: 0,
        }
    }
}

impl Board {
    /// Whether telemetry is paused (a settings frame arrived less than
    /// [`SimConfig::settings_pause_ms`](super::SimConfig::settings_pause_ms) ago).
    #[must_use]
    pub const fn telemetry_paused(&self) -> bool {
        self.port.now_ms < self.streams.quiet_until_ms
    }

    /// Telemetry frames sent.
    #[must_use]
    pub const fn telemetry_sent(&self) -> u32 {
        self.streams.telemetry_sent
    }

    /// Telemetry frames dropped for a command that arrived just before
    /// ([`SimConfig::busy_drop_per_million`](super::SimConfig::busy_drop_per_million)).
    #[must_use]
    pub const fn telemetry_dropped(&self) -> u32 {
        self.streams.telemetry_dropped
    }

    pub(super) fn pause_telemetry(&mut self) {
        self.streams.quiet_until_ms = self
            .port
            .now_ms
            .saturating_add(u64::from(self.config.settings_pause_ms));
    }

    /// Sends the telemetry frame due at `now`, unless telemetry is stopped or paused or the
    /// frame is dropped; the clock goes on either way.
    pub(super) fn send_due_telemetry(&mut self, now: u64) {
        if now < self.streams.next_telemetry_ms {
            return;
        }
        let period = u64::from(self.config.telemetry_period_ms.max(1));
        self.streams.next_telemetry_ms = self.streams.next_telemetry_ms.saturating_add(period);
        if self.port.line.faults.telemetry_stopped || self.telemetry_paused() {
            return;
        }
        let busy = self
            .streams
            .last_command_ms
            .is_some_and(|t| now.saturating_sub(t) <= period);
        if busy && self.port.line.chance(self.config.busy_drop_per_million) {
            self.streams.telemetry_dropped = self.streams.telemetry_dropped.wrapping_add(1);
            return;
        }
        let [_, _, wz] = self.measured_velocity();
        let frame = Telemetry {
            velocity: self.measured_velocity(),
            accel: [0, 0, GRAVITY_RAW],
            gyro: [0, 0, wz],
            quaternion: quaternion(self.chassis.yaw_urad),
            battery_mv: self.chassis.battery_mv,
        };
        self.port.line.send(now, &frame.encode());
        self.streams.telemetry_sent = self.streams.telemetry_sent.wrapping_add(1);
    }
}
