//! The v1.0.0 board: frames in are written by hand from `docs/protocol-v1.md` (each BCC worked out by
//! hand, the XOR of the bytes before it), never made by the encoder; what comes out is read
//! with `v1::DownlinkParser`.

use super::*;
use crate::sim::Faults;
use crate::v1::{Downlink, DownlinkParser, Parser, Telemetry};

/// The vendor's readback requests, as `docs/protocol-v1.md` quotes them (BCC 48, 4F, 2B).
const READ_SYSTEM: [u8; 14] = [0x7B, 0x33, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x48, 0x7D];
const READ_GEOMETRY: [u8; 14] = [0x7B, 0x34, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x4F, 0x7D];
const READ_PID: [u8; 14] = [0x7B, 0x50, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x2B, 0x7D];
/// 7B ^ 35 = 4E; 7B ^ 36 = 4D.
const READ_BODY: [u8; 14] = [0x7B, 0x35, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x4E, 0x7D];
const READ_MOTORS: [u8; 14] = [0x7B, 0x36, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x4D, 0x7D];
/// The forced stop: ctl 0, everything 0; 7B ^ 25 = 5E.
const FORCED_STOP: [u8; 14] = [0x7B, 0x25, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x5E, 0x7D];
/// vy 0.3 m/s (012C), ctl 2, type 4: 7B^25^02^04^01^2C = 75.
const FORWARD: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0, 0, 0x01, 0x2C, 0, 0, 0, 0, 0x75, 0x7D,
];
/// vx -0.1 m/s (FF9C), vy 0.3 m/s (012C), wz 0.5 rad/s (01F4): 7B^25^02^04^FF^9C^01^2C^01^F4
/// = E3.
const DRIVE: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0xFF, 0x9C, 0x01, 0x2C, 0x01, 0xF4, 0, 0, 0xE3, 0x7D,
];
/// wz 0.5 rad/s only: 7B^25^02^04^01^F4 = AD.
const TURN: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0, 0, 0, 0, 0x01, 0xF4, 0, 0, 0xAD, 0x7D,
];
/// wz -0.5 rad/s (FE0C): 7B^25^02^04^FE^0C, step by step 5E 5C 58 A6 AA.
const TURN_BACK: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0, 0, 0, 0, 0xFE, 0x0C, 0, 0, 0xAA, 0x7D,
];
/// Each motor at 100 (0064), ctl 2, type 4: 7B^26^02^04 = 5B, the four 64s cancel.
const MOTORS_100: [u8; 14] = [
    0x7B, 0x26, 0x02, 0x04, 0, 0x64, 0, 0x64, 0, 0x64, 0, 0x64, 0x5B, 0x7D,
];
/// System 1, 2, 3000 (0BB8), 1000 (03E8), 500 (01F4): 7B^23^01^02^0B^B8^03^E8^01^F4, step by
/// step 58 59 5B 50 E8 EB 03 02 F6.
const WRITE_SYSTEM: [u8; 14] = [
    0x7B, 0x23, 0x01, 0x02, 0x0B, 0xB8, 0x03, 0xE8, 0x01, 0xF4, 0, 0, 0xF6, 0x7D,
];
/// The vendor's geometry 110, 110, 55, 60: 7B^24^6E^6E^37^3C = 54.
const WRITE_GEOMETRY: [u8; 14] = [
    0x7B, 0x24, 0, 0x6E, 0, 0x6E, 0, 0x37, 0, 0x3C, 0, 0, 0x54, 0x7D,
];
/// PID 100, 200, 300, 400, 500 (0064 00C8 012C 0190 01F4): step by step 3B 5F 97 96 BA BB 2B
/// 2A DE.
const WRITE_PID: [u8; 14] = [
    0x7B, 0x40, 0, 0x64, 0, 0xC8, 0x01, 0x2C, 0x01, 0x90, 0x01, 0xF4, 0xDE, 0x7D,
];
/// The reply to `0x33` at power-up, the vendor's 0, 10, 3600 (0E10), 2100 (0834), 165 (00A5):
/// 7B^33^0A^0E^10^08^34^A5, step by step 48 42 4C 5C 54 60 C5.
const FACTORY_SYSTEM_REPLY: [u8; 14] = [
    0x7B, 0x33, 0, 0x0A, 0x0E, 0x10, 0x08, 0x34, 0, 0xA5, 0, 0, 0xC5, 0x7D,
];

