//! A plausibility check of v1.0.0 telemetry, beside the BCC: values a chassis cannot report.
//!
//! | value | plausible | why |
//! |---|---|---|
//! | quaternion (w, x, y, z) × 1000 | norm within 1000 ± 5 % (950–1050) | a unit quaternion; rounding each component to × 1000 moves the norm by under 0.2 % |
//! | vx, vy | \|v\| ≤ 2000 mm/s | a small mecanum chassis; the stream model drives at 1 m/s at most |
//! | wz | \|wz\| ≤ 6000 mrad/s | about a turn a second; the model turns at 2.5 rad/s at most |
//! | battery | 6000–30 000 mV | from a flat 2S pack to a full 6S one |
//!
//! Replies are not checked: their values are settings whose ranges nobody has established.

use chassis_protocol::v1::{Downlink, Telemetry};

/// The quaternion's norm, × 1000.
pub const QUATERNION_NORM: i64 = 1_000;
/// How far the norm may be from [`QUATERNION_NORM`]: 5 %.
pub const QUATERNION_TOLERANCE: i64 = 50;
/// The largest |vx| and |vy|, mm/s.
pub const SPEED_LIMIT_MM_S: u16 = 2_000;
/// The largest |wz|, mrad/s.
pub const TURN_LIMIT_MRAD_S: u16 = 6_000;
/// The lowest battery voltage, mV.
pub const BATTERY_MIN_MV: i16 = 6_000;
/// The highest battery voltage, mV.
pub const BATTERY_MAX_MV: i16 = 30_000;

/// Whether `t`'s values are ones a chassis can report (the table above).
pub fn plausible(t: &Telemetry) -> bool {
    let norm2: i64 = t.quaternion.iter().map(|q| i64::from(*q).pow(2)).sum();
    let low = QUATERNION_NORM - QUATERNION_TOLERANCE;
    let high = QUATERNION_NORM + QUATERNION_TOLERANCE;
    let [vx, vy, wz] = t.velocity;
    (low * low..=high * high).contains(&norm2)
        && vx.unsigned_abs() <= SPEED_LIMIT_MM_S
        && vy.unsigned_abs() <= SPEED_LIMIT_MM_S
        && wz.unsigned_abs() <= TURN_LIMIT_MRAD_S
        && (BATTERY_MIN_MV..=BATTERY_MAX_MV).contains(&t.battery_mv)
}

/// [`plausible`] for telemetry; a reply is always plausible (nothing is checked).
pub fn plausible_frame(frame: &Downlink) -> bool {
    match frame {
        Downlink::Telemetry(t) => plausible(t),
        Downlink::Reply(_) => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn good() -> Telemetry {
        Telemetry {
            velocity: [-250, 800, 1_200],
            quaternion: [707, 0, 0, -707],
            battery_mv: 11_900,
            ..Telemetry::default()
        }
    }

    #[test]
    fn each_threshold() {
        assert!(plausible(&good()));
        type Edit = fn(&mut Telemetry);
        let edits: [(Edit, bool); 8] = [
            (|t| t.quaternion = [950, 0, 0, 0], true),
            (|t| t.quaternion = [949, 0, 0, 0], false),
            (|t| t.quaternion = [1_050, 0, 0, 0], true),
            (|t| t.quaternion = [1_051, 0, 0, 0], false),
            (|t| t.velocity[0] = -2_001, false),
            (|t| t.velocity[1] = i16::MIN, false),
            (|t| t.velocity[2] = 6_000, true),
            (|t| t.battery_mv = 5_999, false),
        ];
        for (i, (edit, want)) in edits.into_iter().enumerate() {
            let mut t = good();
            edit(&mut t);
            assert_eq!(plausible(&t), want, "edit {i}: {t:?}");
        }
    }
}
