//! The driver over a simulated v1.0.0 board: the failsafe's forced stop, its tolerance of the
//! telemetry frames the board drops while it receives commands, and settings written only when
//! asked. The bytes the board must receive are written by hand from `docs/protocol-v1.md`.

use chassis_protocol::driver::blocking::Driver;
use chassis_protocol::driver::v1::{DriverCore, MIN_FAILSAFE_MS, Settings};
use chassis_protocol::driver::{Config, Error};
use chassis_protocol::sim::v1::{Board, SimConfig};
use chassis_protocol::sim::{Faults, SimClock, SimUart};
use chassis_protocol::v1::{BodyVelocity, Command, Geometry, Pid, Readback, SystemSettings};
use core::cell::Cell;
use core::convert::Infallible;

type V1Driver<'t> = Driver<SimUart<'t, Board>, SimClock<'t>, DriverCore>;

fn driver(time: &Cell<u64>, config: SimConfig) -> V1Driver<'_> {
    Driver::new_v1(
        SimUart::new(Board::new(config), time),
        SimClock(time),
        Config::HOST,
    )
}

/// Runs the driver's loop until the simulated clock reaches `until`: a velocity every
/// `period` ms (0: none), a poll every reading.
fn run(
    d: &mut V1Driver<'_>,
    time: &Cell<u64>,
    until: u64,
    period: u64,
) -> Result<(), Error<Infallible>> {
    let mut next = time.get();
    while time.get() < until {
        if period > 0 && time.get() >= next {
            d.set_velocity(BodyVelocity::new(0, 300, 0))?;
            next = time.get() + period;
        }
        d.poll()?;
    }
    Ok(())
}

#[test]
fn dropped_telemetry_while_commanded_never_trips_the_failsafe() {
    // 20 commands a second for ten minutes of simulated time, the board dropping ~6 % of its
    // telemetry frames after commands (what owners report), then twice that. Six frames
    // dropped in a row (315 ms of silence) would stop it: at 6 %, once in about 2 × 10⁷
    // frames (0.06⁶), five days of streaming.
    for drop in [60_000, 120_000] {
        let time = Cell::new(0);
        let mut d = driver(
            &time,
            SimConfig {
                busy_drop_per_million: drop,
                ..SimConfig::default()
            },
        );
        run(&mut d, &time, 600_000, 50).unwrap();
        let board = d.uart().board();
        assert!(
            board.telemetry_dropped() > 100,
            "{}",
            board.telemetry_dropped()
        );
        assert_eq!(d.core().failsafe_stops(), 0, "drop rate {drop} per million");
        assert_eq!(board.forced_stops(), 0);
        assert_eq!(board.velocity(), BodyVelocity::new(0, 300, 0));
    }
}

#[test]
fn a_silent_board_gets_the_forced_stop_within_the_failsafe() {
    let time = Cell::new(0);
    let mut d = driver(&time, SimConfig::default());
    run(&mut d, &time, 2_000, 50).unwrap();
    // The board's line to the master goes dead; the program keeps polling, no new command.
    d.uart_mut().board_mut().set_faults(Faults {
        telemetry_stopped: true,
        replies_stopped: true,
        ..Faults::default()
    });
    let heard = d.core().last_heard_ms().unwrap();
    let mut stopped_at = None;
    while time.get() < 5_000 {
        d.poll().unwrap();
        if stopped_at.is_none() && d.uart().board().forced_stops() > 0 {
            stopped_at = Some(time.get());
        }
    }
    let stopped_at = stopped_at.expect("the failsafe never stopped the board");
    let silence = stopped_at - heard;
    assert!(
        silence > u64::from(MIN_FAILSAFE_MS) && silence <= u64::from(MIN_FAILSAFE_MS) + 5,
        "stopped after {silence} ms of silence"
    );
    assert_eq!(d.uart().board().velocity(), BodyVelocity::FORCED_STOP);
    assert_eq!(d.uart().board().forced_stops(), 1, "sent once");
    // The frame the board took, byte for byte: the forced stop of `docs/protocol-v1.md`.
    let last = d.uart().board().received().last().copied().unwrap();
    assert_eq!(
        last.encode(),
        [0x7B, 0x25, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x5E, 0x7D]
    );
}

#[test]
fn the_driver_writes_settings_only_when_asked_and_confirms_them() {
    let time = Cell::new(0);
    let mut d = driver(&time, SimConfig::default());
    // A session: drive, read everything back, stop.
    run(&mut d, &time, 1_000, 50).unwrap();
    for readback in Readback::ALL {
        d.readback(readback).unwrap();
    }
    d.stop().unwrap();
    run(&mut d, &time, 2_000, 0).unwrap();
    let board = d.uart().board();
    for code in [0x23, 0x24, 0x40] {
        assert_eq!(
            board.received_count(code),
            0,
            "settings frame {code:#04x} unasked"
        );
    }
    // Asked: three settings frames, each confirmed by its readback, 100 ms apart at least.
    let system = SystemSettings {
        motor_directions: 1,
        encoder_directions: 10,
        pwm_max: 3500,
        pwm_min: 2000,
        encoder_ppr: 330,
    };
    let geometry = Geometry {
        wheel_spacing_mm: 120,
        axle_spacing_mm: 100,
        gear_ratio: 30,
        wheel_diameter_mm: 80,
    };
    let pid = Pid {
        position_kp: 2000,
        position_ki: 0,
        position_kd: 10,
        velocity_kp: 2500,
        velocity_ki: 900,
    };
    let start = time.get();
    d.write_settings(Settings::System(system)).unwrap();
    d.write_settings(Settings::Geometry(geometry)).unwrap();
    d.write_settings(Settings::Pid(pid)).unwrap();
    assert!(
        time.get() - start >= 300,
        "three writes with their readbacks, 100 ms between frames: {} ms",
        time.get() - start
    );
    let board = d.uart().board();
    assert_eq!(board.system(), system);
    assert_eq!(board.geometry(), geometry);
    assert_eq!(board.pid(), pid);
    let written: Vec<u8> = board
        .received()
        .map(Command::code)
        .filter(|c| [0x23, 0x24, 0x40].contains(c))
        .collect();
    assert_eq!(written, vec![0x23, 0x24, 0x40], "each sent once");
}

#[test]
fn an_unanswered_readback_is_an_error_that_leaves_the_driver_usable() {
    let time = Cell::new(0);
    let mut d = driver(&time, SimConfig::default());
    d.uart_mut().board_mut().set_faults(Faults {
        replies_stopped: true,
        ..Faults::default()
    });
    assert_eq!(
        d.readback(Readback::Pid).map(|_| ()),
        Err(Error::Core(
            chassis_protocol::driver::CoreError::NoReadback(Readback::Pid)
        ))
    );
    d.uart_mut().board_mut().set_faults(Faults::default());
    assert_eq!(
        d.pid().unwrap().velocity_kp,
        3000,
        "the vendor example's value"
    );
}