/// The board, and what it sent, parsed, with the ms each frame was whole.
struct Bench {
    board: Board,
    parser: DownlinkParser,
    wire: Vec<u8>,
    frames: Vec<(u64, Downlink)>,
}

impl Bench {
    fn new(config: SimConfig) -> Bench {
        Bench {
            board: Board::new(config),
            parser: DownlinkParser::new(),
            wire: Vec::new(),
            frames: Vec::new(),
        }
    }

    /// Runs the board to `until_ms`, reading every ms.
    fn run_to(&mut self, until_ms: u64) {
        let mut buf = [0u8; 64];
        while self.board.now_ms() < until_ms {
            let ms = self.board.now_ms() + 1;
            self.board.advance(ms);
            let n = self.board.transmit(&mut buf);
            self.wire.extend_from_slice(&buf[..n]);
            for frame in self.parser.frames(&buf[..n]) {
                self.frames.push((ms, frame));
            }
        }
    }

    /// Sends `bytes` now, then runs `ms` more.
    fn send(&mut self, bytes: &[u8], ms: u64) {
        self.board.receive(bytes);
        self.run_to(self.board.now_ms() + ms);
    }

    fn telemetry(&self) -> Vec<(u64, Telemetry)> {
        self.frames
            .iter()
            .filter_map(|(ms, f)| match f {
                Downlink::Telemetry(t) => Some((*ms, *t)),
                Downlink::Reply(_) => None,
            })
            .collect()
    }

    fn replies(&self) -> Vec<(u64, Reply)> {
        self.frames
            .iter()
            .filter_map(|(ms, f)| match f {
                Downlink::Reply(r) => Some((*ms, *r)),
                Downlink::Telemetry(_) => None,
            })
            .collect()
    }

    fn last_reply(&self) -> Reply {
        self.replies().last().expect("a reply").1
    }

    /// Every byte sent was part of a good frame.
    fn assert_clean(&self) {
        let stats = self.parser.stats();
        assert_eq!(
            (stats.bad_checksum, stats.bad_end, stats.discarded),
            (0, 0, 0),
            "{stats:?}"
        );
    }
}

#[test]
fn telemetry_streams_at_about_22_hz_and_every_frame_checks() {
    let mut bench = Bench::new(SimConfig::default());
    bench.run_to(10_000);
    let frames = bench.telemetry();
    let hz = frames.len() as f64 / 10.0;
    assert!((20.0..=24.0).contains(&hz), "{hz} Hz");
    assert_eq!(frames.len(), bench.board.telemetry_sent() as usize);
    bench.assert_clean();
    // Every frame is 32 bytes on the wire, nothing else was sent.
    assert_eq!(bench.wire.len(), frames.len() * 32);
    let (_, first) = frames[0];
    assert_eq!(first.velocity, [0, 0, 0]);
    assert_eq!(first.accel, [0, 0, GRAVITY_RAW]);
    assert_eq!(first.quaternion, [1_000, 0, 0, 0]);
    assert_eq!(first.battery_mv, 12_000);
}

#[test]
fn factory_readbacks_are_the_vendor_examples_values() {
    let mut bench = Bench::new(SimConfig::default());
    bench.send(&READ_SYSTEM, 100);
    assert!(
        bench.wire.windows(14).any(|w| w == FACTORY_SYSTEM_REPLY),
        "the reply, byte for byte"
    );
    bench.send(&READ_GEOMETRY, 100);
    assert_eq!(bench.last_reply().request.code(), 0x34);
    assert_eq!(bench.last_reply().geometry(), Some(FACTORY_GEOMETRY));
    bench.send(&READ_PID, 100);
    assert_eq!(bench.last_reply().request.code(), 0x50);
    let pid = bench.last_reply().pid().expect("a PID reply");
    assert_eq!(
        [
            pid.position_kp,
            pid.position_ki,
            pid.position_kd,
            pid.velocity_kp,
            pid.velocity_ki
        ],
        [3_000, 1_050, 0, 3_000, 1_050]
    );
    assert_eq!(bench.replies().len(), 3);
    bench.assert_clean();
}

