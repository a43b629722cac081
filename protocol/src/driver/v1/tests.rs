//! The v1.0.0 core alone: the forced stop, readbacks, the settings gap, the quiet line.

use super::*;
use crate::v1::{Geometry, Pid, SystemSettings};

/// The forced stop, from PROTOCOL-V1.md: `0x25`, ten `00`, BCC `7B ^ 25 = 5E`.
const FORCED_STOP: [u8; 14] = [0x7B, 0x25, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x5E, 0x7D];
/// The readback request of the geometry: `7B 34`, ten `00`, BCC `7B ^ 34 = 4F`, `7D`.
const READ_GEOMETRY: [u8; 14] = [0x7B, 0x34, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x4F, 0x7D];
/// The vendor's readback request of the system settings.
const READ_SYSTEM: [u8; 14] = [0x7B, 0x33, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x48, 0x7D];

/// Everything the core has to send now, each frame taken whole.
fn out(core: &mut DriverCore, now: u64) -> Vec<Vec<u8>> {
    let mut frames = Vec::new();
    while let Some(bytes) = core.transmit(now) {
        let bytes = bytes.to_vec();
        core.transmitted(bytes.len(), now);
        frames.push(bytes);
    }
    frames
}

fn hear(core: &mut DriverCore, bytes: &[u8], now: u64) -> Vec<Event> {
    let mut events = Vec::new();
    let mut rest = bytes;
    loop {
        let (event, left) = core.receive(rest, now);
        events.extend(event);
        if left.is_empty() {
            break;
        }
        rest = left;
    }
    events
}

fn telemetry() -> [u8; 32] {
    Telemetry {
        battery_mv: 12_000,
        quaternion: [1000, 0, 0, 0],
        ..Telemetry::default()
    }
    .encode()
}

/// Ticks the core a millisecond at a time after `from` (until 2 s), a geometry readback asked
/// for again whenever none runs if `reading`: when the forced stop went, if it did.
fn forced_stop_after(core: &mut DriverCore, from: u64, reading: bool) -> Option<u64> {
    for now in from + 1..2_000 {
        if reading && !core.busy() {
            core.start(Request::Read(Readback::Geometry)).unwrap();
        }
        core.tick(now);
        if out(core, now).contains(&FORCED_STOP.to_vec()) {
            return Some(now);
        }
    }
    None
}

fn driving(now: u64) -> DriverCore {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.velocity(BodyVelocity::new(0, 300, 0), now).unwrap();
    assert_eq!(out(&mut core, now).len(), 1);
    core
}

#[test]
fn the_failsafe_sends_the_forced_stop_and_is_at_least_300_ms() {
    assert_eq!(DriverCore::new(Config::DEFAULT).config().failsafe_ms, 300);
    assert_eq!(DriverCore::new(Config::HOST).config().failsafe_ms, 300);
    let long = Config {
        failsafe_ms: 500,
        ..Config::DEFAULT
    };
    assert_eq!(DriverCore::new(long).config().failsafe_ms, 500);

    let mut core = driving(0);
    hear(&mut core, &telemetry(), 10);
    core.tick(310);
    assert!(
        out(&mut core, 310).is_empty(),
        "300 ms of silence is allowed"
    );
    core.tick(311);
    assert_eq!(out(&mut core, 311), vec![FORCED_STOP.to_vec()]);
    assert_eq!(core.failsafe_stops(), 1);
    assert!(!core.moving());
    core.tick(2_000);
    assert!(out(&mut core, 2_000).is_empty(), "sent once");
}

#[test]
fn readbacks_a_silent_board_leaves_unanswered_never_hold_the_failsafe_off() {
    // Heard at 10, then silent; a readback asked for again as soon as one gives up (another
    // thread's loop): the forced stop still comes 300 ms after the last frame heard.
    let mut core = driving(0);
    hear(&mut core, &telemetry(), 10);
    let stopped = forced_stop_after(&mut core, 10, true);
    assert_eq!(
        stopped,
        Some(311),
        "the forced stop 300 ms after the board was last heard"
    );
    assert_eq!(core.failsafe_stops(), 1);
}

