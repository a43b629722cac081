//! The bring-up on QEMU's mps2-an386 (Cortex-M4 at 25 MHz): UART0 is the link to the chassis
//! (the simulated one, over TCP), defmt goes out over semihosting, and the exit status is the
//! verdict: 0 when every check passed, else [`Check::exit_code`] of the one that failed.
//!
//! It first finds which firmware the board runs (`chassis_protocol::detect::detect`: it
//! listens, and probes only a quiet line), logs it, then runs that generation's bring-up:
//!
//! * **2020** (`FF FE` frames): [`v2020::bring_up`] over the 2020 blocking driver (the encoders
//!   count, one 90° turn sent once, the drive type, register reads while moving).
//! * **v1.0.0** (`7B … BCC 7D` frames): [`v1::bring_up`] over the v1.0.0 blocking driver (the
//!   measured velocity follows, a rotation at a rate turns the quaternion's yaw, the forced
//!   stop; nothing written).
//!
//! The generation is decided once, in [`main`]; [`verdict`] logs either bring-up's result the
//! same way and gives its exit code.
//!
//! A silent line is taken as 2020, whose link check then fails (exit 10) saying what did not
//! come; bytes of neither generation fail the link check at once, with nothing sent.
//!
//! Run it with `cargo xtask demo` from the repository root, or `cargo run --release` here.

#![no_std]
#![no_main]

use board_qemu_an386::{stack, time, uart::Uart0};
use chassis_bringup::{Check, Failure, v1, v2020};
use chassis_protocol::detect::{Firmware, detect};
use chassis_protocol::driver::Config;
use cortex_m_rt::entry;
#[cfg(feature = "log")]
use defmt_semihosting as _;

/// The driver's settings for this board: a microcontroller's, except the quiet line. The
/// emulated UART is fed by another process over TCP, which hands bytes over in bursts when the
/// host is busy; a gap of a few ms inside a frame there is the host, not the board, and a quiet
/// line taken for a frame boundary would throw a frame away. 10 ms is longer than those gaps
/// and still far shorter than the failsafe (100 ms on 2020; the v1.0.0 driver raises it to
/// 300 ms). Detection uses the same quiet line.
const CONFIG: Config = Config {
    idle_ms: 10,
    ..Config::DEFAULT
};

/// Detection is tried again this many times in all if the UART fails (a receive overrun).
const DETECT_TRIES: u8 = 3;

#[entry]
fn main() -> ! {
    stack::paint();
    let mut uart = board_qemu_an386::init();
    defmt::info!(
        "chassis bring-up: QEMU mps2-an386, Cortex-M4, UART0 at 115200 bps, blocking driver"
    );

    let code = match firmware(&mut uart) {
        Ok(Firmware::V2020) => {
            let mut link = v2020::Blocking::new(uart, time::Millis, CONFIG);
            verdict(v2020::bring_up(&mut link, &v2020::Plan::DEFAULT), "")
        }
        Ok(Firmware::V1_0_0) => {
            let mut link = v1::Blocking::new(uart, time::Millis, CONFIG);
            verdict(v1::bring_up(&mut link, &v1::Plan::DEFAULT), " (v1.0.0)")
        }
        Err(code) => code,
    };
    defmt::info!(
        "RAM: {} B static + {} B stack at its peak",
        stack::static_ram(),
        stack::peak()
    );
    semihosting::process::exit(code)
}

/// Which firmware the board runs (a silent line: 2020), or the exit code of a line that
/// carries neither.
fn firmware(uart: &mut Uart0) -> Result<Firmware, i32> {
    let mut tries = 0u8;
    let detection = loop {
        tries = tries.saturating_add(1);
        match detect(uart, &mut time::Millis, &CONFIG) {
            Ok(detection) => break detection,
            Err(e) if tries < DETECT_TRIES => defmt::warn!("detect: {}; again", e),
            Err(e) => {
                defmt::error!("FAIL: detect: {}", e);
                return Err(Check::Link.exit_code());
            }
        }
    };
    match detection.firmware {
        Some(firmware) => {
            defmt::info!(
                "firmware {} ({}): {}",
                firmware.name(),
                firmware.framing(),
                detection
            );
            Ok(firmware)
        }
        None if detection.heard.bytes == 0 => {
            defmt::warn!(
                "firmware: the line is silent ({}): taken as 2020, whose link check says the rest",
                detection
            );
            Ok(Firmware::V2020)
        }
        None => {
            defmt::error!(
                "FAIL: bytes of neither firmware ({}): another device, or another baud rate?",
                detection
            );
            Err(Check::Link.exit_code())
        }
    }
}

/// A bring-up's verdict, logged (`generation`: what follows "passed" in the log, the
/// generation when it is not 2020); its exit code.
fn verdict<R: defmt::Format, W: defmt::Format>(
    result: Result<R, Failure<W>>,
    generation: &str,
) -> i32 {
    match result {
        Ok(report) => {
            defmt::info!("PASS: every check passed{}: {}", generation, report);
            0
        }
        Err(failure) => {
            defmt::error!("FAIL: {} ({})", failure.check, failure.why);
            failure.check.exit_code()
        }
    }
}

#[cfg(not(feature = "no-panic-proof"))]
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    semihosting::process::exit(101)
}

#[cfg(feature = "no-panic-proof")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    unsafe extern "Rust" {
        /// Does not exist: linking fails if any panic path survived optimisation.
        fn firmware_has_a_reachable_panic() -> !;
    }
    // SAFETY: never runs: the link fails if this call is reachable.
    unsafe { firmware_has_a_reachable_panic() }
}
