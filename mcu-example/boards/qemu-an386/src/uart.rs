//! The ARM CMSDK APB UART (UART0 of mps2-an386, at `0x4000_4000`) as an embedded-io 0.7 serial
//! port: what a HAL would give. One byte of receive buffer, no FIFO.

use core::ptr;

/// UART0's registers.
const BASE: usize = 0x4000_4000;
const DATA: usize = BASE;
const STATE: usize = BASE + 0x04;
const CTRL: usize = BASE + 0x08;
const BAUDDIV: usize = BASE + 0x10;

const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const STATE_RX_OVERRUN: u32 = 1 << 3;
const CTRL_TX_EN: u32 = 1 << 0;
const CTRL_RX_EN: u32 = 1 << 1;

fn read(reg: usize) -> u32 {
    // SAFETY: `reg` is one of the UART's word-aligned registers, always mapped on this machine.
    unsafe { ptr::read_volatile(reg as *const u32) }
}

fn write(reg: usize, value: u32) {
    // SAFETY: as in `read`; the UART is owned by the one `Uart0` value.
    unsafe { ptr::write_volatile(reg as *mut u32, value) }
}

/// A receive overrun: a byte came while the last one was still unread (the board cannot resend
/// it; the driver's parser resynchronises).
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub struct Overrun;

impl core::fmt::Display for Overrun {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("UART receive overrun")
    }
}

impl core::error::Error for Overrun {}

impl embedded_io::Error for Overrun {
    fn kind(&self) -> embedded_io::ErrorKind {
        embedded_io::ErrorKind::Other
    }
}

/// UART0, enabled for both directions.
pub struct Uart0(());

impl Uart0 {
    /// Sets the baud divider for `baud` from `clock_hz` and enables both directions.
    pub fn new(clock_hz: u32, baud: u32) -> Self {
        write(BAUDDIV, clock_hz / baud.max(1));
        write(CTRL, CTRL_TX_EN | CTRL_RX_EN);
        Uart0(())
    }
}

impl embedded_io::ErrorType for Uart0 {
    type Error = Overrun;
}

impl embedded_io::ReadReady for Uart0 {
    fn read_ready(&mut self) -> Result<bool, Overrun> {
        Ok(read(STATE) & STATE_RX_FULL != 0)
    }
}

impl embedded_io::Read for Uart0 {
    /// Blocks until at least one byte is in, then takes what is there (one byte: there is no
    /// FIFO). An overrun is reported once, then cleared.
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Overrun> {
        let Some(first) = buf.first_mut() else {
            return Ok(0);
        };
        loop {
            let state = read(STATE);
            if state & STATE_RX_OVERRUN != 0 {
                write(STATE, STATE_RX_OVERRUN);
                return Err(Overrun);
            }
            if state & STATE_RX_FULL != 0 {
                *first = read(DATA) as u8;
                return Ok(1);
            }
        }
    }
}

impl embedded_io::Write for Uart0 {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Overrun> {
        for &byte in buf {
            while read(STATE) & STATE_TX_FULL != 0 {}
            write(DATA, u32::from(byte));
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> Result<(), Overrun> {
        while read(STATE) & STATE_TX_FULL != 0 {}
        Ok(())
    }
}
