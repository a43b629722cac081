//! `sensor_msgs/Imu` and `sensor_msgs/BatteryState`.

use super::{Header, Quaternion, Vector3};
use serde::{Deserialize, Serialize};

/// `sensor_msgs/Imu`: orientation, angular velocity (rad/s) and linear acceleration (m/s²),
/// each with a 3×3 covariance; a covariance whose element 0 is `-1` says the value is not
/// given (REP-145).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Imu {
    /// When, and the IMU's frame.
    pub header: Header,
    /// Orientation (meaningless when `orientation_covariance[0]` is `-1`).
    pub orientation: Quaternion,
    /// Its covariance.
    pub orientation_covariance: [f64; 9],
    /// rad/s.
    pub angular_velocity: Vector3,
    /// Its covariance.
    pub angular_velocity_covariance: [f64; 9],
    /// m/s² (gravity included).
    pub linear_acceleration: Vector3,
    /// Its covariance.
    pub linear_acceleration_covariance: [f64; 9],
}

/// `sensor_msgs/BatteryState` (ROS 2: with `temperature` and `cell_temperature`). Values not
/// measured are NaN.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BatteryState {
    /// When.
    pub header: Header,
    /// V.
    pub voltage: f32,
    /// °C.
    pub temperature: f32,
    /// A, negative when discharging.
    pub current: f32,
    /// Ah.
    pub charge: f32,
    /// Ah (last full charge).
    pub capacity: f32,
    /// Ah (as designed).
    pub design_capacity: f32,
    /// Charge, 0 to 1.
    pub percentage: f32,
    /// One of the `POWER_SUPPLY_STATUS_*` constants.
    pub power_supply_status: u8,
    /// One of the `POWER_SUPPLY_HEALTH_*` constants.
    pub power_supply_health: u8,
    /// One of the `POWER_SUPPLY_TECHNOLOGY_*` constants.
    pub power_supply_technology: u8,
    /// Whether a battery is there.
    pub present: bool,
    /// Each cell's voltage, V (empty: not known).
    pub cell_voltage: Vec<f32>,
    /// Each cell's temperature, °C (empty: not known).
    pub cell_temperature: Vec<f32>,
    /// Where the battery is.
    pub location: String,
    /// Its serial number.
    pub serial_number: String,
}

impl BatteryState {
    /// Status not known.
    pub const POWER_SUPPLY_STATUS_UNKNOWN: u8 = 0;
    /// Charging.
    pub const POWER_SUPPLY_STATUS_CHARGING: u8 = 1;
    /// Discharging.
    pub const POWER_SUPPLY_STATUS_DISCHARGING: u8 = 2;
    /// Not charging.
    pub const POWER_SUPPLY_STATUS_NOT_CHARGING: u8 = 3;
    /// Full.
    pub const POWER_SUPPLY_STATUS_FULL: u8 = 4;
    /// Health not known.
    pub const POWER_SUPPLY_HEALTH_UNKNOWN: u8 = 0;
    /// Good.
    pub const POWER_SUPPLY_HEALTH_GOOD: u8 = 1;
    /// Overheated.
    pub const POWER_SUPPLY_HEALTH_OVERHEAT: u8 = 2;
    /// Dead.
    pub const POWER_SUPPLY_HEALTH_DEAD: u8 = 3;
    /// Over voltage.
    pub const POWER_SUPPLY_HEALTH_OVERVOLTAGE: u8 = 4;
    /// Failed, unspecified.
    pub const POWER_SUPPLY_HEALTH_UNSPEC_FAILURE: u8 = 5;
    /// Cold.
    pub const POWER_SUPPLY_HEALTH_COLD: u8 = 6;
    /// Watchdog timer expired.
    pub const POWER_SUPPLY_HEALTH_WATCHDOG_TIMER_EXPIRE: u8 = 7;
    /// Safety timer expired.
    pub const POWER_SUPPLY_HEALTH_SAFETY_TIMER_EXPIRE: u8 = 8;
    /// Technology not known.
    pub const POWER_SUPPLY_TECHNOLOGY_UNKNOWN: u8 = 0;
    /// NiMH.
    pub const POWER_SUPPLY_TECHNOLOGY_NIMH: u8 = 1;
    /// Li-ion.
    pub const POWER_SUPPLY_TECHNOLOGY_LION: u8 = 2;
    /// LiPo.
    pub const POWER_SUPPLY_TECHNOLOGY_LIPO: u8 = 3;
    /// LiFe.
    pub const POWER_SUPPLY_TECHNOLOGY_LIFE: u8 = 4;
    /// NiCd.
    pub const POWER_SUPPLY_TECHNOLOGY_NICD: u8 = 5;
    /// LiMn.
    pub const POWER_SUPPLY_TECHNOLOGY_LIMN: u8 = 6;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::le;
    use crate::msg::{header, wire};

