//! The 2020 core alone: frames out, replies matched, ghosts, the failsafe and the turn guard.

use super::*;
use crate::telemetry::Reply;

/// Everything the core has to send now, each frame taken whole by the UART.
fn out(core: &mut DriverCore, now: u64) -> Option<Vec<u8>> {
    let bytes = core.transmit(now)?.to_vec();
    core.transmitted(bytes.len(), now);
    Some(bytes)
}

fn reply(core: &mut DriverCore, register: Register, value: u32, now: u64) {
    let _ = core.receive(&Reply::new(register, value).encode(), now);
    while core.tick(now.saturating_add(5)).is_some() {}
}

/// An IMU frame with count `seq`, heard whole at `at`, then the line judged.
fn imu(core: &mut DriverCore, seq: u8, at: u64) {
    let frame = crate::Imu {
        accel: [0; 3],
        gyro: [0; 3],
        seq,
    }
    .encode();
    let mut rest = &frame[..];
    while !rest.is_empty() {
        rest = core.receive(rest, at).1;
    }
    let _ = core.tick(at);
}

/// The chassis told to move at `now`, and the frame sent.
fn drive(core: &mut DriverCore, now: u64) {
    core.velocity(Velocity::new(0, 100, 0), now).unwrap();
    assert!(out(core, now).is_some());
}

/// The failsafe's stop came, at most `failsafe_ms` (and 2 ms of judging) after the board was
/// last heard.
fn assert_stopped_in_time(stopped: Option<u64>, heard: u64) {
    let stopped = stopped.expect("the failsafe never stopped the chassis");
    assert!(
        stopped <= heard + u64::from(Config::DEFAULT.failsafe_ms) + 2,
        "stopped {} ms after the board was last heard",
        stopped - heard
    );
}

/// A core that has read the pending angle (0): turns may be sent.
fn idle_core() -> DriverCore {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::Read(Register::PendingAngle)).unwrap();
    assert!(out(&mut core, 0).is_some());
    reply(&mut core, Register::PendingAngle, 0, 1);
    assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(0))));
    assert_eq!(core.turn_state(), TurnState::Idle);
    core
}

const STOP: [u8; 10] = [0xFF, 0xFE, 0x01, 0, 0, 0, 0, 0, 0, 0];

#[test]
fn reply_timeout_follows_the_baud_rate() {
    assert_eq!(Config::DEFAULT.reply_timeout_ms(), 3 + 50 + 2);
    assert_eq!(
        Config::HOST.reply_timeout_ms(),
        133,
        "as the driver docs say"
    );
    assert_eq!(Config::HOST.failsafe_ms, 200, "as the driver docs say");
    let slow = Config {
        baud: 9_600,
        board_latency_ms: 0,
        idle_ms: 0,
        ..Config::DEFAULT
    };
    assert_eq!(slow.reply_timeout_ms(), 33);
}

#[test]
fn a_new_core_does_not_turn_before_it_knows_no_turn_is_pending() {
    let mut core = DriverCore::new(Config::DEFAULT);
    assert_eq!(core.turn_state(), TurnState::Unknown);
    assert_eq!(
        core.turn(Turn::by_deci_degrees(900), 0),
        Err(CoreError::TurnStateUnknown)
    );
    // The board still has 45.0° to go from an earlier program: a turn is outstanding.
    core.start(Request::Read(Register::PendingAngle)).unwrap();
    assert!(out(&mut core, 0).is_some());
    reply(&mut core, Register::PendingAngle, 450, 1);
    assert_eq!(core.turn_state(), TurnState::Turning { deci_degrees: 450 });
    assert_eq!(
        core.turn(Turn::by_deci_degrees(900), 10),
        Err(CoreError::TurnInProgress)
    );
}

