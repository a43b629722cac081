//! The bring-up on an nRF52840 (nRF52840-DK, Cortex-M4F) with embassy: UARTE0 as a
//! `BufferedUarte` (P1.02 TX, P1.01 RX, 115 200 8N1) through the async driver, defmt over RTT.
//! The same 2020 bring-up as every board (`chassis_bringup::v2020::bring_up`); this file is only
//! the glue.
//!
//! embassy-nrf's `BufferedUarte` receives by EasyDMA into its ring buffer, counting bytes with
//! TIMER1 through two PPI channels (hence the timer and PPI arguments), so a read is served from
//! memory and dropping it loses nothing: the cancel-safe read the async driver's `poll` needs
//! (it races the read against the next deadline). It implements embedded-io-async 0.7 `Read +
//! Write` (and `ReadReady`, `BufRead`), not blocking embedded-io: the async driver only.
//!
//! Pins: P0.06/P0.08 are the DK's virtual COM port (its J-Link's UART), so the chassis is on
//! P1.02/P1.01; the high-frequency clock is the DK's 32 MHz crystal, for an exact baud rate.

#![no_std]
#![no_main]

use chassis_bringup::embassy::Millis;
use chassis_bringup::v2020::{Async, Plan, bring_up_and_park};
use chassis_protocol::driver::Config;
use embassy_executor::Spawner;
use embassy_nrf::buffered_uarte::{self, BufferedUarte};
use embassy_nrf::config::HfclkSource;
use embassy_nrf::{bind_interrupts, peripherals, uarte};
use embassy_time::Delay;
use {defmt_rtt as _, panic_probe as _};

bind_interrupts!(struct Irqs {
    UARTE0 => buffered_uarte::InterruptHandler<peripherals::UARTE0>;
});

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let mut chip = embassy_nrf::config::Config::default();
    chip.hfclk_source = HfclkSource::ExternalXtal;
    let p = embassy_nrf::init(chip);
    let mut config = uarte::Config::default();
    config.baudrate = uarte::Baudrate::Baud115200;
    // 256 bytes of receive buffer hold 20 ms of telemetry (even: the driver receives into its
    // two halves in turn).
    let mut tx_buf = [0u8; 64];
    let mut rx_buf = [0u8; 256];
    let uart = BufferedUarte::new(
        p.UARTE0,
        p.TIMER1,
        p.PPI_CH0,
        p.PPI_CH1,
        p.PPI_GROUP0,
        p.P1_01,
        p.P1_02,
        Irqs,
        config,
        &mut rx_buf,
        &mut tx_buf,
    );
    defmt::info!("chassis bring-up: nRF52840, UARTE0 at 115200 bps, async driver (embassy)");
    let mut link = Async::new(uart, Millis, Delay, Config::DEFAULT);
    bring_up_and_park(&mut link, &Plan::DEFAULT).await;
}
