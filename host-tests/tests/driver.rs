//! The blocking driver against the board simulator, through an in-memory UART and a simulated
//! clock (1 ms per clock reading): every command, every setting written and read back, the
//! one-shot turn, the failsafe, the reply timeout, telemetry rates, the settings snapshot.

use chassis_protocol::driver::{Config, CoreError, Error, Event, Snapshot, blocking::Driver, reg};
use chassis_protocol::sim::{Board, FACTORY, Faults, Motion, SimClock, SimConfig, SimUart};
use chassis_protocol::{
    Action, Downlink, DriveType, Motors, Register, Stream, SystemMode, Velocity, Write,
};
use core::cell::Cell;
use core::convert::Infallible;

type SimDriver<'t> = Driver<SimUart<'t>, SimClock<'t>>;

fn driver(time: &Cell<u64>) -> SimDriver<'_> {
    let uart = SimUart::new(Board::new(SimConfig::default()), time);
    Driver::new(uart, SimClock(time), Config::DEFAULT)
}

/// Polls for `ms` milliseconds of simulated time, collecting telemetry.
fn run_for(d: &mut SimDriver<'_>, time: &Cell<u64>, ms: u64) -> Vec<Downlink> {
    let end = time.get() + ms;
    let mut frames = Vec::new();
    while time.get() < end {
        if let Some(Event::Telemetry(frame)) = d.poll().unwrap() {
            frames.push(frame);
        }
    }
    frames
}

fn board<'a>(d: &'a SimDriver<'_>) -> &'a Board {
    d.uart().board()
}

#[test]
fn motion_commands_reach_the_board() {
    let time = Cell::new(0);
    let mut d = driver(&time);
    d.set_velocity(Velocity::new(-10, 200, 30)).unwrap();
    run_for(&mut d, &time, 5);
    assert_eq!(
        board(&d).motion(),
        Motion::Velocity {
            x: -10,
            y: 200,
            z: 30
        }
    );
    d.set_motors(Motors::closed_loop([1, -2, 3, -4])).unwrap();
    run_for(&mut d, &time, 5);
    assert_eq!(board(&d).motion(), Motion::Motors([1, -2, 3, -4]));
    d.set_motors(Motors::open_loop_duty([10_000, -10_000, 2_500, 0]))
        .unwrap();
    run_for(&mut d, &time, 5);
    assert_eq!(
        board(&d).motion(),
        Motion::Motors([10_000, -10_000, 2_500, 0])
    );
    d.stop().unwrap();
    run_for(&mut d, &time, 5);
    assert_eq!(board(&d).motion(), Motion::Velocity { x: 0, y: 0, z: 0 });
    // Differential chassis: the duty form.
    d.set_velocity(Velocity::differential_duty(5_000, -1_000))
        .unwrap();
    run_for(&mut d, &time, 5);
    assert_eq!(
        board(&d).motion(),
        Motion::Velocity {
            x: 0,
            y: 5_000,
            z: -1_000
        }
    );
}

#[test]
fn every_register_written_reads_back() {
    let time = Cell::new(0);
    let mut d = driver(&time);
    let writes = [
        Write::MaxSpeed(1_234),
        Write::SpeedKp(0x0102_0304),
        Write::SpeedKi(77),
        Write::GyroGain(12_345),
        Write::SystemMode(SystemMode::new(DriveType::Differential).with_steering_reversed(true)),
        Write::GyroCalibration(0x0321),
        Write::MotorVoltage { centivolts: 1_180 },
        Write::BatteryRange {
            full_centivolts: 1_260,
            cutoff_centivolts: 1_000,
        },
    ];
    for write in writes {
        d.write(write).unwrap();
        let raw = d.read_raw(write.register()).unwrap();
        assert_eq!(raw, write.value(), "{write:?}");
    }
}

