//! The work of the size probes (`src/bin/size_*.rs`): each probe runs the board's loop with
//! some of these, and `cargo xtask size` subtracts the board alone from each. Inputs come from
//! the UART and results go back to it, so nothing is optimised away.

use crate::uart::Uart0;
use chassis_protocol::{
    Action, Command, Downlink, DownlinkParser, Motors, Register, Setting, Turn, UplinkParser,
    Velocity, Write,
};
use embedded_io::Write as _;

/// Both streaming parsers.
pub struct Parsers {
    down: DownlinkParser,
    up: UplinkParser,
}

impl Parsers {
    /// Both parsers, fresh.
    pub const fn new() -> Self {
        Parsers {
            down: DownlinkParser::new(),
            up: UplinkParser::new(),
        }
    }

    /// Feeds `byte` to both parsers (and a quiet line when `quiet`); a byte from every field
    /// of what came out.
    pub fn push(&mut self, byte: u8, quiet: bool) -> u8 {
        if quiet {
            let _ = self.down.quiet(1);
        }
        let down = match self.down.push(byte) {
            Some(Downlink::Imu(f)) => f.gyro[2] as u8 ^ f.accel[0] as u8,
            Some(Downlink::Encoders(f)) => f.ticks[3] as u8,
            Some(Downlink::Battery(f)) => f.centivolts as u8 ^ f.percent as u8,
            Some(Downlink::Reply(r)) => r.value as u8 ^ r.code,
            None => 0,
        };
        let up = match self.up.push(byte) {
            Some(Command::Velocity(v)) => v.z as u8 ^ v.x as u8,
            Some(Command::Turn(t)) => t.encode()[4],
            Some(Command::Motors(m)) => m.values[0] as u8,
            Some(Command::Setting(s)) => s.encode()[4],
            None => 0,
        };
        down ^ up
    }
}

impl Default for Parsers {
    fn default() -> Self {
        Self::new()
    }
}

/// Builds the frame `input[0]` selects from the values in `input` and sends it.
pub fn build(uart: &mut Uart0, input: [u8; 4]) {
    let v = i32::from(i16::from_be_bytes([input[1], input[2]]));
    let u = u32::from_be_bytes(input);
    let register = Register::from_code(input[3]).unwrap_or(Register::PendingAngle);
    let _ = match input[0] % 8 {
        0 => uart.write_all(&Velocity::new(v, -v, v / 2).encode()),
        1 => uart.write_all(&Turn::by_deci_degrees(v).encode()),
        2 => uart.write_all(&Motors::closed_loop([v, -v, v, -v]).encode()),
        3 => uart.write_all(&Motors::open_loop_duty([v, v, -v, -v]).encode()),
        4 => uart.write_all(&Setting::Action(Action::from_number(input[3].into())).encode()),
        5 => match Write::from_value(register, u) {
            Some(write) => uart.write_all(&Setting::Write(write).encode()),
            None => Ok(()),
        },
        _ => uart.write_all(&Setting::Read(register).encode()),
    };
}