#[test]
fn a_second_turn_is_refused_until_the_pending_angle_reads_near_zero() {
    let mut core = idle_core();
    assert!(core.turn(Turn::by_deci_degrees(900), 10).is_ok());
    assert!(out(&mut core, 10).is_some());
    assert_eq!(
        core.turn(Turn::by_deci_degrees(900), 11),
        Err(CoreError::TurnInProgress)
    );
    core.start(Request::Read(Register::PendingAngle)).unwrap();
    assert!(out(&mut core, 12).is_some());
    reply(&mut core, Register::PendingAngle, 450, 13);
    assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(450))));
    assert!(core.turning(), "still 45.0° to go");
    core.start(Request::Read(Register::PendingAngle)).unwrap();
    assert!(out(&mut core, 30).is_some());
    // A board that leaves a fraction of a degree still ends the turn.
    reply(&mut core, Register::PendingAngle, (-3i32) as u32, 31);
    assert!(!core.turning());
    assert!(core.turn(Turn::by_deci_degrees(-900), 41).is_ok());
}

#[test]
fn a_frame_goes_out_whole_before_any_other() {
    let mut core = idle_core();
    core.velocity(Velocity::new(0, 300, 0), 10).unwrap();
    let first = core.transmit(10).unwrap().to_vec();
    assert_eq!(first, [0xFF, 0xFE, 0x01, 0, 0, 0x01, 0x2C, 0, 0, 0]);
    core.transmitted(3, 10);
    // Nothing new is accepted while the rest waits; a stop waits behind it.
    assert_eq!(
        core.velocity(Velocity::new(0, 100, 0), 11),
        Err(CoreError::FramePending)
    );
    assert_eq!(
        core.turn(Turn::by_deci_degrees(900), 11),
        Err(CoreError::FramePending)
    );
    core.stop();
    assert_eq!(core.transmit(12), Some(&first[3..]));
    core.transmitted(7, 12);
    assert_eq!(out(&mut core, 12).as_deref(), Some(&STOP[..]));
    assert_eq!(core.transmit(13), None);
}

#[test]
fn reads_time_out_and_a_second_request_is_busy() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::Read(Register::SpeedKp)).unwrap();
    assert_eq!(
        core.start(Request::Read(Register::SpeedKi)),
        Err(CoreError::Busy)
    );
    assert!(out(&mut core, 0).is_some());
    assert_eq!(core.waiting_for(), Some(Register::SpeedKp));
    let _ = core.tick(55);
    assert_eq!(core.take_outcome(), None);
    let _ = core.tick(56);
    assert_eq!(
        core.take_outcome(),
        Some(Err(CoreError::Timeout(Register::SpeedKp)))
    );
    assert_eq!(core.waiting_for(), None);
    assert!(core.start(Request::Read(Register::SpeedKi)).is_ok());
}

#[test]
fn the_reply_timeout_starts_when_the_last_byte_has_left() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::Read(Register::SpeedKp)).unwrap();
    assert!(core.transmit(0).is_some());
    core.transmitted(4, 0);
    // The rest goes out 500 ms later (a future dropped, the next call finishing it).
    let _ = core.tick(500);
    assert_eq!(core.take_outcome(), None, "not sent yet: no timeout");
    assert!(core.transmit(500).is_some());
    core.transmitted(6, 500);
    let _ = core.tick(555);
    assert_eq!(core.take_outcome(), None);
    let _ = core.tick(556);
    assert_eq!(
        core.take_outcome(),
        Some(Err(CoreError::Timeout(Register::SpeedKp)))
    );
}

#[test]
fn abort_leaves_the_core_usable() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::ReadSettings).unwrap();
    assert!(out(&mut core, 0).is_some());
    core.abort();
    assert!(!core.busy());
    assert_eq!(core.take_outcome(), None);
    // The late reply is a stray one.
    let _ = core.receive(&Reply::new(Register::MaxSpeed, 1).encode(), 1);
    assert!(matches!(core.tick(10), Some(Event::StrayReply(_))));
    assert!(core.start(Request::Read(Register::MaxSpeed)).is_ok());
}

