//! The bring-up on a Raspberry Pi Pico (RP2040, Cortex-M0+) with embassy: UART0 as a
//! `BufferedUart` (GP0 TX, GP1 RX, 115 200 8N1) through the async driver, defmt over RTT.
//! The same 2020 bring-up as every board (`chassis_bringup::v2020::bring_up`); this file is only
//! the glue.

#![no_std]
#![no_main]

use chassis_bringup::embassy::Millis;
use chassis_bringup::v2020::{Async, Plan, bring_up_and_park};
use chassis_protocol::driver::Config;
use embassy_executor::Spawner;
use embassy_rp::bind_interrupts;
use embassy_rp::peripherals::UART0;
use embassy_rp::uart::{self, BufferedUart};
use embassy_time::Delay;
use {defmt_rtt as _, panic_probe as _};

bind_interrupts!(struct Irqs {
    UART0_IRQ => uart::BufferedInterruptHandler<UART0>;
});

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_rp::init(Default::default());
    let mut config = uart::Config::default();
    config.baudrate = 115_200;
    // 256 bytes of receive buffer hold 20 ms of telemetry.
    let mut tx_buf = [0u8; 64];
    let mut rx_buf = [0u8; 256];
    let uart = BufferedUart::new(
        p.UART0,
        p.PIN_0,
        p.PIN_1,
        Irqs,
        &mut tx_buf,
        &mut rx_buf,
        config,
    );
    defmt::info!("chassis bring-up: RP2040, UART0 at 115200 bps, async driver (embassy)");
    let mut link = Async::new(uart, Millis, Delay, Config::DEFAULT);
    bring_up_and_park(&mut link, &Plan::DEFAULT).await;
}
