//! [`DriverCore`]: the driver's logic with no I/O and no clock.

use super::{Config, Error};
use crate::command::{Motors, Register, Setting, Turn, Velocity};
use crate::parse::{DownlinkParser, DownlinkStats, Lock};
use crate::telemetry::{Battery, Encoders, Imu, Reply, Stream, Telemetry};

/// A value and the time it arrived.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stamped<T> {
    /// The value.
    pub value: T,
    /// When it arrived, in ms.
    pub at_ms: u64,
}

/// What the driver knows of one telemetry stream.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StreamInfo {
    /// Frames received.
    pub frames: u32,
    /// Frames missing according to the count bytes.
    pub missed: u32,
    /// Mean interval between frames, in µs (smoothed); 0 until two frames have come.
    pub interval_us: u32,
    last_ms: Option<u64>,
}

impl StreamInfo {
    /// Frames per second, from the smoothed interval (0 until two frames have come).
    #[must_use]
    pub fn rate_hz(&self) -> u32 {
        1_000_000u32.checked_div(self.interval_us).unwrap_or(0)
    }

    fn arrived(&mut self, at_ms: u64) {
        self.frames = self.frames.wrapping_add(1);
        if let Some(last) = self.last_ms {
            let gap_us =
                u32::try_from(at_ms.saturating_sub(last).saturating_mul(1_000)).unwrap_or(u32::MAX);
            // Exponential smoothing, 1/8 of the new interval.
            self.interval_us = if self.interval_us == 0 {
                gap_us
            } else {
                let old = self.interval_us;
                old.saturating_sub(old / 8).saturating_add(gap_us / 8)
            };
        }
        self.last_ms = Some(at_ms);
    }
}

/// Something the core saw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// A telemetry frame (also kept as the latest of its stream).
    Telemetry(Telemetry),
    /// The reply to the read that was waiting.
    Reply(Reply),
    /// A reply for another register than the one waiting, or with none waiting.
    StrayReply(Reply),
}

/// Bytes read from the UART but not yet through the parser: what a shell keeps between calls so
/// that nothing is dropped when an event comes out mid-read.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RxBuffer {
    bytes: [u8; RxBuffer::LEN],
    start: usize,
    end: usize,
}

impl Default for RxBuffer {
    fn default() -> Self {
        Self::new()
    }
}

impl RxBuffer {
    /// Bytes read from the UART at a time.
    pub const LEN: usize = 32;

    /// An empty buffer.
    #[must_use]
    pub const fn new() -> Self {
        RxBuffer {
            bytes: [0; Self::LEN],
            start: 0,
            end: 0,
        }
    }

    /// Feeds the bytes held to `core` until one completes an event.
    pub fn drain(&mut self, core: &mut DriverCore, now_ms: u64) -> Option<Event> {
        if self.start >= self.end {
            return None;
        }
        let pending = self.bytes.get(self.start..self.end).unwrap_or(&[]);
        let (event, rest) = core.receive(pending, now_ms);
        self.start = self.end.saturating_sub(rest.len());
        event
    }

    /// Where to read into: the whole buffer (call only once [`drain`](Self::drain) has
    /// emptied it), then [`filled`](Self::filled) with the count read.
    pub fn space(&mut self) -> &mut [u8] {
        &mut self.bytes
    }

    /// Records that `n` bytes were read into [`space`](Self::space).
    pub fn filled(&mut self, n: usize) {
        self.start = 0;
        self.end = n.min(Self::LEN);
    }
}

/// The turn guard: see the module docs of [`crate::driver`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum TurnState {
    Idle,
    Outstanding,
}

/// The driver's logic: frames out, telemetry in, reply matching, the reply timeout, the
/// failsafe and the one-shot turn guard. No I/O, no clock: bytes and the time in ms come in as
/// arguments, bytes to send come out.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriverCore {
    config: Config,
    parser: DownlinkParser,
    waiting: Option<(Register, u64)>,
    imu: Option<Stamped<Imu>>,
    encoders: Option<Stamped<Encoders>>,
    battery: Option<Stamped<Battery>>,
    streams: [StreamInfo; 3],
    last_telemetry_ms: Option<u64>,
    last_byte_ms: Option<u64>,
    moving_since_ms: Option<u64>,
    turn: TurnState,
    failsafe_stops: u32,
}