#[test]
fn a_late_reply_never_answers_a_later_read_of_its_register() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::Read(Register::PendingAngle)).unwrap();
    assert!(out(&mut core, 0).is_some());
    let _ = core.tick(56);
    assert_eq!(
        core.take_outcome(),
        Some(Err(CoreError::Timeout(Register::PendingAngle)))
    );
    // The next read of the same register waits for the late reply (or its time to pass).
    core.start(Request::Read(Register::PendingAngle)).unwrap();
    assert_eq!(core.transmit(57), None);
    reply(&mut core, Register::PendingAngle, 0, 60);
    assert_eq!(core.take_outcome(), None, "the late 0 answers nothing");
    assert_eq!(core.turn_state(), TurnState::Unknown);
    assert!(out(&mut core, 66).is_some(), "now the read goes");
    reply(&mut core, Register::PendingAngle, 300, 70);
    assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(300))));
    // The board took 60 ms: later reads wait that long.
    assert!(core.reply_timeout_ms() >= 60, "{}", core.reply_timeout_ms());
}

#[test]
fn a_late_reply_of_another_register_is_passed_over() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::Read(Register::SpeedKp)).unwrap();
    assert!(out(&mut core, 0).is_some());
    let _ = core.tick(56);
    assert!(core.take_outcome().is_some());
    core.start(Request::Read(Register::SpeedKi)).unwrap();
    assert!(out(&mut core, 57).is_some());
    reply(&mut core, Register::SpeedKp, 5, 60);
    assert_eq!(core.take_outcome(), None, "not a wrong reply: a late one");
    reply(&mut core, Register::SpeedKi, 7, 70);
    assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(7))));
}

#[test]
fn a_verified_read_needs_two_agreeing_replies_that_fit() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::ReadVerified(Register::MaxSpeed))
        .unwrap();
    let mut now = 0;
    // A damaged reply (high half set: no u16), then two good ones.
    for value in [0x0001_03E8, 1_000, 1_000] {
        assert!(out(&mut core, now).is_some(), "a read goes out");
        reply(&mut core, Register::MaxSpeed, value, now.saturating_add(1));
        now = now.saturating_add(10);
    }
    assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(1_000))));
}

#[test]
fn a_verified_read_that_never_agrees_is_unconfirmed() {
    let mut core = DriverCore::new(Config::DEFAULT);
    core.start(Request::ReadVerified(Register::SpeedKp))
        .unwrap();
    let mut now = 0;
    for value in [1, 2, 3, 4] {
        assert!(out(&mut core, now).is_some());
        reply(&mut core, Register::SpeedKp, value, now.saturating_add(1));
        now = now.saturating_add(10);
    }
    assert!(out(&mut core, now).is_none(), "four tries at most");
    assert_eq!(
        core.take_outcome(),
        Some(Err(CoreError::Unconfirmed(Register::SpeedKp)))
    );
}

#[test]
fn the_failsafe_allows_the_settings_pause_but_not_a_dead_board() {
    let mut core = DriverCore::new(Config::DEFAULT);
    drive(&mut core, 0);
    let _ = core.tick(100);
    assert_eq!(out(&mut core, 100), None);
    let _ = core.tick(101);
    assert_eq!(out(&mut core, 101).as_deref(), Some(&STOP[..]));
    assert_eq!(core.failsafe_stops(), 1);
    // Moving again; a write makes the board pause: 600 ms allowed.
    drive(&mut core, 1_000);
    core.write(Write::MaxSpeed(10), 1_000).unwrap();
    assert!(out(&mut core, 1_000).is_some());
    let _ = core.tick(1_599);
    assert_eq!(out(&mut core, 1_599), None);
    let _ = core.tick(1_601);
    assert!(out(&mut core, 1_601).is_some());
    // Standing still, silence is no reason to stop.
    core.velocity(Velocity::STOP, 2_000).unwrap();
    assert!(out(&mut core, 2_000).is_some());
    let _ = core.tick(10_000);
    assert_eq!(out(&mut core, 10_000), None);
}