#[test]
fn actions_store_load_and_defaults() {
    let time = Cell::new(0);
    let mut d = driver(&time);
    d.write(Write::MaxSpeed(42)).unwrap();
    d.write(Write::SystemMode(
        SystemMode::new(DriveType::Omni).with_gyro_compensation(true),
    ))
    .unwrap();
    d.action(Action::Store).unwrap();
    d.action(Action::LoadDefaults).unwrap();
    assert_eq!(d.read(reg::MaxSpeed).unwrap(), FACTORY.max_speed);
    d.action(Action::LoadStored).unwrap();
    assert_eq!(d.read(reg::MaxSpeed).unwrap(), 42);
    // System-mode bit 3 (gyro compensation) is not stored.
    let mode = d.read(reg::SystemMode).unwrap();
    assert_eq!(mode.drive_type(), DriveType::Omni);
    assert!(!mode.gyro_compensation());
    d.action(Action::GyroCompensationOn).unwrap();
    assert!(d.read(reg::SystemMode).unwrap().gyro_compensation());
    d.action(Action::GyroCompensationOff).unwrap();
    assert!(!d.read(reg::SystemMode).unwrap().gyro_compensation());
}

#[test]
fn gyro_calibration_takes_thirty_seconds() {
    let time = Cell::new(0);
    let mut d = driver(&time);
    d.action(Action::RecalibrateGyro).unwrap();
    run_for(&mut d, &time, 1_000);
    assert_eq!(d.read(reg::GyroCalibration).unwrap(), 0xFFFF);
    run_for(&mut d, &time, 28_000);
    assert_eq!(d.read(reg::GyroCalibration).unwrap(), 0xFFFF);
    run_for(&mut d, &time, 1_100);
    assert_ne!(d.read(reg::GyroCalibration).unwrap(), 0xFFFF);
}

#[test]
fn a_turn_in_a_periodic_loop_is_sent_once() {
    let time = Cell::new(0);
    let mut d = driver(&time);
    // A control loop at 100 Hz that asks for a 90° turn every period, as a naive master would.
    let mut refused = 0;
    for _ in 0..50 {
        match d.turn_by(900) {
            Ok(()) => {}
            Err(Error::Core(CoreError::TurnInProgress)) => refused += 1,
            Err(e) => panic!("{e:?}"),
        }
        run_for(&mut d, &time, 10);
    }
    assert_eq!(refused, 49);
    assert_eq!(d.uart().board().total_turn_commanded(), 900);
    // 90° at 90°/s: done after a second; the pending angle reads 0 and frees the next turn.
    run_for(&mut d, &time, 600);
    assert_eq!(d.turn_remaining().unwrap(), 0);
    d.turn_by(-450).unwrap();
    run_for(&mut d, &time, 10);
    assert_eq!(d.uart().board().total_turn_commanded(), 450);
    assert_eq!(d.turn_by(-450), Err(Error::Core(CoreError::TurnInProgress)));
}

#[test]
fn failsafe_stops_the_chassis_when_telemetry_stops() {
    let time = Cell::new(0);
    let mut d = driver(&time);
    run_for(&mut d, &time, 200);
    assert!(d.core().link_alive(time.get()));
    d.set_velocity(Velocity::new(0, 300, 0)).unwrap();
    run_for(&mut d, &time, 50);
    d.uart_mut().board_mut().set_faults(Faults {
        telemetry_stopped: true,
        ..Faults::default()
    });
    let silent_from = time.get();
    while d.uart().board().motion() != (Motion::Velocity { x: 0, y: 0, z: 0 }) {
        d.poll().unwrap();
        assert!(time.get() - silent_from < 1_000, "no failsafe stop");
    }
    let after = time.get() - silent_from;
    // The last IMU frame came at most 10 ms before the silence began.
    assert!(
        after <= u64::from(Config::DEFAULT.failsafe_ms) + 2,
        "stopped after {after} ms"
    );
    assert!(
        after >= u64::from(Config::DEFAULT.failsafe_ms) - 10,
        "stopped after {after} ms"
    );
    assert_eq!(d.core().failsafe_stops(), 1);
    assert!(!d.core().link_alive(time.get()));
}

#[test]
fn a_silent_board_gives_a_reply_timeout() {
    let time = Cell::new(0);
    let mut d = driver(&time);
    d.uart_mut().board_mut().set_faults(Faults {
        replies_stopped: true,
        ..Faults::default()
    });
    let start = time.get();
    assert_eq!(
        d.read(reg::SpeedKp),
        Err(Error::<Infallible>::Core(CoreError::Timeout(
            Register::SpeedKp
        )))
    );
    let waited = time.get() - start;
    let timeout = u64::from(Config::DEFAULT.reply_timeout_ms());
    assert!(
        (timeout..timeout + 3).contains(&waited),
        "waited {waited} ms for {timeout}"
    );
    // The driver is free again.
    d.uart_mut().board_mut().set_faults(Faults::default());
    assert_eq!(d.read(reg::MotorVoltage).unwrap(), 1_200);
}