#[test]
fn readbacks_answer_with_what_was_written_and_writes_get_no_reply() {
    let mut bench = Bench::new(SimConfig::default());
    bench.send(&WRITE_SYSTEM, 200);
    bench.send(&WRITE_PID, 200);
    assert!(bench.replies().is_empty(), "no reply to a write");
    let asked = bench.board.now_ms();
    bench.send(&READ_SYSTEM, 100);
    let (at, reply) = bench.replies()[0];
    assert_eq!(reply.request.code(), 0x33);
    let system = reply.system().expect("a system reply");
    assert_eq!(
        (
            system.motor_directions,
            system.encoder_directions,
            system.pwm_max,
            system.pwm_min,
            system.encoder_ppr
        ),
        (1, 2, 3_000, 1_000, 500)
    );
    // Reply delay (3 ms), then 14 bytes on the wire (1.2 ms), perhaps behind a telemetry
    // frame (2.8 ms).
    assert!(
        (asked + 4..=asked + 9).contains(&at),
        "asked at {asked}, whole at {at}"
    );
    bench.send(&READ_PID, 100);
    let pid = bench.last_reply().pid().expect("a PID reply");
    assert_eq!((pid.position_kp, pid.velocity_ki), (100, 500));
    assert_eq!(bench.board.received_count(0x23), 1);
    assert_eq!(bench.board.received_count(0x40), 1);
    assert_eq!(bench.board.received_count(0x33), 1);
    bench.assert_clean();
}

#[test]
fn body_velocity_and_motor_speed_readbacks() {
    let mut bench = Bench::new(SimConfig::default());
    bench.send(&DRIVE, 10);
    bench.send(&READ_BODY, 50);
    let body = bench.last_reply().body_velocity().expect("a 0x35 reply");
    assert_eq!(
        (
            body.ctl,
            body.kind,
            body.vx_mm_s,
            body.vy_mm_s,
            body.wz_mrad_s
        ),
        (2, 4, -100, 300, 500)
    );
    bench.send(&READ_MOTORS, 50);
    let motors = bench.last_reply().motor_speeds().expect("a 0x36 reply");
    // Lever (110 + 110) / 2 = 110 mm; 0.5 rad/s × 110 mm = 55 mm/s.
    // M1 = 300 - 100 - 55, M2 = 300 + 100 + 55, M3 = 300 + 100 - 55, M4 = 300 - 100 + 55.
    assert_eq!((motors.ctl, motors.kind), (2, 4));
    assert_eq!(motors.speeds, [145, 455, 345, 255]);

    bench.send(&MOTORS_100, 10);
    bench.send(&READ_MOTORS, 50);
    assert_eq!(
        bench.last_reply().motor_speeds().map(|m| m.speeds),
        Some([100; 4])
    );
    bench.send(&READ_BODY, 50);
    let body = bench.last_reply().body_velocity().expect("a 0x35 reply");
    assert_eq!((body.vx_mm_s, body.vy_mm_s, body.wz_mrad_s), (0, 100, 0));
    bench.run_to(bench.board.now_ms() + 100);
    assert_eq!(bench.telemetry().last().unwrap().1.velocity, [0, 100, 0]);
    bench.assert_clean();
}

#[test]
fn the_forced_stop_zeroes_the_velocity() {
    let mut bench = Bench::new(SimConfig::default());
    bench.send(&FORWARD, 1_000);
    assert_eq!(bench.telemetry().last().unwrap().1.velocity, [0, 300, 0]);
    bench.send(&FORCED_STOP, 200);
    assert!(bench.board.velocity().is_forced_stop());
    assert_eq!(bench.board.measured_velocity(), [0, 0, 0]);
    assert_eq!(bench.board.forced_stops(), 1);
    assert_eq!(bench.telemetry().last().unwrap().1.velocity, [0, 0, 0]);
    bench.send(&READ_BODY, 50);
    let body = bench.last_reply().body_velocity().expect("a 0x35 reply");
    assert!(body.is_forced_stop(), "{body:?}");
    bench.assert_clean();
}

#[test]
fn the_last_velocity_is_kept_with_no_watchdog() {
    let mut bench = Bench::new(SimConfig::default());
    bench.send(&DRIVE, 10_500);
    assert_eq!(bench.board.total_commands(), 1);
    assert_eq!(
        (
            bench.board.velocity().vx_mm_s,
            bench.board.velocity().vy_mm_s,
            bench.board.velocity().wz_mrad_s
        ),
        (-100, 300, 500)
    );
    let late: Vec<_> = bench
        .telemetry()
        .into_iter()
        .filter(|(ms, _)| *ms > 500)
        .collect();
    assert!(late.len() > 200, "{} frames", late.len());
    assert!(late.iter().all(|(_, t)| t.velocity == [-100, 300, 500]));
    assert_eq!(bench.board.forced_stops(), 0);
}

