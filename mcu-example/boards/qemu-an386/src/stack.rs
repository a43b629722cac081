//! Stack high-water mark: the stack is painted at boot and the untouched part is measured at
//! the end, so the RAM a run really needed is known (the driver and the parser live on the
//! stack: the firmware has almost no static RAM).

use core::ptr::{addr_of, read_volatile, write_volatile};

/// What an unused stack word holds.
const PAINT: u32 = 0x5AFE_C0DE;

unsafe extern "C" {
    /// The lowest address the stack may reach (cortex-m-rt: the end of static RAM).
    static mut __sheap: u32;
    /// The top of the stack (cortex-m-rt).
    static _stack_start: u32;
}

fn bottom() -> usize {
    addr_of!(__sheap) as usize
}

fn top() -> usize {
    addr_of!(_stack_start) as usize
}

/// Paints the stack below the current frame (less a margin for this function's own frame).
/// Call once, first thing in `main`.
pub fn paint() {
    let here = cortex_m::register::msp::read() as usize;
    let mut addr = bottom();
    while addr + 4 < here.saturating_sub(64) {
        // SAFETY: between the end of static RAM and below the live stack: memory nothing else
        // uses, word-aligned (cortex-m-rt aligns __sheap to 4).
        unsafe { write_volatile(addr as *mut u32, PAINT) };
        addr += 4;
    }
}

/// The most stack used since [`paint`], in bytes.
pub fn peak() -> usize {
    let mut addr = bottom();
    // SAFETY: reads of the painted region only, word-aligned.
    while addr < top() && unsafe { read_volatile(addr as *const u32) } == PAINT {
        addr += 4;
    }
    top().saturating_sub(addr)
}

/// Static RAM (`.data`, `.bss`, `.uninit`), in bytes.
pub fn static_ram() -> usize {
    bottom().saturating_sub(0x2000_0000)
}
