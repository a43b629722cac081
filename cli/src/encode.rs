//! `chassis encode`: a master → board frame from arguments, as uppercase hex pairs. A value out
//! of its field's range is an error, never a wrapped or saturated number.

use crate::names::{ActionName, RegisterName};
use crate::value::{parse_i32, parse_u32};
use chassis_protocol::{Motors, Setting, Turn, Velocity, Write};
use clap::{Args, Subcommand};

/// X, Y and Z of a velocity, each ±65 535 (decimal or 0x hex).
#[derive(Debug, Args)]
pub struct Axes {
    /// X: sideways.
    #[arg(long, default_value = "0", allow_hyphen_values = true)]
    pub x: String,
    /// Y: forward.
    #[arg(long, default_value = "0", allow_hyphen_values = true)]
    pub y: String,
    /// Z: rotation (`encode velocity --angle`: the angle to turn, in 0.1°).
    #[arg(long, default_value = "0", allow_hyphen_values = true)]
    pub z: String,
}

impl Axes {
    /// The three values, range-checked.
    pub fn values(&self) -> Result<(i32, i32, i32), String> {
        const MAG: i64 = 65_535;
        Ok((
            parse_i32(&self.x, "x", -MAG, MAG)?,
            parse_i32(&self.y, "y", -MAG, MAG)?,
            parse_i32(&self.z, "z", -MAG, MAG)?,
        ))
    }
}

/// The frames `encode` builds.
#[derive(Debug, Subcommand)]
pub enum Frame {
    /// Mode 01: chassis velocity (X sideways, Y forward, Z rotation); with --angle, a relative
    /// turn of Z × 0.1° that the board ADDS to the pending angle.
    Velocity {
        #[command(flatten)]
        axes: Axes,
        /// Angle mode (bit 4): Z is an angle to add, not a rotation speed.
        #[arg(long)]
        angle: bool,
    },
    /// Modes 02 / 03: each motor on its own (closed loop: speeds ±65 535; --open-loop: duty in
    /// 0.01 %, ±10 000).
    Motors {
        /// MOTO1.
        #[arg(long, default_value = "0", allow_hyphen_values = true)]
        m1: String,
        /// MOTO2.
        #[arg(long, default_value = "0", allow_hyphen_values = true)]
        m2: String,
        /// MOTO3.
        #[arg(long, default_value = "0", allow_hyphen_values = true)]
        m3: String,
        /// MOTO4.
        #[arg(long, default_value = "0", allow_hyphen_values = true)]
        m4: String,
        /// Open loop (mode 03): duty cycles.
        #[arg(long)]
        open_loop: bool,
    },
    /// 2A: an action.
    Action {
        /// What to do.
        action: ActionName,
    },
    /// 2B: a register write (battery-range takes FULL and CUTOFF, both in 0.01 V).
    Write {
        /// The register.
        register: RegisterName,
        /// The value (decimal or 0x hex).
        value: String,
        /// battery-range only: the cut-off voltage in 0.01 V.
        cutoff: Option<String>,
    },
    /// 2C / 2D: a register read.
    Read {
        /// The register (pending-angle: 2D).
        register: RegisterName,
    },
}

/// The frame's bytes.
pub fn encode(frame: &Frame) -> Result<Vec<u8>, String> {
    const MAG: i64 = 65_535;
    Ok(match frame {
        Frame::Velocity { axes, angle } => {
            let (x, y, z) = axes.values()?;
            if *angle {
                Turn::new(x, y, z).encode().to_vec()
            } else {
                Velocity::new(x, y, z).encode().to_vec()
            }
        }
        Frame::Motors {
            m1,
            m2,
            m3,
            m4,
            open_loop,
        } => {
            let limit = if *open_loop { 10_000 } else { MAG };
            let mut values = [0i32; 4];
            for (slot, (text, name)) in
                values
                    .iter_mut()
                    .zip([(m1, "m1"), (m2, "m2"), (m3, "m3"), (m4, "m4")])
            {
                *slot = parse_i32(text, name, -limit, limit)?;
            }
            if *open_loop {
                Motors::open_loop_duty(values).encode().to_vec()
            } else {
                Motors::closed_loop(values).encode().to_vec()
            }
        }
        Frame::Action { action } => Setting::Action(action.action()).encode().to_vec(),
        Frame::Write {
            register,
            value,
            cutoff,
        } => Setting::Write(write_of(*register, value, cutoff.as_deref())?)
            .encode()
            .to_vec(),
        Frame::Read { register } => Setting::Read(register.register()).encode().to_vec(),
    })
}

/// The write of `value` (and `cutoff`, for the battery range) to `register`, range-checked.
pub fn write_of(
    register: RegisterName,
    value: &str,
    cutoff: Option<&str>,
) -> Result<Write, String> {
    let reg = register.register();
    if reg == chassis_protocol::Register::PendingAngle {
        return Err("pending-angle is read only".into());
    }
    let name = register.name();
    if reg == chassis_protocol::Register::BatteryRange {
        let Some(cutoff) = cutoff else {
            return Err("battery-range takes two values: FULL CUTOFF (0.01 V each)".into());
        };
        let full = parse_u32(value, "full", 0, u32::from(u16::MAX))?;
        let cut = parse_u32(cutoff, "cutoff", 0, u32::from(u16::MAX))?;
        let write = Write::BatteryRange {
            full_centivolts: full as u16,
            cutoff_centivolts: cut as u16,
        };
        chassis_protocol::driver::host::check_write(write)?;
        return Ok(write);
    }
    if cutoff.is_some() {
        return Err(format!("{name} takes one value"));
    }
    let max = match reg {
        chassis_protocol::Register::SpeedKp
        | chassis_protocol::Register::SpeedKi
        | chassis_protocol::Register::GyroGain
        | chassis_protocol::Register::SystemMode => u32::MAX,
        _ => u32::from(u16::MAX),
    };
    let v = parse_u32(value, name, 0, max)?;
    Write::from_value(reg, v).ok_or_else(|| format!("{v} is not a value of {name}"))
}

/// Uppercase hex pairs separated by spaces.
pub fn hex(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect::<Vec<_>>()
        .join(" ")
}
