//! Size probe: the board and both v1.0.0 streaming parsers (beside `size_parsers`, the 2020
//! ones).

#![no_std]
#![no_main]

use board_qemu_an386::{probe::V1Parsers, time};
use chassis_protocol::driver::Clock;
use embedded_io::{Read, Write};

#[cortex_m_rt::entry]
fn main() -> ! {
    let mut uart = board_qemu_an386::init();
    let mut parsers = V1Parsers::new();
    let mut byte = [0u8; 1];
    loop {
        if uart.read(&mut byte).is_ok() {
            let t = time::Millis.now_ms() as u8;
            let out = parsers.push(byte[0]);
            let _ = uart.write(&[out ^ t]);
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
