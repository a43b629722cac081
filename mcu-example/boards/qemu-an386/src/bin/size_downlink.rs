//! Size probe: the board and the 2020 board → master parser alone (beside `size_v1_downlink`).

#![no_std]
#![no_main]

use board_qemu_an386::{probe::Downlink2020, time};
use chassis_protocol::driver::Clock;
use embedded_io::{Read, Write};

#[cortex_m_rt::entry]
fn main() -> ! {
    let mut uart = board_qemu_an386::init();
    let mut parser = Downlink2020::new();
    let mut byte = [0u8; 1];
    loop {
        if uart.read(&mut byte).is_ok() {
            let t = time::Millis.now_ms() as u8;
            let out = parser.push(byte[0], t == 0);
            let _ = uart.write(&[out ^ t]);
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
