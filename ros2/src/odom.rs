//! The odometry (crate `chassis-odometry`) set up from the node's parameters.

pub use chassis_odometry::{
    Counts, Drive, Geometry, Noise, Odometry, Pose2, RawScale, Twist2, v1_twist, v1_yaw,
};

use crate::params::{DEFAULT_SPEED_SCALE, DEFAULT_TURN_SCALE, DriveKind, EncoderCounts, Params};

/// The chassis geometry the parameters give.
pub fn geometry(params: &Params) -> Geometry {
    Geometry {
        drive: match params.drive {
            DriveKind::Mecanum => Drive::Mecanum,
            DriveKind::Omni => Drive::Omni,
            DriveKind::Differential => Drive::Differential,
        },
        half_wheelbase_m: params.half_wheelbase as f32,
        half_track_m: params.half_track as f32,
        ticks_per_m: params.ticks_per_meter as f32,
    }
}

/// The noise the parameters give, the odometry's defaults where they give none.
pub fn noise(params: &Params) -> Noise {
    let or = |given: Option<f64>, default: f32| given.map_or(default, |v| v as f32);
    let d = Noise::DEFAULT;
    Noise {
        pose_xy: or(params.noise_pose_xy, d.pose_xy),
        pose_yaw: or(params.noise_pose_yaw, d.pose_yaw),
        twist_linear: or(params.noise_twist_linear, d.twist_linear),
        twist_angular: or(params.noise_twist_angular, d.twist_angular),
        immobile: or(params.noise_immobile, d.immobile),
    }
}

/// The odometry for these parameters, at the origin.
pub fn odometry(params: &Params) -> Odometry {
    let counts = match params.encoder_counts {
        EncoderCounts::RunningTotal => Counts::RunningTotal,
        EncoderCounts::PerFrame => Counts::PerFrame,
    };
    Odometry::new(geometry(params), counts, noise(params))
}

/// The 2020 board's scale, and whether any of it is the assumed default (not given).
pub fn scale(params: &Params) -> (RawScale, bool) {
    let scale = RawScale {
        per_m_s: params.speed_scale.unwrap_or(DEFAULT_SPEED_SCALE) as f32,
        per_rad_s: params.turn_scale.unwrap_or(DEFAULT_TURN_SCALE) as f32,
    };
    (
        scale,
        params.speed_scale.is_none() || params.turn_scale.is_none(),
    )
}
