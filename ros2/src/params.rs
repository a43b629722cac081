//! The node's parameters: a ROS 2 parameters file (`--params FILE.yaml`, the node's section
//! under `ros__parameters`), then `--param KEY=VALUE` flags and the dedicated flags on top.
//! Every key is checked: an unknown one is an error that names it, a value of the wrong type
//! or out of range an error that names the parameter.
//!
//! ```yaml
//! chassis:
//!   ros__parameters:
//!     odom_frame: odom
//!     drive: mecanum
//!     speed_scale: 1000.0
//! ```

use serde::Deserialize;
use serde_norway::{Mapping, Value};

/// How the wheels move the chassis (the odometry's kinematics).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DriveKind {
    /// Four mecanum wheels: moves sideways.
    Mecanum,
    /// Omni wheels: moves sideways.
    Omni,
    /// Two sides: no sideways motion.
    Differential,
}

/// What a 2020 encoder frame's counts are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EncoderCounts {
    /// A running total per wheel (wrapping `i16`).
    RunningTotal,
    /// The ticks since the previous frame.
    PerFrame,
}

/// The 2020 board's speed unit, assumed when not given: raw units per m/s (decision A8 in
/// docs/protocol-2020.md: the vendor states none; the simulated board's unit).
pub const DEFAULT_SPEED_SCALE: f64 = 1000.0;
/// The 2020 board's turn unit, assumed when not given: raw units per rad/s.
pub const DEFAULT_TURN_SCALE: f64 = 220.0;
/// The 2020 accelerometer, assumed when not given: raw counts per g (a ±2 g range, 16 384 at
/// rest, what the simulated board sends).
pub const DEFAULT_ACCEL_PER_G_2020: f64 = 16_384.0;
/// The 2020 gyro, assumed when not given: raw counts per rad/s (a ±2000 °/s range, 16.4 per
/// °/s).
pub const DEFAULT_GYRO_PER_RAD_S_2020: f64 = 16.4 * 180.0 / core::f64::consts::PI;
/// The v1.0.0 accelerometer, assumed when not given: raw counts per g (milli-g).
pub const DEFAULT_ACCEL_PER_G_V1: f64 = 1000.0;
/// The v1.0.0 gyro, assumed when not given: raw counts per rad/s (mrad/s, as users read it).
pub const DEFAULT_GYRO_PER_RAD_S_V1: f64 = 1000.0;