#[test]
fn the_settings_pause_ends_when_telemetry_comes_back() {
    // Found by the emulator test of the bring-up: a read just before a motion gave a board
    // that went silent mid-motion 600 ms instead of 100.
    let mut core = DriverCore::new(Config::DEFAULT);
    drive(&mut core, 0);
    core.write(Write::MaxSpeed(10), 0).unwrap();
    assert!(out(&mut core, 0).is_some());
    for (seq, at) in (1..).zip((150..=180).step_by(10)) {
        imu(&mut core, seq, at);
    }
    assert!(core.last_telemetry_ms().is_some(), "telemetry is back");
    // Silent from 180: stopped after 100 ms, not 600 after the write.
    let _ = core.tick(280);
    assert_eq!(out(&mut core, 280), None);
    let _ = core.tick(281);
    assert_eq!(out(&mut core, 281).as_deref(), Some(&STOP[..]));
}

#[test]
fn telemetry_on_its_way_before_a_reply_does_not_end_the_settings_pause() {
    // Found by the emulator's noisy bring-up (one run in a few): a register read while
    // moving, two IMU frames the board had sent before taking the read parsed right after
    // it, then the reply, then the board's pause: the failsafe stopped the chassis.
    let mut core = DriverCore::new(Config::DEFAULT);
    // Telemetry streaming (the parser locked on it), then the read.
    for seq in 1..=5 {
        imu(&mut core, seq, 0);
    }
    assert!(core.last_telemetry_ms().is_some());
    drive(&mut core, 0);
    core.start(Request::Read(Register::MaxSpeed)).unwrap();
    assert!(out(&mut core, 0).is_some());
    imu(&mut core, 6, 1);
    imu(&mut core, 7, 2);
    reply(&mut core, Register::MaxSpeed, 0, 3);
    // The board pauses for 150 ms after the reply: no stop.
    let _ = core.tick(160);
    assert_eq!(out(&mut core, 160), None);
    assert_eq!(core.failsafe_stops(), 0);
}

#[test]
fn reads_a_silent_board_leaves_unanswered_never_hold_the_failsafe_off() {
    // The pause idle_core's answered read allows (600 ms from 0) over, the board heard at
    // 700, moving, then silent; a read started again as soon as one gives up (another
    // thread's loop): the stop still comes failsafe_ms after the board was last heard.
    let mut core = idle_core();
    reply(&mut core, Register::MaxSpeed, 1_000, 700);
    // Moving from the core's time now (the reply was taken in at 705, on a quiet line).
    let heard = core.now_ms();
    let mut now = heard;
    drive(&mut core, now);
    let mut stopped = None;
    while now < 2_000 && stopped.is_none() {
        if !core.busy() {
            core.start(Request::Read(Register::MotorVoltage)).unwrap();
        }
        for _ in 0..20 {
            now += 1;
            let _ = core.tick(now);
            while let Some(frame) = out(&mut core, now) {
                if frame == STOP {
                    stopped = Some(now);
                }
            }
        }
    }
    assert_stopped_in_time(stopped, heard);
    assert_eq!(core.failsafe_stops(), 1);
}

#[test]
fn a_read_unanswered_ends_the_pause_an_answered_read_allowed() {
    // Moving, reads answered (each allows the board a telemetry pause, A13), then the board
    // goes silent: the next read goes unanswered, and the stop comes failsafe_ms after the
    // last frame heard, not settings_pause_ms after the last read answered.
    let mut core = idle_core();
    let mut now = 700;
    drive(&mut core, now);
    core.start(Request::Read(Register::MaxSpeed)).unwrap();
    assert!(out(&mut core, now).is_some());
    reply(&mut core, Register::MaxSpeed, 1_000, now + 1);
    assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(1_000))));
    let heard = now + 1;
    now = core.now_ms();
    core.start(Request::Read(Register::MotorVoltage)).unwrap();
    assert!(out(&mut core, now).is_some());
    let mut stopped = None;
    while now < 2_000 && stopped.is_none() {
        now += 1;
        let _ = core.tick(now);
        if out(&mut core, now).as_deref() == Some(&STOP[..]) {
            stopped = Some(now);
        }
    }
    assert_stopped_in_time(stopped, heard);
}

/// The motor-voltage read's reply (`#`, code `0B`, 1200 as `00 00 04 B0`) with a byte added on
/// the line after the `#`: no frame comes of it.
const DAMAGED_REPLY: [u8; 7] = [0x23, 0xE3, 0x0B, 0x00, 0x00, 0x04, 0xB0];

