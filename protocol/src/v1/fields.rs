//! The settings frames, and their fields by name (as the `chassis` command and the Python
//! package spell them).

use super::{Command, Geometry, Pid, Readback, Reply, SystemSettings};

/// A settings frame (what the driver's `write_settings` writes, confirmed by its readback).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Settings {
    /// `0x23`, read back by `0x33`.
    System(SystemSettings),
    /// `0x24`, read back by `0x34`.
    Geometry(Geometry),
    /// `0x40`, read back by `0x50`.
    Pid(Pid),
}

impl Settings {
    /// The frame.
    #[must_use]
    pub const fn command(&self) -> Command {
        match *self {
            Settings::System(s) => Command::System(s),
            Settings::Geometry(g) => Command::Geometry(g),
            Settings::Pid(p) => Command::Pid(p),
        }
    }

    /// The readback that shows it.
    #[must_use]
    pub const fn readback(&self) -> Readback {
        match self {
            Settings::System(_) => Readback::System,
            Settings::Geometry(_) => Readback::Geometry,
            Settings::Pid(_) => Readback::Pid,
        }
    }

    /// Whether `reply` carries these settings.
    #[must_use]
    pub fn shown_by(&self, reply: &Reply) -> bool {
        match self {
            Settings::System(s) => reply.system() == Some(*s),
            Settings::Geometry(g) => reply.geometry() == Some(*g),
            Settings::Pid(p) => reply.pid() == Some(*p),
        }
    }
}

impl Readback {
    /// Its name as the `chassis` command spells it: `system`, `geometry`, `body-velocity`,
    /// `motor-speeds`, `pid`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Readback::System => "system",
            Readback::Geometry => "geometry",
            Readback::BodyVelocity => "body-velocity",
            Readback::MotorSpeeds => "motor-speeds",
            Readback::Pid => "pid",
        }
    }

    /// The readback of a [`name`](Readback::name).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Readback> {
        Readback::ALL.into_iter().find(|r| r.name() == name)
    }
}

/// The settings fields by name, with the readback (and the settings frame) that holds each.
pub const FIELDS: [(&str, Readback); 14] = [
    ("motor-directions", Readback::System),
    ("encoder-directions", Readback::System),
    ("pwm-max", Readback::System),
    ("pwm-min", Readback::System),
    ("encoder-ppr", Readback::System),
    ("wheel-spacing", Readback::Geometry),
    ("axle-spacing", Readback::Geometry),
    ("gear-ratio", Readback::Geometry),
    ("wheel-diameter", Readback::Geometry),
    ("position-kp", Readback::Pid),
    ("position-ki", Readback::Pid),
    ("position-kd", Readback::Pid),
    ("velocity-kp", Readback::Pid),
    ("velocity-ki", Readback::Pid),
];

/// The readback that holds the field `name`.
#[must_use]
pub fn field_readback(name: &str) -> Option<Readback> {
    FIELDS.iter().find(|(n, _)| *n == name).map(|(_, r)| *r)
}

/// Why a field cannot be set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FieldError {
    /// No field has this name in this reply.
    NotHere,
    /// The field is a byte (a bit field): 0..=255.
    OutOfRange,
}

impl Reply {
    /// The value of the settings field `name` in this reply (`None` if the reply does not
    /// hold it).
    #[must_use]
    pub fn field(&self, name: &str) -> Option<u16> {
        let s = self.system();
        let g = self.geometry();
        let p = self.pid();
        Some(match name {
            "motor-directions" => u16::from(s?.motor_directions),
            "encoder-directions" => u16::from(s?.encoder_directions),
            "pwm-max" => s?.pwm_max,
            "pwm-min" => s?.pwm_min,
            "encoder-ppr" => s?.encoder_ppr,
            "wheel-spacing" => g?.wheel_spacing_mm,
            "axle-spacing" => g?.axle_spacing_mm,
            "gear-ratio" => g?.gear_ratio,
            "wheel-diameter" => g?.wheel_diameter_mm,
            "position-kp" => p?.position_kp,
            "position-ki" => p?.position_ki,
            "position-kd" => p?.position_kd,
            "velocity-kp" => p?.velocity_kp,
            "velocity-ki" => p?.velocity_ki,
            _ => return None,
        })
    }

    /// The settings this reply shows, with the field `name` set to `value`: what to write to
    /// change one field and keep the rest as read.
    pub fn with_field(&self, name: &str, value: u16) -> Result<Settings, FieldError> {
        let byte = || u8::try_from(value).map_err(|_| FieldError::OutOfRange);
        if let Some(mut s) = self.system() {
            match name {
                "motor-directions" => s.motor_directions = byte()?,
                "encoder-directions" => s.encoder_directions = byte()?,
                "pwm-max" => s.pwm_max = value,
                "pwm-min" => s.pwm_min = value,
                "encoder-ppr" => s.encoder_ppr = value,
                _ => return Err(FieldError::NotHere),
            }
            return Ok(Settings::System(s));
        }
        if let Some(mut g) = self.geometry() {
            match name {
                "wheel-spacing" => g.wheel_spacing_mm = value,
                "axle-spacing" => g.axle_spacing_mm = value,
                "gear-ratio" => g.gear_ratio = value,
                "wheel-diameter" => g.wheel_diameter_mm = value,
                _ => return Err(FieldError::NotHere),
            }
            return Ok(Settings::Geometry(g));
        }
        if let Some(mut p) = self.pid() {
            match name {
                "position-kp" => p.position_kp = value,
                "position-ki" => p.position_ki = value,
                "position-kd" => p.position_kd = value,
                "velocity-kp" => p.velocity_kp = value,
                "velocity-ki" => p.velocity_ki = value,
                _ => return Err(FieldError::NotHere),
            }
            return Ok(Settings::Pid(p));
        }
        Err(FieldError::NotHere)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_reads_and_sets_in_its_own_frame_only() {
        for (name, readback) in FIELDS {
            let reply = Reply {
                request: readback,
                payload: [0; 10],
            };
            assert_eq!(reply.field(name), Some(0), "{name}");
            let set = reply.with_field(name, 200).unwrap();
            assert_eq!(set.readback(), readback);
            assert!(matches!(
                set.command(),
                Command::System(_) | Command::Geometry(_) | Command::Pid(_)
            ));
            // The frame written reads back with the field changed.
            let back = Reply {
                request: readback,
                payload: {
                    let bytes = set.command().encode();
                    let mut p = [0u8; 10];
                    p.copy_from_slice(&bytes[2..12]);
                    p
                },
            };
            assert_eq!(back.field(name), Some(200), "{name}");
            for (other, r) in FIELDS {
                if r != readback {
                    assert_eq!(reply.field(other), None);
                    assert_eq!(reply.with_field(other, 1), Err(FieldError::NotHere));
                }
            }
        }
        let system = Reply {
            request: Readback::System,
            payload: [0; 10],
        };
        assert_eq!(
            system.with_field("motor-directions", 256),
            Err(FieldError::OutOfRange)
        );
        for r in Readback::ALL {
            assert_eq!(Readback::from_name(r.name()), Some(r));
        }
    }
}