#[test]
fn a_frame_cut_short_after_a_readback_never_holds_the_failsafe_off() {
    // Heard whole at 10; a readback goes at 20; the link dies in the middle of the next
    // telemetry frame (its first 12 bytes heard at 25). The v1.0.0 board pauses for no
    // readback, so those bytes are no answer: the forced stop 300 ms after the last frame.
    let mut core = driving(0);
    hear(&mut core, &telemetry(), 10);
    core.start(Request::Read(Readback::Geometry)).unwrap();
    assert_eq!(out(&mut core, 20), vec![READ_GEOMETRY.to_vec()]);
    hear(&mut core, &telemetry()[..12], 25);
    let stopped = forced_stop_after(&mut core, 25, false);
    assert_eq!(
        stopped,
        Some(311),
        "the forced stop 300 ms after the last frame"
    );
}

#[test]
fn a_readback_unanswered_ends_the_pause_an_answered_one_allowed() {
    // Moving, a readback answered at 20 (it allows the board a telemetry pause, A13), then
    // the board silent: the next readback goes unanswered, and the forced stop comes 300 ms
    // after the reply, not settings_pause_ms after the readback.
    let mut core = driving(0);
    hear(&mut core, &telemetry(), 10);
    core.start(Request::Read(Readback::Geometry)).unwrap();
    assert_eq!(out(&mut core, 10).len(), 1);
    let reply = Reply {
        request: Readback::Geometry,
        payload: [0; 10],
    }
    .encode();
    assert!(hear(&mut core, &reply, 20).is_empty());
    assert!(matches!(core.take_outcome(), Some(Ok(Outcome::Reply(_)))));
    core.start(Request::Read(Readback::Geometry)).unwrap();
    let mut stopped = None;
    let mut now = 20;
    while now < 2_000 && stopped.is_none() {
        core.tick(now);
        if out(&mut core, now).contains(&FORCED_STOP.to_vec()) {
            stopped = Some(now);
        }
        now += 1;
    }
    assert_eq!(stopped, Some(321), "the forced stop 300 ms after the reply");
}

#[test]
fn telemetry_dropped_five_in_a_row_never_trips_the_failsafe() {
    // Frames every 45 ms; five dropped in a row leave a 270 ms gap.
    let mut core = driving(0);
    let mut t = 0;
    for round in 0..200u64 {
        let drop = round % 20 >= 15; // 5 of every 20 missing, in a row
        t += 45;
        if !drop {
            hear(&mut core, &telemetry(), t);
        }
        core.tick(t);
        core.velocity(BodyVelocity::new(0, 300, 0), t).unwrap();
        let sent = out(&mut core, t);
        assert!(!sent.contains(&FORCED_STOP.to_vec()), "stopped at {t} ms");
    }
    assert_eq!(core.failsafe_stops(), 0);
}

#[test]
fn stop_finishes_a_cut_frame_then_sends_the_forced_stop() {
    let velocity = Command::BodyVelocity(BodyVelocity::new(0, 300, 0)).encode();
    for cut in 1..COMMAND_LEN {
        let mut core = DriverCore::new(Config::DEFAULT);
        core.velocity(BodyVelocity::new(0, 300, 0), 0).unwrap();
        let first = core.transmit(0).unwrap().to_vec();
        core.transmitted(cut, 0);
        core.stop();
        let mut wire = first.get(..cut).unwrap().to_vec();
        for frame in out(&mut core, 1) {
            wire.extend(frame);
        }
        let mut expected = velocity.to_vec();
        expected.extend(FORCED_STOP);
        assert_eq!(wire, expected, "cut after {cut} bytes");
    }
}

#[test]
fn a_readback_is_sent_as_the_vendor_sends_it_and_matched_by_code() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::Read(Readback::System)).unwrap();
    assert_eq!(out(&mut core, 0), vec![READ_SYSTEM.to_vec()]);
    // Another code's reply is not the answer: it is an event.
    let pid = Reply {
        request: Readback::Pid,
        payload: [0; 10],
    };
    assert_eq!(hear(&mut core, &pid.encode(), 5), vec![Event::Reply(pid)]);
    assert!(core.busy());
    // 0x33 with 0, 10, 3600 (0E10), 2100 (0834), 165 (00A5): BCC by hand.
    let mut reply = [
        0x7B, 0x33, 0x00, 0x0A, 0x0E, 0x10, 0x08, 0x34, 0x00, 0xA5, 0, 0, 0, 0x7D,
    ];
    reply[12] = reply[..12].iter().fold(0, |a, b| a ^ b);
    assert!(hear(&mut core, &reply, 6).is_empty());
    let Some(Ok(Outcome::Reply(r))) = core.settle(6, 10) else {
        panic!("no outcome");
    };
    assert_eq!(
        r.system(),
        Some(SystemSettings {
            motor_directions: 0,
            encoder_directions: 10,
            pwm_max: 3600,
            pwm_min: 2100,
            encoder_ppr: 165,
        })
    );
}