/// Sends `frame` every `every_ms` for `for_ms`; the frames due meanwhile and those dropped.
fn command_for(bench: &mut Bench, frame: &[u8], every_ms: u64, for_ms: u64) -> (u32, u32) {
    let (sent, dropped) = (
        bench.board.telemetry_sent(),
        bench.board.telemetry_dropped(),
    );
    let end = bench.board.now_ms() + for_ms;
    while bench.board.now_ms() < end {
        bench.send(frame, every_ms);
    }
    let dropped = bench.board.telemetry_dropped() - dropped;
    (bench.board.telemetry_sent() - sent + dropped, dropped)
}

#[test]
fn telemetry_drops_at_about_the_rate_while_commands_arrive_never_when_idle() {
    // (Seeds 2 and 3 are one stream: the generator starts from `seed | 1`.)
    for seed in [1, 2, 4, 7] {
        let mut bench = Bench::new(SimConfig {
            seed,
            ..SimConfig::default()
        });
        bench.run_to(30_000);
        assert_eq!(bench.board.telemetry_dropped(), 0, "idle, seed {seed}");
        // 20 commands/s for 100 s: about 90 % of the frames follow a command within their
        // period, 6 % of those are dropped: 5.4 %.
        let (due, dropped) = command_for(&mut bench, &FORWARD, 50, 100_000);
        let rate = f64::from(dropped) / f64::from(due);
        assert!(
            (0.035..=0.075).contains(&rate),
            "seed {seed}: {dropped} of {due}"
        );
        // Idle again: none.
        bench.run_to(bench.board.now_ms() + 30_000);
        assert_eq!(
            bench.board.telemetry_dropped(),
            dropped,
            "idle, seed {seed}"
        );
        assert_eq!(
            bench.telemetry().len(),
            bench.board.telemetry_sent() as usize
        );
        bench.assert_clean();
    }
}

#[test]
fn the_drop_rate_is_configurable_and_zero_disables_it() {
    let mut bench = Bench::new(SimConfig {
        busy_drop_per_million: 0,
        ..SimConfig::default()
    });
    let (due, dropped) = command_for(&mut bench, &FORWARD, 50, 60_000);
    assert!(due > 1_300);
    assert_eq!(dropped, 0);
    // Always: only the frames with no command in the period before them are left (a command
    // every 50 ms, a period of 45: about one in ten).
    let mut bench = Bench::new(SimConfig {
        busy_drop_per_million: 1_000_000,
        ..SimConfig::default()
    });
    let (due, dropped) = command_for(&mut bench, &FORWARD, 50, 60_000);
    let kept = f64::from(due - dropped) / f64::from(due);
    assert!((0.07..=0.13).contains(&kept), "{kept}");
}

/// The yaw of a z-rotation quaternion (w, 0, 0, z) × 1000.
fn yaw_of(q: [i16; 4]) -> f64 {
    2.0 * f64::from(q[3]).atan2(f64::from(q[0]))
}

/// `a - b` in (-π, π].
fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}

#[test]
fn yaw_from_the_quaternion_follows_wz() {
    for (frame, wz) in [(TURN, 0.5), (TURN_BACK, -0.5)] {
        let mut bench = Bench::new(SimConfig::default());
        bench.run_to(1_000);
        let start = bench.board.now_ms();
        bench.send(&frame, 15_000);
        for (ms, t) in bench.telemetry() {
            let q = t.quaternion;
            let norm = q.iter().map(|v| f64::from(*v).powi(2)).sum::<f64>().sqrt();
            assert!((norm - 1_000.0).abs() < 2.0, "{q:?}");
            assert_eq!((q[1], q[2]), (0, 0), "about z only");
            // The frame was made when due: up to 4 ms before it was whole here.
            let turned_s = ms.saturating_sub(start) as f64 / 1_000.0;
            let expected = wz * turned_s;
            let err = angle_diff(yaw_of(q), expected).abs();
            assert!(
                err < 0.01,
                "at {ms} ms: {} rad, {expected} expected",
                yaw_of(q)
            );
            if ms > start + 5 {
                assert_eq!(t.gyro, [0, 0, (wz * 1_000.0) as i16]);
            }
        }
        // 7.5 rad turned: wrapped once past ±π.
        let yaw = bench.board.yaw_urad() as f64 / 1e6;
        assert!(angle_diff(yaw, wz * 15.0).abs() < 0.001, "{yaw}");
        assert!(yaw.abs() <= std::f64::consts::PI);
    }
}

