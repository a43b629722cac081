//! The bring-up on an STM32F411 (Nucleo-F411RE, Black Pill) with embassy: USART1 as a
//! `BufferedUart` (PA9 TX, PA10 RX, 115 200 8N1) through the async driver, defmt over RTT.
//! The same 2020 bring-up as every board (`chassis_bringup::v2020::bring_up`); this file is only
//! the glue.

#![no_std]
#![no_main]

use chassis_bringup::embassy::Millis;
use chassis_bringup::v2020::{Async, Plan, bring_up_and_park};
use chassis_protocol::driver::Config;
use embassy_executor::Spawner;
use embassy_stm32::usart::{self, BufferedUart};
use embassy_stm32::{bind_interrupts, peripherals};
use embassy_time::Delay;
use {defmt_rtt as _, panic_probe as _};

bind_interrupts!(struct Irqs {
    USART1 => usart::BufferedInterruptHandler<peripherals::USART1>;
});

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_stm32::init(Default::default());
    let mut config = usart::Config::default();
    config.baudrate = 115_200;
    // A second of telemetry is 1 782 bytes: 256 bytes of receive buffer hold 20 ms of it, far
    // more than the loop ever leaves unread.
    let mut tx_buf = [0u8; 64];
    let mut rx_buf = [0u8; 256];
    let uart = match BufferedUart::new(
        p.USART1,
        p.PA10,
        p.PA9,
        &mut tx_buf,
        &mut rx_buf,
        Irqs,
        config,
    ) {
        Ok(uart) => uart,
        Err(e) => {
            defmt::error!("USART1 configuration refused: {}", e);
            return;
        }
    };
    defmt::info!("chassis bring-up: STM32F411, USART1 at 115200 bps, async driver (embassy)");
    let mut link = Async::new(uart, Millis, Delay, Config::DEFAULT);
    bring_up_and_park(&mut link, &Plan::DEFAULT).await;
}
