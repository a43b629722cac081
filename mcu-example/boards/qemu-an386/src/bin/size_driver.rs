//! Size probe: the board and the blocking driver, every call used (with the parser and the
//! builders it needs).

#![no_std]
#![no_main]

use board_qemu_an386::time;
use chassis_protocol::driver::{Config, blocking::Driver, reg};
use chassis_protocol::{Action, Motors, Velocity, Write};
use embedded_io::Write as _;

#[cortex_m_rt::entry]
fn main() -> ! {
    let uart = board_qemu_an386::init();
    let mut driver = Driver::new(uart, time::Millis, Config::DEFAULT);
    let mut step = 0u8;
    loop {
        let out: u8 = match driver.poll() {
            Ok(Some(_)) => continue,
            Ok(None) => {
                step = step.wrapping_add(1);
                let result = match step % 8 {
                    0 => driver
                        .set_velocity(Velocity::new(0, i32::from(step), 0))
                        .map(|_| 0),
                    1 => driver
                        .set_motors(Motors::closed_loop([i32::from(step); 4]))
                        .map(|_| 1),
                    2 => driver.turn_by(i32::from(step)).map(|_| 2),
                    3 => driver.read(reg::MaxSpeed).map(|v| v as u8),
                    4 => driver.read_settings().map(|s| s.max_speed as u8),
                    5 => driver.write(Write::MaxSpeed(u16::from(step))).map(|_| 5),
                    6 => driver.action(Action::Store).map(|_| 6),
                    _ => driver.stop().map(|_| 7),
                };
                result.unwrap_or(0xEE)
            }
            Err(_) => 0xFF,
        };
        let _ = driver.uart_mut().write(&[out]);
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
