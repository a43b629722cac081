//! Size probe: the board and the v1.0.0 board → master parser (`chassis_protocol::v1`).

#![no_std]
#![no_main]

use board_qemu_an386::{probe::V1Downlink, time};
use chassis_protocol::driver::Clock;
use embedded_io::{Read, Write};

#[cortex_m_rt::entry]
fn main() -> ! {
    let mut uart = board_qemu_an386::init();
    let mut parser = V1Downlink::new();
    let mut byte = [0u8; 1];
    loop {
        if uart.read(&mut byte).is_ok() {
            let t = time::Millis.now_ms() as u8;
            let out = parser.push(byte[0]);
            let _ = uart.write(&[out ^ t]);
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
