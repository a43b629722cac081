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

#[test]
fn a_port_set_not_to_wait_takes_in_what_arrived_and_returns_at_once() {
    use embedded_io::{Read as _, ReadReady as _};
    use std::io::Write as _;
    let (mut board_end, driver_end) = serialport::TTYPort::pair().unwrap();
    let mut port = SerialPort::from_port(Box::new(driver_end)).unwrap();

    // By default each look at a silent line waits WAIT_FOR_BYTE (1 ms) for a byte: at least
    // 20 ms for 20 looks, whatever the machine.
    let start = Instant::now();
    for _ in 0..20 {
        assert!(!port.read_ready().unwrap());
    }
    assert!(start.elapsed() >= Duration::from_millis(20));

    // Set not to wait: 100 looks take less than the 100 ms they would have waited.
    port.set_wait_for_byte(Duration::ZERO).unwrap();
    let start = Instant::now();
    for _ in 0..100 {
        assert!(!port.read_ready().unwrap());
    }
    assert!(
        start.elapsed() < Duration::from_millis(100),
        "{:?}",
        start.elapsed()
    );

    // What arrived is still taken in, every byte, in order.
    board_end.write_all(&[0xFF, 0xFA, 0x01, 0x02]).unwrap();
    board_end.flush().unwrap();
    let deadline = Instant::now() + Duration::from_secs(2);
    let mut got = Vec::new();
    while got.len() < 4 && Instant::now() < deadline {
        if port.read_ready().unwrap() {
            let mut buf = [0u8; 8];
            let n = port.read(&mut buf).unwrap();
            got.extend_from_slice(&buf[..n]);
        }
    }
    assert_eq!(got, [0xFF, 0xFA, 0x01, 0x02]);
}