// RAM budget of the core (the parser, latest frames, stream figures, timers): 360 bytes on
// thumbv7em and on 64-bit hosts alike (u64 is 8-aligned on both).
const _: () = assert!(
    core::mem::size_of::<DriverCore>() <= 384,
    "DriverCore over its RAM budget"
);
#[cfg(target_arch = "arm")]
const _: () = assert!(core::mem::size_of::<DriverCore>() == 360);

impl DriverCore {
    /// A core that has heard nothing and sent nothing.
    #[must_use]
    pub const fn new(config: Config) -> Self {
        DriverCore {
            config,
            parser: DownlinkParser::new(),
            waiting: None,
            imu: None,
            encoders: None,
            battery: None,
            streams: [StreamInfo {
                frames: 0,
                missed: 0,
                interval_us: 0,
                last_ms: None,
            }; 3],
            last_telemetry_ms: None,
            last_byte_ms: None,
            moving_since_ms: None,
            turn: TurnState::Idle,
            failsafe_stops: 0,
        }
    }

    /// The configuration.
    #[must_use]
    pub const fn config(&self) -> &Config {
        &self.config
    }

    /// Bytes of a body-velocity frame (safe to send again and again).
    pub fn velocity(&mut self, velocity: Velocity, now_ms: u64) -> [u8; Velocity::LEN] {
        let moving = velocity.x != 0 || velocity.y != 0 || velocity.z != 0;
        self.set_moving(moving, now_ms);
        velocity.encode()
    }

    /// Bytes of a per-motor frame.
    pub fn motors(&mut self, motors: Motors, now_ms: u64) -> [u8; Motors::LEN] {
        self.set_moving(motors.values.iter().any(|v| *v != 0), now_ms);
        motors.encode()
    }

    /// Bytes of the stop frame (all velocities 0).
    pub fn stop(&mut self) -> [u8; Velocity::LEN] {
        self.moving_since_ms = None;
        Velocity::STOP.encode()
    }

    /// Bytes of a turn by `deci_degrees` (0.1°), standing still, **once**: refused with
    /// [`Error::TurnInProgress`] while an earlier turn is outstanding.
    pub fn turn<E>(&mut self, deci_degrees: i32, now_ms: u64) -> Result<[u8; Turn::LEN], Error<E>> {
        if self.turn == TurnState::Outstanding {
            return Err(Error::TurnInProgress);
        }
        self.turn = TurnState::Outstanding;
        self.set_moving(true, now_ms);
        Ok(Turn::by_deci_degrees(deci_degrees).encode())
    }

    /// Whether a turn is outstanding.
    #[must_use]
    pub fn turning(&self) -> bool {
        self.turn == TurnState::Outstanding
    }

    /// Forgets an outstanding turn without asking the board (after a board reset, say). The next
    /// [`turn`](DriverCore::turn) is then sent even if the board is still turning, and adds up.
    pub fn abandon_turn(&mut self) {
        self.turn = TurnState::Idle;
    }

    /// Bytes of a settings frame. A read arms the reply matching and its timeout; a second read
    /// while one waits is [`Error::Busy`].
    pub fn setting<E>(
        &mut self,
        setting: Setting,
        now_ms: u64,
    ) -> Result<[u8; Setting::LEN], Error<E>> {
        if let Setting::Read(register) = setting {
            if self.waiting.is_some() {
                return Err(Error::Busy);
            }
            let deadline = now_ms.saturating_add(u64::from(self.config.reply_timeout_ms()));
            self.waiting = Some((register, deadline));
        }
        Ok(setting.encode())
    }

    /// Gives up the read that waits for its reply (a late reply then comes as a stray one).
    pub fn cancel_read(&mut self) {
        self.waiting = None;
    }

    /// The register whose reply is awaited, if any.
    #[must_use]
    pub fn waiting_for(&self) -> Option<Register> {
        self.waiting.map(|(r, _)| r)
    }