#[test]
fn telemetry_streams_at_the_boards_rates() {
    let time = Cell::new(0);
    let mut d = driver(&time);
    let frames = run_for(&mut d, &time, 3_000);
    let count = |s: Stream| {
        frames
            .iter()
            .filter(|f| f.kind() == chassis_protocol::Kind::Telemetry(s))
            .count()
    };
    assert!(
        (295..=301).contains(&count(Stream::Imu)),
        "{}",
        count(Stream::Imu)
    );
    assert!(
        (73..=76).contains(&count(Stream::Encoders)),
        "{}",
        count(Stream::Encoders)
    );
    assert!(
        (2..=4).contains(&count(Stream::Battery)),
        "{}",
        count(Stream::Battery)
    );
    let core = d.core();
    assert_eq!(core.stream(Stream::Imu).rate_hz(), 100);
    assert_eq!(core.stream(Stream::Encoders).rate_hz(), 25);
    assert_eq!(core.stream(Stream::Imu).missed, 0);
    assert!(core.imu().is_some() && core.encoders().is_some() && core.battery().is_some());
    assert!(core.link_alive(time.get()));
}

#[test]
fn replies_interleave_with_telemetry_on_a_noisy_line() {
    let time = Cell::new(0);
    let mut d = driver(&time);
    run_for(&mut d, &time, 100);
    d.uart_mut().board_mut().set_faults(Faults {
        corrupt_per_million: 1_000,
        ..Faults::default()
    });
    // One byte in a thousand changed: without a checksum a plain read can return a wrong value
    // unseen; a verified read (two replies that agree) does not.
    let mut ok = 0;
    for _ in 0..200 {
        if let Ok(centivolts) = d.read_verified(reg::MotorVoltage) {
            assert_eq!(centivolts, 1_200);
            ok += 1;
        }
        run_for(&mut d, &time, 20);
    }
    assert!(ok >= 198, "{ok} of 200 verified reads answered");
    // Downlink paused while the reads went on (A6) and resumes 100 ms after the last one: of
    // the next 300 ms (the last read was 20 ms ago), 80 are still quiet, 220 carry 22 IMU frames.
    let before = d.core().stream(Stream::Imu).frames;
    run_for(&mut d, &time, 300);
    let resumed = d.core().stream(Stream::Imu).frames - before;
    assert!(
        (21..=23).contains(&resumed),
        "{resumed} IMU frames after the pause"
    );
}

#[test]
fn the_settings_snapshot_reads_in_one_call_and_serialises_with_postcard() {
    let time = Cell::new(0);
    let mut d = driver(&time);
    d.write(Write::SpeedKp(999)).unwrap();
    let settings = d.read_settings().unwrap();
    let factory = FACTORY;
    assert_eq!(settings.speed_kp, 999);
    assert_eq!(settings.max_speed, factory.max_speed);
    assert_eq!(settings.system_mode, factory.system_mode);
    assert_eq!(settings.motor_centivolts, factory.motor_centivolts);

    let mut buf = [0u8; 64];
    let bytes = postcard::to_slice(&settings, &mut buf).unwrap();
    let back: Snapshot = postcard::from_bytes(bytes).unwrap();
    assert_eq!(back, settings);
    let mut buf = [0u8; 64];
    let framed = postcard::to_slice_cobs(&settings, &mut buf).unwrap();
    assert!(!framed[..framed.len() - 1].contains(&0));
    let back: Snapshot = postcard::from_bytes_cobs(framed).unwrap();
    assert_eq!(back, settings);

    // Restore on a fresh board.
    let time2 = Cell::new(0);
    let mut fresh = driver(&time2);
    fresh.restore_settings(&settings).unwrap();
    let mut restored = fresh.read_settings().unwrap();
    restored.gyro_calibration = settings.gyro_calibration;
    assert_eq!(restored, settings);
}