/// The parameters, as given (`None`: not given, the default applies).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// The odometry frame (`/odom`'s `header.frame_id`, the transform's parent).
    pub odom_frame: String,
    /// The robot's body frame (`/odom`'s `child_frame_id`, the transform's child).
    pub base_frame: String,
    /// The IMU's frame (`/imu/data_raw`'s `header.frame_id`).
    pub imu_frame: String,
    /// Whether to publish the `odom` → `base_link` transform on `/tf`.
    pub publish_tf: bool,
    /// `/cmd_vel` silent this long (s) stops the chassis; a `TwistStamped` older than it is
    /// ignored.
    pub cmd_vel_timeout: f64,
    /// How often `/odom` (and `/tf`) are published, Hz.
    pub odom_rate: f64,
    /// How often `/diagnostics` is published, Hz.
    pub diagnostics_rate: f64,
    /// The kinematics.
    pub drive: DriveKind,
    /// Half the distance between the front and rear axles, m.
    pub half_wheelbase: f64,
    /// Half the distance between the left and right wheels, m.
    pub half_track: f64,
    /// Encoder ticks per metre of wheel travel (2020).
    pub ticks_per_meter: f64,
    /// What the 2020 encoder counts are.
    pub encoder_counts: EncoderCounts,
    /// 2020 only: raw velocity units per m/s ([`DEFAULT_SPEED_SCALE`] when not given).
    pub speed_scale: Option<f64>,
    /// 2020 only: raw rotation units per rad/s ([`DEFAULT_TURN_SCALE`] when not given).
    pub turn_scale: Option<f64>,
    /// Raw accelerometer counts per g (a default per generation when not given).
    pub accel_per_g: Option<f64>,
    /// Raw gyro counts per rad/s (a default per generation when not given).
    pub gyro_per_rad_s: Option<f64>,
    /// Variance of each angular velocity axis on `/imu/data_raw`, (rad/s)².
    pub imu_gyro_variance: f64,
    /// Variance of each acceleration axis on `/imu/data_raw`, (m/s²)².
    pub imu_accel_variance: f64,
    /// Variance of the v1.0.0 IMU's orientation (each axis), rad².
    pub imu_orientation_variance: f64,
    /// The odometry's covariance model (`Noise` in docs/odometry.md), each `None` for its
    /// default: variance of x and y, m², per metre travelled.
    pub noise_pose_xy: Option<f64>,
    /// Variance of the heading, rad², per metre travelled and per radian turned.
    pub noise_pose_yaw: Option<f64>,
    /// Variance of vx and vy, (m/s)².
    pub noise_twist_linear: Option<f64>,
    /// Variance of wz, (rad/s)².
    pub noise_twist_angular: Option<f64>,
    /// Variance on the axes the chassis cannot move along (z, roll, pitch).
    pub noise_immobile: Option<f64>,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            odom_frame: "odom".into(),
            base_frame: "base_link".into(),
            imu_frame: "imu_link".into(),
            publish_tf: true,
            cmd_vel_timeout: 0.5,
            odom_rate: 50.0,
            diagnostics_rate: 1.0,
            drive: DriveKind::Mecanum,
            half_wheelbase: 0.10,
            half_track: 0.12,
            ticks_per_meter: 1000.0,
            encoder_counts: EncoderCounts::RunningTotal,
            speed_scale: None,
            turn_scale: None,
            accel_per_g: None,
            gyro_per_rad_s: None,
            imu_gyro_variance: 4e-4,
            imu_accel_variance: 4e-2,
            imu_orientation_variance: 1e-3,
            noise_pose_xy: None,
            noise_pose_yaw: None,
            noise_twist_linear: None,
            noise_twist_angular: None,
            noise_immobile: None,
        }
    }
}