#[test]
fn a_settings_frame_is_stored_and_pauses_telemetry_for_100_ms() {
    let mut bench = Bench::new(SimConfig::default());
    bench.run_to(1_000);
    bench.send(&WRITE_GEOMETRY, 1_000);
    assert_eq!(bench.board.geometry(), FACTORY_GEOMETRY);
    bench.send(&WRITE_SYSTEM, 1_000);
    assert_eq!(bench.board.system().pwm_max, 3_000);
    let times: Vec<u64> = bench.telemetry().iter().map(|(ms, _)| *ms).collect();
    for write in [1_000u64, 2_000] {
        assert!(
            !times.iter().any(|ms| (write + 1..write + 100).contains(ms)),
            "quiet after the write at {write}: {times:?}"
        );
        assert!(
            times
                .iter()
                .any(|ms| (write + 100..write + 150).contains(ms))
        );
    }
    assert!(bench.replies().is_empty());
    bench.assert_clean();
}

#[test]
fn damaged_frames_are_counted_and_not_obeyed() {
    let mut bench = Bench::new(SimConfig::default());
    let mut bad = FORWARD;
    bad[12] ^= 0x01;
    bench.send(&bad, 100);
    // A readback request with a payload: start, end and BCC right (7B^33^01 = 49), refused.
    bench.send(
        &[0x7B, 0x33, 0x01, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x49, 0x7D],
        100,
    );
    assert_eq!(bench.board.bad_frames(), 2);
    assert_eq!(bench.board.total_commands(), 0);
    assert_eq!(bench.board.measured_velocity(), [0, 0, 0]);
    assert!(bench.replies().is_empty());
    // Split anywhere, with noise before: taken.
    bench.board.receive(&[0x00, 0x7D, 0x7B]);
    bench.board.receive(&FORWARD[..5]);
    bench.send(&FORWARD[5..], 100);
    assert_eq!(bench.board.total_commands(), 1);
    assert_eq!(bench.board.measured_velocity(), [0, 300, 0]);
}

#[test]
fn the_log_keeps_the_last_commands_in_order() {
    let mut bench = Bench::new(SimConfig::default());
    for _ in 0..40 {
        bench.board.receive(&FORWARD);
    }
    bench.board.receive(&FORCED_STOP);
    bench.board.receive(&READ_SYSTEM);
    let log: Vec<&Command> = bench.board.received().collect();
    assert_eq!(log.len(), RECEIVED_LOG);
    assert_eq!(log[RECEIVED_LOG - 2].code(), 0x25);
    assert_eq!(*log[RECEIVED_LOG - 1], Command::Readback(Readback::System));
    assert_eq!(bench.board.received_count(0x25), 41);
    assert_eq!(bench.board.received_count(0x7B), 0);
    assert_eq!(bench.board.total_commands(), 42);
}

#[test]
fn the_battery_drains_slowly() {
    let mut bench = Bench::new(SimConfig::default());
    bench.run_to(60_000);
    assert_eq!(bench.board.battery_mv(), 12_000 - 3);
    bench.send(&FORWARD, 60_000);
    assert_eq!(bench.board.battery_mv(), 12_000 - 3 - 30);
    // The next frame (the last drain was at 120 000 ms) says so.
    bench.run_to(120_050);
    assert_eq!(
        bench.telemetry().last().unwrap().1.battery_mv,
        bench.board.battery_mv()
    );
}

#[test]
fn faults_damage_the_line_and_random_input_never_panics() {
    let mut bench = Bench::new(SimConfig::default());
    bench.board.set_faults(Faults {
        corrupt_per_million: 2_000,
        drop_per_million: 2_000,
        insert_per_million: 2_000,
        ..Faults::default()
    });
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    for _ in 0..20_000 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let bytes = x.to_le_bytes();
        bench.board.receive(&bytes[..(x % 9) as usize]);
        // Now and then a real frame among the noise.
        if x & 15 == 0 {
            bench.board.receive(&READ_SYSTEM);
        }
        bench.run_to(bench.board.now_ms() + (x >> 60));
    }
    let stats = bench.parser.stats();
    assert!(stats.bad_checksum + stats.bad_end > 0, "{stats:?}");
    assert!(stats.frames > 1_000, "{stats:?}");
    // The replies that came through are right.
    assert!(
        bench
            .replies()
            .iter()
            .filter(|(_, r)| r.request == Readback::System)
            .all(|(_, r)| r.system() == Some(FACTORY_SYSTEM))
    );
}

