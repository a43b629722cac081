//! The `nb` and async shells and the `embedded-io` 0.6 adapter against the simulator: the same
//! driver logic through an `embedded-hal-nb` serial port, an `embedded-io` 0.6 UART, and
//! `embedded-io-async` on a host executor.

use chassis_protocol::driver::asynch::Driver as AsyncDriver;
use chassis_protocol::driver::blocking::Driver;
use chassis_protocol::driver::io06::Io06;
use chassis_protocol::driver::nb::NbSerial;
use chassis_protocol::driver::{Config, CoreError, Error, reg};
use chassis_protocol::sim::{Board, Faults, Motion, SimClock, SimConfig, SimDelay, SimUart};
use chassis_protocol::{Register, Velocity, Write};
use core::cell::Cell;
use core::convert::Infallible;
use embedded_hal_nb::{nb, serial};
use embedded_io::{Read, ReadReady, Write as _};

/// The simulated board as an `embedded-hal-nb` serial port: a byte at a time, `WouldBlock`
/// when none is there.
struct NbPort<'t>(SimUart<'t>);

impl serial::ErrorType for NbPort<'_> {
    type Error = Infallible;
}

impl serial::Read<u8> for NbPort<'_> {
    fn read(&mut self) -> nb::Result<u8, Infallible> {
        let mut byte = [0u8];
        match self.0.read_ready() {
            Ok(true) => match self.0.read(&mut byte) {
                Ok(1) => Ok(byte[0]),
                _ => Err(nb::Error::WouldBlock),
            },
            _ => Err(nb::Error::WouldBlock),
        }
    }
}

impl serial::Write<u8> for NbPort<'_> {
    fn write(&mut self, word: u8) -> nb::Result<(), Infallible> {
        self.0.write(&[word]).map(|_| ()).map_err(nb::Error::Other)
    }

    fn flush(&mut self) -> nb::Result<(), Infallible> {
        Ok(())
    }
}

#[test]
fn nb_shell_drives_the_board() {
    let time = Cell::new(0);
    let port = NbPort(SimUart::new(Board::new(SimConfig::default()), &time));
    let mut d = Driver::new(NbSerial::new(port), SimClock(&time), Config::DEFAULT);
    d.set_velocity(Velocity::new(0, 120, -5)).unwrap();
    d.write(Write::MaxSpeed(777)).unwrap();
    assert_eq!(d.read(reg::MaxSpeed).unwrap(), 777);
    d.turn_by(900).unwrap();
    assert_eq!(d.turn_by(900), Err(Error::Core(CoreError::TurnInProgress)));
    let end = time.get() + 500;
    while time.get() < end {
        d.poll().unwrap();
    }
    assert!(d.core().imu().is_some());
    let (serial, _, _) = d.release();
    let (port, _) = serial.release();
    assert_eq!(port.0.board().total_turn_commanded(), 900);
}

#[test]
fn async_shell_drives_the_board() {
    let time = Cell::new(0);
    let uart = SimUart::new(Board::new(SimConfig::default()), &time);
    let mut d = AsyncDriver::new(uart, SimClock(&time), SimDelay(&time), Config::DEFAULT);
    embassy_futures::block_on(async {
        d.set_velocity(Velocity::new(10, 20, 30)).await.unwrap();
        assert_eq!(d.read(reg::MotorVoltage).await.unwrap(), 1_200);
        d.write(Write::SpeedKi(31)).await.unwrap();
        let settings = d.read_settings().await.unwrap();
        assert_eq!(settings.speed_ki, 31);
        d.turn_by(-300).await.unwrap();
        assert_eq!(
            d.turn_by(-300).await,
            Err(Error::Core(CoreError::TurnInProgress))
        );
        while d.turn_remaining().await.unwrap() != 0 {}
        d.turn_by(-300).await.unwrap();
    });
    assert_eq!(d.uart().board().total_turn_commanded(), -600);
    // A turn is made standing still.
    assert_eq!(
        d.uart().board().motion(),
        Motion::Velocity { x: 0, y: 0, z: 0 }
    );
}

#[test]
fn async_shell_times_out_on_a_silent_board() {
    let time = Cell::new(0);
    let mut board = Board::new(SimConfig::default());
    board.set_faults(Faults {
        replies_stopped: true,
        ..Faults::default()
    });
    let uart = SimUart::new(board, &time);
    let mut d = AsyncDriver::new(uart, SimClock(&time), SimDelay(&time), Config::DEFAULT);
    let result = embassy_futures::block_on(d.read(reg::SpeedKp));
    assert_eq!(
        result,
        Err(Error::Core(CoreError::Timeout(Register::SpeedKp)))
    );
    let waited = time.get();
    let timeout = u64::from(Config::DEFAULT.reply_timeout_ms());
    assert!((timeout..timeout + 5).contains(&waited), "{waited} ms");
}

/// The simulated board as an `embedded-io` 0.6 UART.
struct Uart06<'t>(SimUart<'t>);

impl embedded_io_06::ErrorType for Uart06<'_> {
    type Error = Infallible;
}

impl embedded_io_06::Read for Uart06<'_> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        self.0.read(buf)
    }
}

impl embedded_io_06::ReadReady for Uart06<'_> {
    fn read_ready(&mut self) -> Result<bool, Infallible> {
        self.0.read_ready()
    }
}

impl embedded_io_06::Write for Uart06<'_> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        self.0.write(buf)
    }

    fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

#[test]
fn embedded_io_06_uarts_work_through_the_adapter() {
    let time = Cell::new(0);
    let uart = Uart06(SimUart::new(Board::new(SimConfig::default()), &time));
    let mut d = Driver::new(Io06(uart), SimClock(&time), Config::DEFAULT);
    d.write(Write::GyroGain(4_242)).unwrap();
    assert_eq!(d.read(reg::GyroGain).unwrap(), 4_242);
    d.set_velocity(Velocity::new(1, 2, 3)).unwrap();
    let (Io06(uart), _, _) = d.release();
    assert_eq!(
        uart.0.board().motion(),
        Motion::Velocity { x: 1, y: 2, z: 3 }
    );
}
