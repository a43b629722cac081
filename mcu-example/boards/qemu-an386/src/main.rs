//! The bring-up on QEMU's mps2-an386 (Cortex-M4 at 25 MHz): UART0 is the link to the chassis
//! (the simulated one, over TCP), defmt goes out over semihosting, and the exit status is the
//! verdict: 0 when every check passed, else [`Check::exit_code`] of the one that failed.
//!
//! Run it with `cargo xtask demo` from the repository root, or `cargo run --release` here.

#![no_std]
#![no_main]

use board_qemu_an386::{stack, time};
use chassis_bringup::{Plan, Report, bring_up, link::Blocking};
use chassis_protocol::driver::Config;
use cortex_m_rt::entry;
#[cfg(feature = "log")]
use defmt_semihosting as _;

/// The driver's settings for this board: a microcontroller's, except the quiet line. The
/// emulated UART is fed by another process over TCP, which hands bytes over in bursts when the
/// host is busy; a gap of a few ms inside a frame there is the host, not the board, and a quiet
/// line taken for a frame boundary would throw a frame away. 10 ms is longer than those gaps
/// and still far shorter than the failsafe (100 ms).
const CONFIG: Config = Config {
    idle_ms: 10,
    ..Config::DEFAULT
};

#[entry]
fn main() -> ! {
    stack::paint();
    let uart = board_qemu_an386::init();
    defmt::info!(
        "chassis bring-up: QEMU mps2-an386, Cortex-M4, UART0 at 115200 bps, blocking driver"
    );

    let mut link = Blocking::new(uart, time::Millis, CONFIG);
    let code = match bring_up(&mut link, &Plan::DEFAULT) {
        Ok(report) => {
            log_report(&report);
            0
        }
        Err(failure) => {
            defmt::error!("FAIL: {} ({})", failure.check, failure.why);
            failure.check.exit_code()
        }
    };
    defmt::info!(
        "RAM: {} B static + {} B stack at its peak",
        stack::static_ram(),
        stack::peak()
    );
    semihosting::process::exit(code)
}

fn log_report(report: &Report) {
    defmt::info!("PASS: every check passed: {}", report);
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
