//! Unit conversions, where the spec states the unit: 0.01 V, 0.1°, 0.01 %, 0.00001 (gyro gain).
//!
//! The frames carry integers in these units (the names say so: `centivolts`, `deci_degrees`,
//! `centi_percent`); these helpers convert to and from floating point, rounding to nearest and
//! saturating. On a Cortex-M0+ they pull in soft-float: use the integers in a tight loop.

/// 0.01 V → V.
#[must_use]
pub fn centivolts_to_volts(centivolts: u16) -> f32 {
    f32::from(centivolts) / 100.0
}

/// V → 0.01 V, rounded, saturating at 0 and 655.35 V.
#[must_use]
pub fn volts_to_centivolts(volts: f32) -> u16 {
    saturate_u16(volts * 100.0)
}

/// 0.1° → degrees.
#[must_use]
pub fn deci_degrees_to_degrees(deci_degrees: i32) -> f32 {
    deci_degrees as f32 / 10.0
}

/// Degrees → 0.1°, rounded, saturating.
#[must_use]
pub fn degrees_to_deci_degrees(degrees: f32) -> i32 {
    round_i32(degrees * 10.0)
}

/// Percent → 0.01 % duty, rounded, clamped to ±100.00 %.
#[must_use]
pub fn percent_to_centi_percent(percent: f32) -> i32 {
    round_i32((percent * 100.0).clamp(-10_000.0, 10_000.0))
}

/// Gyro compensation gain in units of 0.00001 → the gain.
#[must_use]
pub fn gyro_gain_to_f32(raw: u32) -> f32 {
    raw as f32 / 100_000.0
}

/// A gyro compensation gain → units of 0.00001, rounded, saturating.
#[must_use]
pub fn gyro_gain_from_f32(gain: f32) -> u32 {
    let scaled = gain * 100_000.0 + 0.5;
    if scaled.is_nan() { 0 } else { scaled as u32 }
}

/// Rounds half away from zero; `as` saturates, and NaN becomes 0.
fn round_i32(value: f32) -> i32 {
    if value.is_nan() {
        0
    } else if value < 0.0 {
        (value - 0.5) as i32
    } else {
        (value + 0.5) as i32
    }
}

fn saturate_u16(value: f32) -> u16 {
    let rounded = value + 0.5;
    if rounded.is_nan() { 0 } else { rounded as u16 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions_round_and_saturate() {
        assert_eq!(centivolts_to_volts(1_100), 11.0);
        assert_eq!(volts_to_centivolts(12.345), 1_235);
        assert_eq!(volts_to_centivolts(-3.0), 0);
        assert_eq!(volts_to_centivolts(1e9), u16::MAX);
        assert_eq!(deci_degrees_to_degrees(-900), -90.0);
        assert_eq!(degrees_to_deci_degrees(90.04), 900);
        assert_eq!(degrees_to_deci_degrees(-45.06), -451);
        assert_eq!(degrees_to_deci_degrees(f32::NAN), 0);
        assert_eq!(percent_to_centi_percent(25.5), 2_550);
        assert_eq!(percent_to_centi_percent(-250.0), -10_000);
        assert_eq!(gyro_gain_from_f32(0.5), 50_000);
        assert_eq!(gyro_gain_to_f32(100_000), 1.0);
    }
}