    /// Feeds received bytes; returns the first event they complete and the bytes not yet
    /// consumed (feed them again: nothing is dropped).
    pub fn receive<'a>(&mut self, bytes: &'a [u8], now_ms: u64) -> (Option<Event>, &'a [u8]) {
        if !bytes.is_empty() {
            self.last_byte_ms = Some(now_ms);
        }
        let mut rest = bytes;
        loop {
            let (frame, later) = self.parser.push_slice(rest);
            rest = later;
            match frame {
                Some(frame) => {
                    if let Some(event) = self.frame(frame, now_ms) {
                        return (Some(event), rest);
                    }
                }
                None => return (None, rest),
            }
        }
    }

    /// Call when no byte has arrived for a while: after [`Config::idle_ms`] of silence the line
    /// is quiet, which completes a frame that waits for proof (a reply alone on the line).
    pub fn quiet(&mut self, now_ms: u64) -> Option<Event> {
        let silent = self
            .last_byte_ms
            .is_some_and(|t| now_ms.saturating_sub(t) >= u64::from(self.config.idle_ms));
        if !silent {
            return None;
        }
        while let Some(frame) = self.parser.idle() {
            if let Some(event) = self.frame(frame, now_ms) {
                return Some(event);
            }
        }
        None
    }

    /// Checks the reply timeout: the register whose read has timed out (and is given up).
    pub fn reply_timed_out(&mut self, now_ms: u64) -> Option<Register> {
        match self.waiting {
            Some((register, deadline)) if now_ms > deadline => {
                self.waiting = None;
                Some(register)
            }
            _ => None,
        }
    }

    /// The failsafe: if the chassis is moving and telemetry has been silent for longer than
    /// [`Config::failsafe_ms`], the stop frame to send now (once).
    pub fn failsafe(&mut self, now_ms: u64) -> Option<[u8; Velocity::LEN]> {
        let since = self.moving_since_ms?;
        let heard = self.last_telemetry_ms.map_or(since, |t| t.max(since));
        if now_ms.saturating_sub(heard) > u64::from(self.config.failsafe_ms) {
            self.failsafe_stops = self.failsafe_stops.wrapping_add(1);
            Some(self.stop())
        } else {
            None
        }
    }

    /// Times the failsafe has stopped the chassis.
    #[must_use]
    pub const fn failsafe_stops(&self) -> u32 {
        self.failsafe_stops
    }

    /// Whether telemetry has come within [`Config::failsafe_ms`].
    #[must_use]
    pub fn link_alive(&self, now_ms: u64) -> bool {
        self.last_telemetry_ms
            .is_some_and(|t| now_ms.saturating_sub(t) <= u64::from(self.config.failsafe_ms))
    }

    /// Whether the driver last told the chassis to move.
    #[must_use]
    pub const fn moving(&self) -> bool {
        self.moving_since_ms.is_some()
    }

    /// The latest IMU frame and when it came.
    #[must_use]
    pub const fn imu(&self) -> Option<Stamped<Imu>> {
        self.imu
    }

    /// The latest encoder frame and when it came.
    #[must_use]
    pub const fn encoders(&self) -> Option<Stamped<Encoders>> {
        self.encoders
    }

    /// The latest battery frame and when it came.
    #[must_use]
    pub const fn battery(&self) -> Option<Stamped<Battery>> {
        self.battery
    }

    /// Rate and drops of one stream.
    #[must_use]
    pub fn stream(&self, stream: Stream) -> StreamInfo {
        self.streams
            .get(stream.index())
            .copied()
            .unwrap_or_default()
    }

    /// The parser's counters.
    #[must_use]
    pub const fn parser_stats(&self) -> &DownlinkStats {
        self.parser.stats()
    }

    /// How sure the parser is of the frame boundaries.
    #[must_use]
    pub const fn lock(&self) -> Lock {
        self.parser.lock()
    }

    fn set_moving(&mut self, moving: bool, now_ms: u64) {
        self.moving_since_ms = match (moving, self.moving_since_ms) {
            (false, _) => None,
            (true, Some(since)) => Some(since),
            (true, None) => Some(now_ms),
        };
    }

    fn frame(&mut self, frame: Telemetry, now_ms: u64) -> Option<Event> {
        let stream = match frame {
            Telemetry::Imu(value) => {
                self.imu = Some(Stamped {
                    value,
                    at_ms: now_ms,
                });
                Stream::Imu
            }
            Telemetry::Encoders(value) => {
                self.encoders = Some(Stamped {
                    value,
                    at_ms: now_ms,
                });
                Stream::Encoders
            }
            Telemetry::Battery(value) => {
                self.battery = Some(Stamped {
                    value,
                    at_ms: now_ms,
                });
                Stream::Battery
            }
            Telemetry::Reply(reply) => return Some(self.reply(reply)),
        };
        self.last_telemetry_ms = Some(now_ms);
        let missed = self.parser.stats().missed_of(stream);
        if let Some(info) = self.streams.get_mut(stream.index()) {
            info.arrived(now_ms);
            info.missed = missed;
        }
        Some(Event::Telemetry(frame))
    }

    fn reply(&mut self, reply: Reply) -> Event {
        match self.waiting {
            Some((register, _)) if register.reply_code() == reply.code => {
                self.waiting = None;
                if register == Register::PendingAngle && reply.value == 0 {
                    self.turn = TurnState::Idle;
                }
                Event::Reply(reply)
            }
            _ => Event::StrayReply(reply),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Register;
    use core::convert::Infallible;

    type E = Error<Infallible>;

    #[test]
    fn reply_timeout_follows_the_baud_rate() {
        assert_eq!(Config::DEFAULT.reply_timeout_ms(), 3 + 50);
        let slow = Config {
            baud: 9_600,
            board_latency_ms: 0,
            ..Config::DEFAULT
        };
        assert_eq!(slow.reply_timeout_ms(), 33);
    }

    #[test]
    fn a_second_turn_is_refused_until_the_pending_angle_reads_zero() {
        let mut core = DriverCore::new(Config::DEFAULT);
        assert!(core.turn::<Infallible>(900, 0).is_ok());
        assert_eq!(core.turn::<Infallible>(900, 1), Err(E::TurnInProgress));
        core.setting::<Infallible>(Setting::Read(Register::PendingAngle), 2)
            .unwrap();
        let (event, _) = core.receive(&Reply::new(Register::PendingAngle, 450).encode(), 3);
        assert!(
            event.is_none(),
            "a lone reply waits for the next header or a quiet line"
        );
        assert!(matches!(core.quiet(10), Some(Event::Reply(_))));
        assert!(core.turning(), "still 45.0° to go");
        core.setting::<Infallible>(Setting::Read(Register::PendingAngle), 20)
            .unwrap();
        // After a quiet line the parser takes the next byte as a frame start: out at once.
        let (event, _) = core.receive(&Reply::new(Register::PendingAngle, 0).encode(), 21);
        assert!(matches!(event, Some(Event::Reply(_))));
        assert!(!core.turning());
        assert!(core.turn::<Infallible>(-900, 31).is_ok());
    }

    #[test]
    fn failsafe_stops_once_when_telemetry_goes_silent_while_moving() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.velocity(Velocity::new(0, 100, 0), 0);
        assert_eq!(core.failsafe(100), None);
        assert_eq!(core.failsafe(101), Some(Velocity::STOP.encode()));
        assert_eq!(core.failsafe(500), None);
        assert_eq!(core.failsafe_stops(), 1);
        // Standing still, silence is no reason to stop.
        core.velocity(Velocity::STOP, 600);
        assert_eq!(core.failsafe(10_000), None);
    }

    #[test]
    fn reads_time_out_and_a_second_read_is_busy() {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.setting::<Infallible>(Setting::Read(Register::SpeedKp), 0)
            .unwrap();
        assert_eq!(
            core.setting::<Infallible>(Setting::Read(Register::SpeedKi), 1),
            Err(E::Busy)
        );
        assert_eq!(core.reply_timed_out(53), None);
        assert_eq!(core.reply_timed_out(54), Some(Register::SpeedKp));
        assert_eq!(core.waiting_for(), None);
    }
}