/// Ticks the core a millisecond at a time from `from` to `to`, sending whatever it has (its
/// retries); when the failsafe's stop went, if it did.
fn stop_between(core: &mut DriverCore, from: u64, to: u64) -> Option<u64> {
    for now in from..=to {
        let _ = core.tick(now);
        while let Some(frame) = out(core, now) {
            if frame == STOP {
                return Some(now);
            }
        }
    }
    None
}

/// Moving at 0 with telemetry streaming (IMU at 0..=50), then the motor-voltage read at 50.
fn moving_with_a_read() -> DriverCore {
    let mut core = DriverCore::new(Config::DEFAULT);
    for seq in 0..=5 {
        imu(&mut core, seq, u64::from(seq) * 10);
    }
    drive(&mut core, 0);
    core.start(Request::Read(Register::MotorVoltage)).unwrap();
    assert!(out(&mut core, 50).is_some());
    core
}

#[test]
fn a_reply_damaged_on_the_line_still_allows_the_boards_pause() {
    // Found by the emulator's noisy bring-up: a byte added to a read's reply while moving,
    // the board's telemetry pause after it (it took the read), and the failsafe stopped the
    // chassis 100 ms after the last frame heard. Bytes that make no frame after a read, then a
    // quiet line, are the board's answer, damaged: it took the read and may pause.
    let mut core = moving_with_a_read();
    let mut rest = &DAMAGED_REPLY[..];
    while !rest.is_empty() {
        rest = core.receive(rest, 53).1;
    }
    // The board pauses 200 ms: no stop (the read retried meanwhile goes unanswered too).
    assert_eq!(stop_between(&mut core, 53, 253), None);
    assert_eq!(core.failsafe_stops(), 0);
    // Its telemetry back, the pause is over: silence from the last frame stops it in time.
    imu(&mut core, 6, 260);
    imu(&mut core, 7, 270);
    assert_stopped_in_time(stop_between(&mut core, 271, 1_000), 270);
}

#[test]
fn a_damaged_answer_holds_the_failsafe_off_no_longer_than_the_settings_pause() {
    // The board answers damaged, then never again: stopped at most settings_pause_ms after
    // the read went, as after any settings frame.
    let mut core = moving_with_a_read();
    let _ = core.receive(&DAMAGED_REPLY, 53);
    let stopped = stop_between(&mut core, 53, 2_000).expect("the failsafe stops it");
    assert!(
        (150..=50 + u64::from(Config::DEFAULT.settings_pause_ms) + 2).contains(&stopped),
        "stopped at {stopped}"
    );
}

#[test]
fn bytes_before_a_read_are_no_answer_to_it() {
    // The same bytes, heard before the read went: nothing took the read, the board is just
    // silent from 50, and the stop comes failsafe_ms after the last frame heard.
    let mut core = DriverCore::new(Config::DEFAULT);
    for seq in 0..=5 {
        imu(&mut core, seq, u64::from(seq) * 10);
    }
    drive(&mut core, 0);
    let _ = core.receive(&DAMAGED_REPLY, 50);
    let _ = core.tick(55);
    core.start(Request::Read(Register::MotorVoltage)).unwrap();
    assert!(out(&mut core, 55).is_some());
    assert_stopped_in_time(stop_between(&mut core, 55, 1_000), 50);
}

#[test]
fn stop_cancels_an_outstanding_turn() {
    let mut core = idle_core();
    core.turn(Turn::by_deci_degrees(900), 10).unwrap();
    assert!(out(&mut core, 10).is_some());
    core.stop();
    assert_eq!(out(&mut core, 100).as_deref(), Some(&STOP[..]));
    let read = out(&mut core, 100).unwrap();
    assert_eq!(read, [0xFF, 0xFE, 0x80, 0x80, 0x20, 0, 0, 0, 0, 0]);
    // A damaged reply (more than the turn) is not believed: read again.
    reply(&mut core, Register::PendingAngle, 8_100, 101);
    let again = out(&mut core, 106).unwrap();
    assert_eq!(again, read);
    reply(&mut core, Register::PendingAngle, 810, 107);
    let counter = out(&mut core, 112).unwrap();
    // −81.0°: angle mode (bit 4) and Z reverse (bit 0).
    assert_eq!(counter, [0xFF, 0xFE, 0x01, 0, 0, 0, 0, 0x03, 0x2A, 0x11]);
    assert_eq!(core.take_outcome(), Some(Ok(Outcome::Done)));
    assert!(!core.turning());
}

