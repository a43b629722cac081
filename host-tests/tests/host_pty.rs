//! The host driver (`driver::host`: `serialport`, a monotonic clock, `Config::HOST`) against the
//! simulated board through the kernel's pseudo-terminal, in real time.
#![cfg(unix)]

use chassis_protocol::driver::host::{MonotonicClock, SerialPort};
use chassis_protocol::driver::{Config, blocking::Driver, reg};
use chassis_protocol::sim::{Board, FACTORY, Motion, SimConfig, serve};
use chassis_protocol::{Stream, Velocity};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

#[test]
fn the_host_driver_drives_the_simulated_board_through_a_pty() {
    let (mut board_end, driver_end) = serialport::TTYPort::pair().unwrap();
    serialport::SerialPort::set_timeout(&mut board_end, Duration::from_millis(1)).unwrap();
    let stop = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let board = scope.spawn(|| serve(Board::new(SimConfig::default()), board_end, &stop));
        let port = SerialPort::from_port(Box::new(driver_end)).unwrap();
        let mut d = Driver::new(port, MonotonicClock::new(), Config::HOST);

        assert_eq!(d.read_settings().unwrap(), FACTORY);
        d.set_velocity(Velocity::new(0, 150, 0)).unwrap();
        d.turn_by(90).unwrap();
        let started = Instant::now();
        while d.core().turning() {
            assert!(
                started.elapsed() < Duration::from_secs(2),
                "turn never ended"
            );
            let until = Instant::now() + Duration::from_millis(30);
            while Instant::now() < until {
                d.poll().unwrap();
            }
            d.turn_remaining().unwrap();
        }
        assert_eq!(d.read(reg::MotorVoltage).unwrap(), 1_200);
        let until = Instant::now() + Duration::from_millis(1_300);
        while Instant::now() < until {
            d.poll().unwrap();
        }
        let imu = d.core().stream(Stream::Imu);
        assert!(
            (95..=105).contains(&imu.rate_hz()),
            "IMU at {} Hz",
            imu.rate_hz()
        );
        assert_eq!(d.core().failsafe_stops(), 0);
        d.stop().unwrap();
        std::thread::sleep(Duration::from_millis(20));
        stop.store(true, Ordering::Relaxed);
        let board = board.join().unwrap().unwrap();
        assert_eq!(board.total_turn_commanded(), 90);
        assert_eq!(board.motion(), Motion::Velocity { x: 0, y: 0, z: 0 });
    });
}
