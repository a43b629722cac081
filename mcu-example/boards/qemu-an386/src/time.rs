//! A millisecond clock on SysTick (the core's own timer: every Cortex-M has it).

use core::cell::Cell;
use cortex_m::peripheral::{SYST, syst::SystClkSource};
use cortex_m_rt::exception;
use critical_section::Mutex;

static MILLIS: Mutex<Cell<u64>> = Mutex::new(Cell::new(0));

/// Starts SysTick at one interrupt per millisecond of a `clock_hz` core clock.
pub fn start(syst: &mut SYST, clock_hz: u32) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(clock_hz / 1_000 - 1);
    syst.clear_current();
    syst.enable_counter();
    syst.enable_interrupt();
}

/// Starts SysTick as a free-running counter of core clock ticks (see [`cycles`]): the
/// instruction-count run.
pub fn start_cycles(syst: &mut SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(WRAP - 1);
    syst.clear_current();
    syst.enable_counter();
    syst.enable_interrupt();
}

/// SysTick's reload in [`start_cycles`]: 2^24, its widest.
const WRAP: u32 = 1 << 24;

/// Core clock ticks since [`start_cycles`] (the interrupt counts the wraps).
pub fn cycles() -> u64 {
    loop {
        let wraps = critical_section::with(|cs| MILLIS.borrow(cs).get());
        let current = SYST::get_current();
        // A wrap between the two reads: read again.
        if critical_section::with(|cs| MILLIS.borrow(cs).get()) == wraps {
            return wraps * u64::from(WRAP) + u64::from(WRAP - 1 - current);
        }
    }
}

#[exception]
fn SysTick() {
    critical_section::with(|cs| {
        let millis = MILLIS.borrow(cs);
        millis.set(millis.get().wrapping_add(1));
    });
}

/// Milliseconds since [`start`]: the driver's clock (a handle: copy it freely).
#[derive(Clone, Copy, Debug)]
pub struct Millis;

impl chassis_protocol::driver::Clock for Millis {
    fn now_ms(&mut self) -> u64 {
        critical_section::with(|cs| MILLIS.borrow(cs).get())
    }
}

#[cfg(feature = "log")]
defmt::timestamp!(
    "{=u64:ms}",
    critical_section::with(|cs| MILLIS.borrow(cs).get())
);
