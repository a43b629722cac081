//! Size probe: the board, both streaming parsers and every frame builder (the budget: these two
//! under 4 KiB of flash).

#![no_std]
#![no_main]

use board_qemu_an386::{probe, time};
use chassis_protocol::driver::Clock;
use embedded_io::{Read, Write};

#[cortex_m_rt::entry]
fn main() -> ! {
    let mut uart = board_qemu_an386::init();
    let mut parsers = probe::Parsers::new();
    let mut input = [0u8; 4];
    loop {
        if uart.read_exact(&mut input).is_ok() {
            let t = time::Millis.now_ms() as u8;
            let out = parsers.push(input[0], t == 0);
            if out == 0 {
                probe::build(&mut uart, input);
            } else {
                let _ = uart.write(&[out]);
            }
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