    #[test]
    fn battery_state_bytes_with_its_sequences_and_strings() {
        let battery = BatteryState {
            header: header(0, 0, ""),
            voltage: 12.5,
            temperature: f32::NAN,
            current: f32::NAN,
            charge: f32::NAN,
            capacity: f32::NAN,
            design_capacity: f32::NAN,
            percentage: 0.5,
            power_supply_status: BatteryState::POWER_SUPPLY_STATUS_DISCHARGING,
            power_supply_health: BatteryState::POWER_SUPPLY_HEALTH_UNKNOWN,
            power_supply_technology: BatteryState::POWER_SUPPLY_TECHNOLOGY_UNKNOWN,
            present: true,
            cell_voltage: vec![4.0, 4.25],
            cell_temperature: vec![],
            location: String::new(),
            serial_number: "A1".into(),
        };
        // 0 time, 8 length 1, 12 NUL, 13..16 padding, 16 voltage, 20..40 five NaN, 40
        // percentage, 44 status, 45 health, 46 technology, 47 present, 48 count 2, 52 and 56
        // the cells, 60 count 0, 64 length 1, 68 NUL, 69..72 padding, 72 length 3, 76 "A1" NUL.
        let mut expected = vec![0x00, 0x01, 0x00, 0x00, 0, 0, 0, 0, 0, 0, 0, 0];
        expected.extend_from_slice(&[1, 0, 0, 0, 0, 0, 0, 0]);
        expected.extend_from_slice(&[0x00, 0x00, 0x48, 0x41]); // 12.5 = 0x4148_0000
        for _ in 0..5 {
            expected.extend_from_slice(&[0x00, 0x00, 0xC0, 0x7F]); // NaN = 0x7FC0_0000
        }
        expected.extend_from_slice(&[0x00, 0x00, 0x00, 0x3F]); // 0.5 = 0x3F00_0000
        expected.extend_from_slice(&[2, 0, 0, 1]);
        expected.extend_from_slice(&le::u32(2));
        expected.extend_from_slice(&[0x00, 0x00, 0x80, 0x40]); // 4.0 = 0x4080_0000
        expected.extend_from_slice(&[0x00, 0x00, 0x88, 0x40]); // 4.25 = 0x4088_0000
        expected.extend_from_slice(&le::u32(0));
        expected.extend_from_slice(&[1, 0, 0, 0, 0, 0, 0, 0]);
        expected.extend_from_slice(&[3, 0, 0, 0, b'A', b'1', 0]);
        assert_eq!(expected.len(), 4 + 79);
        assert_eq!(le::f32(12.5), [0x00, 0x00, 0x48, 0x41]);
        assert_eq!(wire(&battery), expected);
    }

    #[test]
    fn imu_bytes_are_the_header_then_f64s_aligned() {
        let mut imu = Imu {
            header: header(0, 0, "imu"),
            ..Imu::default()
        };
        imu.orientation_covariance[0] = -1.0;
        imu.linear_acceleration.z = 9.80665;
        let bytes = wire(&imu);
        // Payload: 0 time, 8 length 4, 12 "imu" NUL, 16 the orientation (aligned already).
        assert_eq!(
            bytes[4..20],
            [0, 0, 0, 0, 0, 0, 0, 0, 4, 0, 0, 0, b'i', b'm', b'u', 0]
        );
        // 4 quaternion + 9 + 3 + 9 + 3 + 9 f64 after 16 bytes.
        assert_eq!(bytes.len(), 4 + 16 + 37 * 8);
        // orientation_covariance[0] right after the quaternion (x, y, z, w = 0, 0, 0, 1).
        assert_eq!(bytes[20 + 24..20 + 32], le::f64(1.0));
        assert_eq!(bytes[20 + 32..20 + 40], [0, 0, 0, 0, 0, 0, 0xF0, 0xBF]);
        // linear_acceleration.z: after 4 + 9 + 3 + 9 + 2 f64.
        let z = 20 + 27 * 8;
        assert_eq!(bytes[z..z + 8], le::f64(9.80665));
    }
}