#[test]
fn the_failsafe_cancels_a_turn_once_the_board_answers_again() {
    let mut core = idle_core();
    core.turn(Turn::by_deci_degrees(900), 10).unwrap();
    assert!(out(&mut core, 10).is_some());
    // Silent after the read of the pending angle (at 0: the settings pause allows 600 ms):
    // the stop at 601, then the pending angle asked for, again and again.
    let _ = core.tick(600);
    assert_eq!(out(&mut core, 600), None);
    let _ = core.tick(601);
    assert_eq!(out(&mut core, 601).as_deref(), Some(&STOP[..]));
    let mut reads = 0;
    let mut now = 601;
    while now < 1_600 {
        let _ = core.tick(now);
        if let Some(frame) = out(&mut core, now) {
            assert_eq!(frame, [0xFF, 0xFE, 0x80, 0x80, 0x20, 0, 0, 0, 0, 0]);
            reads += 1;
        }
        now += 1;
    }
    assert!(reads >= 3, "{reads} reads of the pending angle in 1 s");
    assert!(core.turning(), "the guard holds while nothing is known");
    // A user's read goes first; then the board answers the cancel's read.
    core.start(Request::Read(Register::MaxSpeed)).unwrap();
    loop {
        let _ = core.tick(now);
        if let Some(frame) = out(&mut core, now) {
            if frame[4] == 0x11 {
                break;
            }
        }
        now += 1;
        assert!(now < 3_000, "the user's read never went");
    }
    reply(&mut core, Register::MaxSpeed, 1_000, now + 1);
    assert_eq!(core.take_outcome(), Some(Ok(Outcome::Value(1_000))));
    let mut now = now + 10;
    let read = loop {
        let _ = core.tick(now);
        if let Some(frame) = out(&mut core, now) {
            break frame;
        }
        now += 1;
        assert!(now < 5_000, "the cancel never came back");
    };
    assert_eq!(read[4], 0x20);
    reply(&mut core, Register::PendingAngle, 450, now + 1);
    let counter = out(&mut core, now + 6).unwrap();
    // −45.0°
    assert_eq!(counter, [0xFF, 0xFE, 0x01, 0, 0, 0, 0, 0x01, 0xC2, 0x11]);
    assert!(!core.turning());
    assert_eq!(
        core.take_outcome(),
        None,
        "nobody waits for the core's own cancel"
    );
}

#[test]
fn time_from_a_wrapping_u32_counter_keeps_the_failsafe() {
    let mut core = DriverCore::new(Config::DEFAULT);
    let start = u64::from(u32::MAX) - 50;
    core.velocity(Velocity::new(0, 100, 0), start).unwrap();
    assert!(out(&mut core, start).is_some());
    let _ = core.tick(u64::from(u32::MAX));
    assert_eq!(out(&mut core, u64::from(u32::MAX)), None);
    // Across the wrap (u32::MAX → 0 is one millisecond): 100 ms after the last command,
    // not yet; 101 ms, stopped.
    let _ = core.tick(49);
    assert_eq!(out(&mut core, 49), None);
    let _ = core.tick(50);
    assert_eq!(out(&mut core, 50).as_deref(), Some(&STOP[..]));
}

#[test]
fn rates_hold_for_frames_read_in_batches() {
    let mut info = StreamInfo::default();
    // A 1 Hz loop reading 100 frames a second, all stamped with the read's time.
    for second in 1..=3u64 {
        for _ in 0..100 {
            info.arrived(second * 1_000, 0);
        }
    }
    assert_eq!(info.rate_hz(), 100);
}