/// The section of a parameters file that is the node's: `<name>:`, `/<name>:` or `/**:`
/// (the ROS 2 wildcard), each `ros__parameters:` inside. Later ones win key by key, in the
/// order `/**`, then the node's own.
fn node_section(file: &Value, node: &str, source: &str) -> Result<Mapping, String> {
    let Value::Mapping(top) = file else {
        return Err(format!(
            "{source}: a ROS 2 parameters file is a map of node names (`{node}:` then `ros__parameters:`)"
        ));
    };
    let mut merged = Mapping::new();
    let mut found = false;
    for name in ["/**".to_string(), node.to_string(), format!("/{node}")] {
        let Some(section) = top.get(name.as_str()) else {
            continue;
        };
        let params = section
            .get("ros__parameters")
            .ok_or_else(|| format!("{source}: `{name}:` has no `ros__parameters:` inside"))?;
        let Value::Mapping(params) = params else {
            return Err(format!(
                "{source}: `{name}: ros__parameters:` is not a map of parameters"
            ));
        };
        found = true;
        for (key, value) in params {
            merged.insert(key.clone(), value.clone());
        }
    }
    if !found {
        return Err(format!(
            "{source}: no section for the node `{node}` (nor `/**`): the file's nodes are {}",
            top.keys()
                .map(|k| format!("`{}`", k.as_str().unwrap_or("?")))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    Ok(merged)
}

/// The parameters of node `node`: the file's text (`yaml`, read from `source`, if given), then
/// each `KEY=VALUE` of `overrides` (the value read as YAML: `0.3`, `true`, `omni`).
pub fn parse(
    yaml: Option<(&str, &str)>,
    node: &str,
    overrides: &[(String, String)],
) -> Result<Params, String> {
    let mut given = match yaml {
        Some((text, source)) => {
            let file: Value = serde_norway::from_str(text)
                .map_err(|e| format!("{source}: not a YAML parameters file: {e}"))?;
            node_section(&file, node, source)?
        }
        None => Mapping::new(),
    };
    for (key, value) in overrides {
        let value: Value = serde_norway::from_str(value)
            .map_err(|e| format!("parameter {key}: {value:?} is not a value: {e}"))?;
        given.insert(Value::String(key.clone()), value);
    }
    let params: Params = serde_norway::from_value(Value::Mapping(given.clone()))
        .map_err(|e| blame(&given, &e.to_string()))?;
    params.check()?;
    Ok(params)
}

/// serde's words for a bad parameter, said as the node's, naming the parameter at fault: the
/// first whose value alone is refused.
fn blame(given: &Mapping, serde: &str) -> String {
    for (key, value) in given {
        let mut one = Mapping::new();
        one.insert(key.clone(), value.clone());
        if let Err(e) = serde_norway::from_value::<Params>(Value::Mapping(one)) {
            let e = e.to_string();
            if e.starts_with("unknown field ") {
                return explain(&e);
            }
            return format!("parameter {}: {e}", key.as_str().unwrap_or("?"));
        }
    }
    explain(serde)
}

/// serde's words for a bad parameter, said as the node's.
fn explain(serde: &str) -> String {
    if let Some(rest) = serde.strip_prefix("unknown field ") {
        let (name, known) = rest.split_once(", expected").unwrap_or((rest, ""));
        return format!(
            "unknown parameter {name} (the parameters are{})",
            known.trim_start_matches(" one of")
        );
    }
    format!("bad parameter: {serde}")
}

impl Params {
    /// Every number in its range.
    fn check(&self) -> Result<(), String> {
        let positive = [
            ("cmd_vel_timeout", Some(self.cmd_vel_timeout)),
            ("odom_rate", Some(self.odom_rate)),
            ("diagnostics_rate", Some(self.diagnostics_rate)),
            ("half_track", Some(self.half_track)),
            ("ticks_per_meter", Some(self.ticks_per_meter)),
            ("accel_per_g", self.accel_per_g),
            ("gyro_per_rad_s", self.gyro_per_rad_s),
        ];
        for (name, value) in positive {
            if let Some(v) = value.filter(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(format!(
                    "parameter {name}: {v} is not a positive finite number"
                ));
            }
        }
        for (name, value) in [
            ("speed_scale", self.speed_scale),
            ("turn_scale", self.turn_scale),
        ] {
            if let Some(v) = value.filter(|v| !v.is_finite() || *v == 0.0) {
                return Err(format!(
                    "parameter {name}: {v} is not a non-zero finite number (raw units per m/s or rad/s; negative flips the axis)"
                ));
            }
        }
        let variances = [
            ("imu_gyro_variance", Some(self.imu_gyro_variance)),
            ("imu_accel_variance", Some(self.imu_accel_variance)),
            (
                "imu_orientation_variance",
                Some(self.imu_orientation_variance),
            ),
            ("noise_pose_xy", self.noise_pose_xy),
            ("noise_pose_yaw", self.noise_pose_yaw),
            ("noise_twist_linear", self.noise_twist_linear),
            ("noise_twist_angular", self.noise_twist_angular),
            ("noise_immobile", self.noise_immobile),
        ];
        for (name, value) in variances {
            if let Some(v) = value.filter(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(format!(
                    "parameter {name}: {v} is not a finite number of at least 0"
                ));
            }
        }
        if !(self.half_wheelbase.is_finite() && self.half_wheelbase >= 0.0) {
            return Err(format!(
                "parameter half_wheelbase: {} is not a finite number of metres, 0 or more",
                self.half_wheelbase
            ));
        }
        if self.cmd_vel_timeout > 3600.0 {
            return Err(format!(
                "parameter cmd_vel_timeout: {} s is more than an hour",
                self.cmd_vel_timeout
            ));
        }
        for (name, frame) in [
            ("odom_frame", &self.odom_frame),
            ("base_frame", &self.base_frame),
            ("imu_frame", &self.imu_frame),
        ] {
            if frame.is_empty() {
                return Err(format!("parameter {name}: a frame id is not empty"));
            }
        }
        Ok(())
    }
}
