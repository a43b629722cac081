//! The bring-up on an ESP32-C3 (RISC-V) with esp-hal and no executor: UART1 (GPIO4 TX, GPIO5
//! RX, 115 200 8N1) is an embedded-io 0.7 `Read + Write + ReadReady` port (esp-hal's `Uart`,
//! with its `unstable` feature), the blocking driver's transport as it is; the bring-up is
//! compiled as plain blocking code (feature `blocking` of `chassis-bringup`). The log is defmt
//! through esp-println (USB-Serial-JTAG when a host is on the USB port, else UART0), decoded by
//! `espflash flash --monitor`. The same bring-up as every board; this file is only the glue.
//!
//! Why blocking and not esp-rtos's embassy executor: the blocking shell needs nothing but the
//! UART and a clock, the bring-up then has no future (and no executor, timer queue or
//! interrupt handler of its own), and a loop that never sleeps for more than a log line reads
//! the 128-byte receive FIFO long before it fills (11 ms of a saturated 115 200 bps link).
//! The async way builds on stable as well (esp-rtos 0.4 with `embassy`, on embassy-executor
//! 0.10; esp-hal's `Uart<Async>` has `read_async` and `write_async`, both documented
//! cancel-safe, as the async driver needs), but a trial build of the same bring-up that way
//! took 87.8 KB of flash and 9.4 KB of RAM, against this board's 66.1 KB and 4.4 KB.
//!
//! Pins: GPIO20/GPIO21 are UART0's (the USB-UART bridge of the DevKits, and where the ROM boot
//! loader prints at reset), GPIO18/19 are USB, GPIO2/8/9 are strapping pins: GPIO4 and GPIO5
//! are free on the DevKitM-1, the DevKitC-02 and the SuperMini boards alike.

#![no_std]
#![no_main]

use chassis_bringup::v2020::{Blocking, Plan, bring_up_and_park};
use chassis_protocol::driver::Config;
use esp_hal::clock::CpuClock;
use esp_hal::time::Instant;
use esp_hal::uart::{self, Uart};
use {esp_backtrace as _, esp_println as _};

// The application descriptor the ESP-IDF second-stage boot loader checks (espflash flashes that
// boot loader along with the firmware).
esp_bootloader_esp_idf::esp_app_desc!();

#[esp_hal::main]
fn main() -> ! {
    let p = esp_hal::init(esp_hal::Config::default().with_cpu_clock(CpuClock::max()));
    let config = uart::Config::default().with_baudrate(115_200);
    let uart = match Uart::new(p.UART1, config) {
        Ok(uart) => uart.with_tx(p.GPIO4).with_rx(p.GPIO5),
        Err(e) => defmt::panic!("UART1 refused 115200 8N1: {}", e),
    };
    // The driver's clock: esp-hal's system timer, in ms (a closure without captures: a handle).
    let millis = || Instant::now().duration_since_epoch().as_millis();

    defmt::info!("chassis bring-up: ESP32-C3, UART1 at 115200 bps, blocking driver over esp-hal");
    let mut link = Blocking::new(uart, millis, Config::DEFAULT);
    bring_up_and_park(&mut link, &Plan::DEFAULT)
}
