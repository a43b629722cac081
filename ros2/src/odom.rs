//! The odometry (crate `chassis-odometry`) set up from the node's parameters.

pub use stand_in::{Counts, Drive, Geometry, Noise, Odometry, Pose2, RawScale, Twist2};

/// A stand-in with the calls of the odometry crate (the shared contract), until it is merged:
/// it integrates nothing (the pose stays at the origin, the twist is the last body velocity).
mod stand_in {
    /// A planar velocity (REP-103).
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Twist2 {
        /// Forward, m/s.
        pub vx: f32,
        /// To the left, m/s.
        pub vy: f32,
        /// Counter-clockwise, rad/s.
        pub wz: f32,
    }
    /// A planar pose.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Pose2 {
        /// m.
        pub x: f32,
        /// m.
        pub y: f32,
        /// rad.
        pub yaw: f32,
    }
    /// The kinematics.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub enum Drive {
        /// Mecanum.
        Mecanum,
        /// Omni.
        Omni,
        /// Differential.
        Differential,
    }
    /// What encoder counts are.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub enum Counts {
        /// Running totals.
        RunningTotal,
        /// Per frame.
        PerFrame,
    }
    /// The geometry.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Geometry {
        /// The kinematics.
        pub drive: Drive,
        /// m.
        pub half_wheelbase_m: f32,
        /// m.
        pub half_track_m: f32,
        /// Ticks per m.
        pub ticks_per_m: f32,
    }
    /// The covariance model.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Noise {
        /// m² per m.
        pub pose_xy: f32,
        /// rad² per m or rad.
        pub pose_yaw: f32,
        /// (m/s)².
        pub twist_linear: f32,
        /// (rad/s)².
        pub twist_angular: f32,
        /// What cannot move.
        pub immobile: f32,
    }
    impl Noise {
        /// The defaults.
        pub const DEFAULT: Noise = Noise {
            pose_xy: 1e-3,
            pose_yaw: 1e-3,
            twist_linear: 1e-3,
            twist_angular: 1e-3,
            immobile: 1e3,
        };
    }
    /// The 2020 scale.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct RawScale {
        /// Raw per m/s.
        pub per_m_s: f32,
        /// Raw per rad/s.
        pub per_rad_s: f32,
    }
    impl RawScale {
        /// (x, y, z) of the 2020 velocity: x to the right, y forward.
        pub fn to_raw(&self, b: Twist2) -> (i16, i16, i16) {
            (
                (-b.vy * self.per_m_s) as i16,
                (b.vx * self.per_m_s) as i16,
                (b.wz * self.per_rad_s) as i16,
            )
        }
    }
    /// The odometry.
    #[derive(Clone, Debug)]
    pub struct Odometry {
        twist: Twist2,
    }
    impl Odometry {
        /// At the origin.
        pub fn new(_: Geometry, _: Counts, _: Noise) -> Self {
            Odometry {
                twist: Twist2 {
                    vx: 0.0,
                    vy: 0.0,
                    wz: 0.0,
                },
            }
        }
        /// A 2020 encoder frame.
        pub fn encoders(&mut self, _: [i16; 4], _: u64) -> Option<Twist2> {
            None
        }
        /// A v1.0.0 body velocity.
        pub fn body(&mut self, body: Twist2, _: Option<f32>, _: u64) {
            self.twist = body;
        }
        /// The pose.
        pub fn pose(&self) -> Pose2 {
            Pose2 {
                x: 0.0,
                y: 0.0,
                yaw: 0.0,
            }
        }
        /// The twist.
        pub fn twist(&self) -> Twist2 {
            self.twist
        }
        /// The pose's covariance.
        pub fn pose_covariance(&self) -> [f64; 36] {
            [0.0; 36]
        }
        /// The twist's covariance.
        pub fn twist_covariance(&self) -> [f64; 36] {
            [0.0; 36]
        }
    }
}

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
