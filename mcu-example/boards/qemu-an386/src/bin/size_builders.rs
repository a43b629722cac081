//! Size probe: the board and every master → board frame builder.

#![no_std]
#![no_main]

use board_qemu_an386::probe;
use embedded_io::Read;

#[cortex_m_rt::entry]
fn main() -> ! {
    let mut uart = board_qemu_an386::init();
    let mut input = [0u8; 4];
    loop {
        if uart.read_exact(&mut input).is_ok() {
            probe::build(&mut uart, input);
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
