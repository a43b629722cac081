//! The work of the size probes (`src/bin/size_*.rs`): each probe runs the board's loop with
//! some of these, and `cargo xtask size` subtracts the board alone from each. Inputs come from
//! the UART and results go back to it, so nothing is optimised away.

use crate::uart::Uart0;
use chassis_protocol::v1;
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

/// The 2020 board → master parser alone.
pub struct Downlink2020 {
    down: DownlinkParser,
}

impl Downlink2020 {
    /// A fresh parser.
    pub const fn new() -> Self {
        Downlink2020 {
            down: DownlinkParser::new(),
        }
    }

    /// Feeds `byte` (and a quiet line when `quiet`); a byte from every field of what came out.
    pub fn push(&mut self, byte: u8, quiet: bool) -> u8 {
        if quiet {
            let _ = self.down.quiet(1);
        }
        match self.down.push(byte) {
            Some(Downlink::Imu(f)) => f.gyro[2] as u8 ^ f.accel[0] as u8,
            Some(Downlink::Encoders(f)) => f.ticks[3] as u8,
            Some(Downlink::Battery(f)) => f.centivolts as u8 ^ f.percent as u8,
            Some(Downlink::Reply(r)) => r.value as u8 ^ r.code,
            None => 0,
        }
    }
}

impl Default for Downlink2020 {
    fn default() -> Self {
        Self::new()
    }
}

/// A byte from every field of a v1.0.0 board → master frame.
fn v1_fields(frame: &v1::Downlink) -> u8 {
    match frame {
        v1::Downlink::Telemetry(t) => t
            .velocity
            .iter()
            .chain(&t.accel)
            .chain(&t.gyro)
            .chain(&t.quaternion)
            .chain(core::iter::once(&t.battery_mv))
            .fold(0u8, |acc, v| acc ^ *v as u8),
        v1::Downlink::Reply(r) => r.payload.iter().fold(r.request.code(), |acc, b| acc ^ b),
    }
}

/// The v1.0.0 board → master parser.
pub struct V1Downlink {
    down: v1::DownlinkParser,
}

impl V1Downlink {
    /// A fresh parser.
    pub const fn new() -> Self {
        V1Downlink {
            down: v1::DownlinkParser::new(),
        }
    }

    /// Feeds `byte`; a byte from every field of what came out (the frame it completes and any
    /// found after it among the bytes held).
    pub fn push(&mut self, byte: u8) -> u8 {
        let mut out = 0;
        let mut next = self.down.push(byte);
        while let Some(frame) = next {
            out ^= v1_fields(&frame);
            next = self.down.poll();
        }
        out
    }
}

impl Default for V1Downlink {
    fn default() -> Self {
        Self::new()
    }
}

/// Both v1.0.0 parsers.
pub struct V1Parsers {
    down: V1Downlink,
    up: v1::UplinkParser,
}

impl V1Parsers {
    /// Both parsers, fresh.
    pub const fn new() -> Self {
        V1Parsers {
            down: V1Downlink::new(),
            up: v1::UplinkParser::new(),
        }
    }

    /// Feeds `byte` to both parsers; a byte from every field of what came out.
    pub fn push(&mut self, byte: u8) -> u8 {
        let up = match self.up.push(byte) {
            Some(c) => c.encode().iter().fold(0, |acc, b| acc ^ b),
            None => 0,
        };
        self.down.push(byte) ^ up
    }
}

impl Default for V1Parsers {
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
