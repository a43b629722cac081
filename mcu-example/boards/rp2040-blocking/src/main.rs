//! The bring-up on a Raspberry Pi Pico with no executor: rp2040-hal's UART0 (GP0 TX, GP1 RX,
//! 115 200 8N1) is an embedded-hal-nb serial port, made a blocking driver's transport by the
//! `nb` shell (`NbSerial`); the bring-up is compiled as plain blocking code (feature `blocking`
//! of `chassis-bringup`). The same bring-up as every board; this file is only the glue.

#![no_std]
#![no_main]

use chassis_bringup::v2020::{Blocking, Plan, bring_up_and_park};
use chassis_protocol::driver::{Config, nb::NbSerial};
use rp2040_hal::fugit::RateExtU32;
use rp2040_hal::uart::{DataBits, StopBits, UartConfig, UartPeripheral};
use rp2040_hal::{Clock as _, Sio, Timer, Watchdog, clocks, gpio, pac};
use {defmt_rtt as _, panic_probe as _};

/// The second-stage boot loader for the Pico's W25Q080 flash.
#[unsafe(link_section = ".boot2")]
#[used]
pub static BOOT2: [u8; 256] = rp2040_boot2::BOOT_LOADER_W25Q080;

/// The Pico's crystal.
const XOSC_HZ: u32 = 12_000_000;

#[rp2040_hal::entry]
fn main() -> ! {
    let Some(mut pac) = pac::Peripherals::take() else {
        defmt::panic!("peripherals taken twice");
    };
    let mut watchdog = Watchdog::new(pac.WATCHDOG);
    let Ok(clocks) = clocks::init_clocks_and_plls(
        XOSC_HZ,
        pac.XOSC,
        pac.CLOCKS,
        pac.PLL_SYS,
        pac.PLL_USB,
        &mut pac.RESETS,
        &mut watchdog,
    ) else {
        defmt::panic!("clocks did not start");
    };
    let sio = Sio::new(pac.SIO);
    let pins = gpio::Pins::new(
        pac.IO_BANK0,
        pac.PADS_BANK0,
        sio.gpio_bank0,
        &mut pac.RESETS,
    );
    let uart_pins = (
        pins.gpio0.into_function::<gpio::FunctionUart>(),
        pins.gpio1.into_function::<gpio::FunctionUart>(),
    );
    let uart = match UartPeripheral::new(pac.UART0, uart_pins, &mut pac.RESETS).enable(
        UartConfig::new(115_200.Hz(), DataBits::Eight, None, StopBits::One),
        clocks.peripheral_clock.freq(),
    ) {
        Ok(uart) => uart,
        Err(_) => defmt::panic!("UART0 refused 115200 8N1"),
    };
    let timer = Timer::new(pac.TIMER, &mut pac.RESETS, &clocks);
    // The driver's clock: the microsecond timer, in ms (a copy of the timer: it is a handle).
    let millis = move || timer.get_counter().ticks() / 1_000;

    defmt::info!(
        "chassis bring-up: RP2040, UART0 at 115200 bps, blocking driver over rp2040-hal (nb)"
    );
    let mut link = Blocking::new(NbSerial::new(uart), millis, Config::DEFAULT);
    bring_up_and_park(&mut link, &Plan::DEFAULT)
}
