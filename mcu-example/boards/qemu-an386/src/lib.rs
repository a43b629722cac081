//! Board support for QEMU's mps2-an386 (Cortex-M4 at 25 MHz): UART0 (the link to the chassis)
//! and a SysTick millisecond clock. The binaries: `bringup` (the bring-up, `src/main.rs`), the
//! size probes (`src/bin/size_*.rs`, measured by `cargo xtask size`) and the instruction-count
//! runs of the board → master parsers, 2020 and v1.0.0 (`src/bin/icount.rs`,
//! `src/bin/icount_v1.rs`: the work of both in [`icount`]).

#![no_std]

pub mod icount;
pub mod probe;
pub mod stack;
pub mod time;
pub mod uart;

/// The core clock of mps2-an386.
pub const CLOCK_HZ: u32 = 25_000_000;

/// Brings the board up: UART0 at 115 200 bps, then SysTick as the millisecond clock (right
/// after the UART: QEMU's CMSDK UART delivers its first byte late otherwise). Call once, first.
pub fn init() -> uart::Uart0 {
    // SAFETY: the core peripherals are taken here once, before anything else runs.
    let mut core = unsafe { cortex_m::Peripherals::steal() };
    let uart = uart::Uart0::new(CLOCK_HZ, 115_200);
    time::start(&mut core.SYST, CLOCK_HZ);
    uart
}
