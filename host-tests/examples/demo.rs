//! The host demo (`cargo xtask demo`): builds every kind of command frame, then parses two
//! seconds of realistic board telemetry that crossed a noisy line, and says how it went.

use chassis_host_tests::channel::{Noise, transmit};
use chassis_host_tests::{BoardStream, score_downlink};
use chassis_protocol::driver::{Config, CoreError, Error, blocking::Driver};
use chassis_protocol::sim::{Board, SimClock, SimConfig, SimUart};
use chassis_protocol::{
    Action, Downlink, DownlinkParser, DriveType, Motors, Register, Setting, SystemMode, Turn,
    Velocity, Write,
};
use core::cell::Cell;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

fn hex(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn main() {
    println!("== Master -> board: fixed-size frames, no parser needed");
    let mode = SystemMode::new(DriveType::Mecanum).with_gyro_compensation(true);
    let commands: [(&str, Vec<u8>); 7] = [
        (
            "forward 300, turn -50",
            Velocity::new(0, 300, -50).encode().to_vec(),
        ),
        (
            "turn by +90.0 deg (once!)",
            Turn::by_deci_degrees(900).encode().to_vec(),
        ),
        (
            "motors, open loop 25 %",
            Motors::open_loop_duty([2_500, 2_500, -2_500, -2_500])
                .encode()
                .to_vec(),
        ),
        (
            "system mode: mecanum + gyro",
            Setting::Write(Write::SystemMode(mode)).encode().to_vec(),
        ),
        (
            "motor voltage 12.00 V",
            Setting::Write(Write::MotorVoltage { centivolts: 1_200 })
                .encode()
                .to_vec(),
        ),
        (
            "read pending angle",
            Setting::Read(Register::PendingAngle).encode().to_vec(),
        ),
        (
            "store settings",
            Setting::Action(Action::Store).encode().to_vec(),
        ),
    ];
    for (what, bytes) in &commands {
        println!("  {what:<30} {}", hex(bytes));
    }

    println!("\n== Board -> master: 2 s of telemetry through a line with 1e-3 errors per byte");
    let (bytes, sent) = BoardStream::new(2026, 2.0).take(255);
    let rx = transmit(&bytes, &Noise::mixed(1e-3), &mut Pcg64Mcg::seed_from_u64(1));
    let mut parser = DownlinkParser::new();
    let frames: Vec<Downlink> = parser.frames(&rx.bytes).collect();
    for frame in frames.iter().take(6) {
        println!("  {frame:?}");
    }
    println!("  ... {} frames in all", frames.len());
    let stats = parser.stats();
    println!(
        "  parser: {} bytes discarded, {} lock losses, {} resyncs, IMU count gaps {}, lock now {:?}",
        stats.discarded,
        stats.lock_losses,
        stats.resyncs,
        stats.gaps[0],
        parser.lock()
    );
    let score = score_downlink(&sent, &rx);
    println!(
        "  against what was sent: {} channel errors, {}/{} untouched frames recalled, {} false",
        score.errors, score.recalled, score.untouched, score.false_frames
    );

    println!("\n== The driver against the simulated board (in-memory UART, simulated clock)");
    if let Err(e) = drive_the_simulator() {
        println!("  driver error: {e}");
    }
}

fn drive_the_simulator() -> Result<(), Error<core::convert::Infallible>> {
    let time = Cell::new(0);
    let uart = SimUart::new(Board::new(SimConfig::default()), &time);
    let mut driver = Driver::new(uart, SimClock(&time), Config::DEFAULT);
    let settings = driver.read_settings()?;
    println!("  settings read in one call: {settings:?}");
    driver.set_velocity(Velocity::new(0, 300, 0))?;
    // A 100 Hz loop that asks for a 90-degree turn every period, as a naive master would.
    let mut refused = 0;
    for _ in 0..100 {
        if let Err(Error::Core(CoreError::TurnInProgress)) = driver.turn_by(900) {
            refused += 1;
        }
        let until = time.get() + 10;
        while time.get() < until {
            driver.poll()?;
        }
    }
    let board = driver.uart().board();
    println!(
        "  turn asked 100 times in a loop: sent once, refused {refused} times; the board was told to turn {:.1} degrees in all",
        board.total_turn_commanded() as f32 / 10.0
    );
    let remaining = driver.turn_remaining()?;
    // A second with nothing asked of the board: its telemetry runs unpaused, rates settle.
    let until = time.get() + 1_100;
    while time.get() < until {
        driver.poll()?;
    }
    let core = driver.core();
    println!(
        "  pending angle now {remaining} (0.1 deg); IMU at {} Hz, encoders at {} Hz; reply timeout {} ms; failsafe {} ms",
        core.stream(chassis_protocol::Stream::Imu).rate_hz(),
        core.stream(chassis_protocol::Stream::Encoders).rate_hz(),
        core.config().reply_timeout_ms(),
        core.config().failsafe_ms
    );
    Ok(())
}