/// Stopped: no telemetry at all; replies still come.
#[test]
fn stopped_telemetry_is_silence_but_replies_come() {
    let mut bench = Bench::new(SimConfig::default());
    bench.board.set_faults(Faults {
        telemetry_stopped: true,
        ..Faults::default()
    });
    bench.send(&READ_SYSTEM, 2_000);
    assert!(bench.telemetry().is_empty());
    assert_eq!(bench.replies().len(), 1);
    assert_eq!(bench.wire.len(), 14);
}

/// The same in-memory UART as the 2020 board's.
#[cfg(feature = "driver")]
#[test]
fn the_sim_uart_takes_the_v1_board() {
    use crate::sim::SimUart;
    use embedded_io::{Read, ReadReady, Write};
    let time = core::cell::Cell::new(0u64);
    let mut uart = SimUart::new(Board::new(SimConfig::default()), &time).with_bursts(4);
    uart.write_all(&READ_PID).unwrap();
    let mut parser = DownlinkParser::new();
    let mut reply = None;
    let mut buf = [0u8; 64];
    for _ in 0..200 {
        time.set(time.get() + 1);
        if uart.read_ready().unwrap() {
            let n = uart.read(&mut buf).unwrap();
            for frame in parser.frames(&buf[..n]) {
                if let Downlink::Reply(r) = frame {
                    reply = Some(r);
                }
            }
        }
    }
    assert_eq!(reply.and_then(|r| r.pid()), Some(FACTORY_PID));
    assert_eq!(uart.board().total_commands(), 1);
    uart.board_mut().set_faults(Faults::default());
}

/// vy 0.25 m/s (00FA), ctl 2, type 4: 7B^25^02^04^FA = A2.
const FORWARD_250: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0, 0, 0x00, 0xFA, 0, 0, 0, 0, 0xA2, 0x7D,
];
/// vx 0.25 m/s (00FA), to the right: 7B^25^02^04^FA = A2.
const RIGHT_250: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0x00, 0xFA, 0, 0, 0, 0, 0, 0, 0xA2, 0x7D,
];

#[test]
fn forward_for_4_s_at_250_mm_s_is_1_m_of_true_pose() {
    let mut bench = Bench::new(SimConfig::default());
    bench.send(&FORWARD_250, 4_000);
    bench.send(&FORCED_STOP, 1_000);
    let (x, y, yaw) = bench.board.pose();
    // 0.25 m/s for 4 000 ms, each ms 250 µm.
    assert!(
        (x - 1.0).abs() < 1e-9 && y.abs() < 1e-12 && yaw == 0.0,
        "{x} {y} {yaw}"
    );
}

#[test]
fn the_true_pose_is_in_rep_103_axes() {
    // vx is to the right: REP-103's -y.
    let mut bench = Bench::new(SimConfig::default());
    bench.send(&RIGHT_250, 4_000);
    bench.send(&FORCED_STOP, 10);
    let (x, y, _) = bench.board.pose();
    assert!(x.abs() < 1e-12 && (y + 1.0).abs() < 1e-9, "{x} {y}");
    // wz 0.5 rad/s for 2 s, counter-clockwise; the true yaw is the board's own heading.
    let mut turning = Bench::new(SimConfig::default());
    turning.send(&TURN, 2_000);
    turning.send(&FORCED_STOP, 10);
    let (_, _, yaw) = turning.board.pose();
    assert!((yaw - 1.0).abs() < 1e-9, "{yaw}");
    assert!((yaw - turning.board.yaw_urad() as f64 / 1e6).abs() < 1e-9);
}

#[test]
fn driving_while_turning_traces_the_circle() {
    // 0.3 m/s forward and 0.5 rad/s (DRIVE has vx -0.1 m/s too: 0.1 m/s to the left).
    // For 4π s: once round a circle, back at the start.
    let mut bench = Bench::new(SimConfig::default());
    let full_turn_ms = (4.0 * std::f64::consts::PI * 1_000.0).round() as u64;
    bench.send(&DRIVE, full_turn_ms);
    bench.send(&FORCED_STOP, 10);
    let (x, y, yaw) = bench.board.pose();
    // 12 566 ms against 12 566.37: a shortfall of 0.37 ms, 0.2 mrad, at most 0.12 mm off.
    assert!(x.hypot(y) < 2e-4, "({x}, {y})");
    assert!(yaw.abs() < 3e-4, "{yaw}");
}
