//! The host driver against the simulated board through a pseudo-terminal: the real OS serial
//! stack (the kernel's pty, `serialport`, the driver's host transport and monotonic clock, the
//! host defaults), in real time, no hardware. Unix only.
//!
//! `cargo run -p chassis-host-tests --example host_pty`

#[cfg(unix)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    use chassis_protocol::driver::host::{MonotonicClock, SerialPort};
    use chassis_protocol::driver::{Config, blocking::Driver, reg};
    use chassis_protocol::sim::{Board, SimConfig, serve};
    use chassis_protocol::{Stream, Velocity};
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::time::{Duration, Instant};

    let (mut board_end, master_end) = serialport::TTYPort::pair()?;
    serialport::SerialPort::set_timeout(&mut board_end, Duration::from_millis(1))?;
    let stop = AtomicBool::new(false);
    std::thread::scope(|scope| -> Result<(), Box<dyn std::error::Error>> {
        let board = scope.spawn(|| serve(Board::new(SimConfig::default()), board_end, &stop));
        let port = SerialPort::from_port(Box::new(master_end))?;
        println!("simulated board on {}", port.name().unwrap_or_default());
        let mut driver = Driver::new(port, MonotonicClock::new(), Config::HOST);

        let settings = driver.read_settings()?;
        println!("settings (each read verified): {settings:?}");
        driver.set_velocity(Velocity::new(0, 200, 0))?;
        driver.turn_by(450)?;
        let started = Instant::now();
        loop {
            let end = Instant::now() + Duration::from_millis(50);
            while Instant::now() < end {
                driver.poll()?;
            }
            let left = driver.turn_remaining()?;
            if !driver.core().turning() {
                println!(
                    "turned 45.0 degrees in {:.2} s (pending now {left})",
                    started.elapsed().as_secs_f32()
                );
                break;
            }
            if started.elapsed() > Duration::from_secs(3) {
                println!("turn not done after 3 s: {left} to go");
                break;
            }
        }
        driver.read(reg::MotorVoltage)?;
        let end = Instant::now() + Duration::from_millis(1_500);
        while Instant::now() < end {
            driver.poll()?;
        }
        driver.stop()?;
        let core = driver.core();
        println!(
            "IMU {} Hz, encoders {} Hz, battery {} frames; failsafe stops {}; parser lock {:?}",
            core.stream(Stream::Imu).rate_hz(),
            core.stream(Stream::Encoders).rate_hz(),
            core.stream(Stream::Battery).frames,
            core.failsafe_stops(),
            core.lock()
        );
        stop.store(true, Ordering::Relaxed);
        let board = board.join().map_err(|_| "board thread panicked")??;
        println!(
            "the board was told to turn {:.1} degrees in all; it last moved as {:?}",
            board.total_turn_commanded() as f32 / 10.0,
            board.motion()
        );
        Ok(())
    })
}

#[cfg(not(unix))]
fn main() {
    eprintln!("host_pty needs a Unix pseudo-terminal");
}