#[test]
fn an_unanswered_readback_is_sent_read_tries_times_then_fails() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::Read(Readback::Geometry)).unwrap();
    let mut sent = 0;
    let mut t = 0;
    while core.busy() && t < 10_000 {
        sent += out(&mut core, t).len();
        core.tick(t);
        t += 1;
    }
    assert_eq!(sent, usize::from(Config::DEFAULT.read_tries));
    assert_eq!(
        core.take_outcome(),
        Some(Err(CoreError::NoReadback(Readback::Geometry)))
    );
}

#[test]
fn settings_keep_their_gap_and_are_confirmed_by_a_readback() {
    let geometry = Geometry {
        wheel_spacing_mm: 110,
        axle_spacing_mm: 110,
        gear_ratio: 55,
        wheel_diameter_mm: 60,
    };
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::Write(Settings::Geometry(geometry)))
        .unwrap();
    // 0x24: 006E 006E 0037 003C 0000.
    let mut frame = [
        0x7B, 0x24, 0x00, 0x6E, 0x00, 0x6E, 0x00, 0x37, 0x00, 0x3C, 0, 0, 0, 0x7D,
    ];
    frame[12] = frame[..12].iter().fold(0, |a, b| a ^ b);
    assert_eq!(out(&mut core, 1_000), vec![frame.to_vec()]);
    // The readback waits for the gap.
    assert!(out(&mut core, 1_099).is_empty());
    assert_eq!(core.wait_ms(1_099), Some(1));
    let read = out(&mut core, 1_100);
    assert_eq!(read.len(), 1);
    assert_eq!(read[0][1], 0x34);
    let mut reply = frame;
    reply[1] = 0x34;
    reply[12] = reply[..12].iter().fold(0, |a, b| a ^ b);
    hear(&mut core, &reply, 1_105);
    assert_eq!(core.take_outcome(), Some(Ok(Outcome::Done)));

    // A second write: its frame goes (100 ms have passed since the first), its readback
    // waits 100 ms; a readback that differs is said.
    let pid = Pid {
        position_kp: 3000,
        ..Pid::default()
    };
    core.start(Request::Write(Settings::Pid(pid))).unwrap();
    assert_eq!(out(&mut core, 1_110).len(), 1);
    assert!(out(&mut core, 1_209).is_empty());
    let read = out(&mut core, 1_210);
    assert_eq!(read[0][1], 0x50);
    let other = Reply {
        request: Readback::Pid,
        payload: [0; 10],
    };
    hear(&mut core, &other.encode(), 1_215);
    assert_eq!(
        core.take_outcome(),
        Some(Err(CoreError::ReadbackDiffers(Readback::Pid)))
    );
}

#[test]
fn motion_is_never_held_back_by_the_settings_gap() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::Write(Settings::Pid(Pid::default())))
        .unwrap();
    assert_eq!(out(&mut core, 0).len(), 1);
    core.stop();
    assert_eq!(out(&mut core, 1), vec![FORCED_STOP.to_vec()]);
}

#[test]
fn the_core_tells_its_parser_of_a_quiet_line() {
    // A's first 4 bytes, then, 45 ms later, B from its byte 4: joined, the BCC matches
    // (v1::tests::a_frame_never_spans_a_quiet_line has the bytes written out).
    let a = Telemetry {
        velocity: [1, 0, 0],
        battery_mv: 12_000,
        ..Telemetry::default()
    }
    .encode();
    let b = Telemetry {
        velocity: [256, 0, 0],
        battery_mv: 11_900,
        ..Telemetry::default()
    }
    .encode();
    let mut core = DriverCore::new(Config::DEFAULT);
    assert!(hear(&mut core, &a[..4], 0).is_empty());
    assert_eq!(
        core.next_deadline(),
        Some(2),
        "the quiet line is a deadline"
    );
    core.tick(2);
    assert!(
        hear(&mut core, &b[4..], 45).is_empty(),
        "nothing made of the two"
    );
    assert_eq!(core.parser_stats().frames, 0);
    // Back to back, the same bytes make a frame: the quiet line is what told them apart.
    let mut blind = DriverCore::new(Config::DEFAULT);
    hear(&mut blind, &a[..4], 0);
    assert_eq!(hear(&mut blind, &b[4..], 1).len(), 1);
}
