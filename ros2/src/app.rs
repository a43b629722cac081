//! The `chassis-ros2` program: its command line, the start-up (parameters, the port and its
//! firmware, the ROS node, the `ready:` line), the loop, the stop and the exit status.

use crate::board::Generation;
use crate::convert::ImuScale;
use crate::node::{self, Settings};
use crate::params::{self, Params};
use crate::ros::{self, Ros};
use crate::stats::Latency;
use chassis_cli::connect;
use chassis_protocol::detect::Firmware;
use chassis_protocol::driver::{DriverCore, v1};
use clap::Parser;

/// A ROS 2 node for the chassis board: /cmd_vel in; /odom, /tf, /imu/data_raw,
/// /battery_state and /diagnostics out. Stops the chassis when /cmd_vel goes quiet and on
/// SIGINT, SIGTERM and SIGHUP (exit 130, 143, 129 after the stop).
#[derive(Debug, Parser)]
#[command(name = "chassis-ros2", version, about)]
pub struct Args {
    /// The board's serial port (115 200 8N1).
    #[arg(long, value_name = "PATH")]
    pub port: String,
    /// The board's firmware: 2020 or v1.0.0 (also v1). Without it, found from what the board
    /// sends, as every `chassis` command does.
    #[arg(long, value_name = "VERSION", value_parser = connect::firmware_arg)]
    pub firmware: Option<Firmware>,
    /// A ROS 2 parameters file (the node's section, or `/**`, under `ros__parameters`).
    #[arg(long, value_name = "FILE.yaml")]
    pub params: Option<String>,
    /// Sets one parameter, over the file's (e.g. `-p speed_scale:=1200` or
    /// `-p drive=omni`); may be repeated.
    #[arg(short = 'p', long = "param", value_name = "KEY:=VALUE")]
    pub param: Vec<String>,
    /// The node's name.
    #[arg(long, default_value = "chassis")]
    pub name: String,
    /// /cmd_vel is geometry_msgs/TwistStamped (as Jazzy's controllers take), not Twist.
    #[arg(long)]
    pub stamped: bool,
    /// Do not publish the odom → base_link transform on /tf (parameter publish_tf: false).
    #[arg(long)]
    pub no_tf: bool,
    /// /cmd_vel silent this long stops the chassis (parameter cmd_vel_timeout; 0.5 s).
    #[arg(long, value_name = "SECONDS")]
    pub cmd_vel_timeout: Option<f64>,
    /// On exit, one line on stderr: the time from a /cmd_vel sample's arrival to its frame
    /// written to the port (n, p50, p99, max).
    #[arg(long)]
    pub stats: bool,
}

/// Exit status for a bad parameter or argument.
pub const USAGE: u8 = 2;

/// A parameters file larger than this is refused (a ROS parameters file is a few KiB).
const MAX_PARAMS_BYTES: u64 = 1 << 20;

/// `KEY:=VALUE` (ROS 2's form) or `KEY=VALUE`.
fn key_value(text: &str) -> Result<(String, String), String> {
    let (key, value) = text
        .split_once(":=")
        .or_else(|| text.split_once('='))
        .ok_or_else(|| format!("-p {text:?}: give KEY:=VALUE"))?;
    Ok((key.trim().to_string(), value.to_string()))
}

/// The parameters from the file and the flags.
pub fn parameters(args: &Args) -> Result<Params, String> {
    let text = match &args.params {
        Some(path) => {
            let meta = std::fs::metadata(path).map_err(|e| format!("--params {path}: {e}"))?;
            if meta.len() > MAX_PARAMS_BYTES {
                return Err(format!(
                    "--params {path}: {} bytes, more than a parameters file (1 MiB at most)",
                    meta.len()
                ));
            }
            Some(std::fs::read_to_string(path).map_err(|e| format!("--params {path}: {e}"))?)
        }
        None => None,
    };
    let mut overrides = args
        .param
        .iter()
        .map(|p| key_value(p))
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(t) = args.cmd_vel_timeout {
        overrides.push(("cmd_vel_timeout".into(), format!("{t:?}")));
    }
    if args.no_tf {
        overrides.push(("publish_tf".into(), "false".into()));
    }
    let yaml = text.as_deref().zip(args.params.as_deref());
    let params = params::parse(yaml, &args.name, &overrides)?;
    crate::odom::geometry(&params)
        .validate()
        .map_err(|e| format!("the chassis geometry: {e}"))?;
    Ok(params)
}

/// The IMU's scale: the parameters', else the generation's assumption (and a note saying so).
pub fn imu_scale(params: &Params, firmware: &str) -> (ImuScale, Option<String>) {
    let (accel, gyro) = if firmware == DriverCore::NAME {
        (
            params::DEFAULT_ACCEL_PER_G_2020,
            params::DEFAULT_GYRO_PER_RAD_S_2020,
        )
    } else {
        (
            params::DEFAULT_ACCEL_PER_G_V1,
            params::DEFAULT_GYRO_PER_RAD_S_V1,
        )
    };
    let scale = ImuScale {
        accel_per_g: params.accel_per_g.unwrap_or(accel),
        gyro_per_rad_s: params.gyro_per_rad_s.unwrap_or(gyro),
        accel_variance: params.imu_accel_variance,
        gyro_variance: params.imu_gyro_variance,
        orientation_variance: params.imu_orientation_variance,
    };
    let note = (params.accel_per_g.is_none() || params.gyro_per_rad_s.is_none()).then(|| {
        format!(
            "the {firmware} IMU's scale is not stated by the vendor: assuming {:.0} counts per g and {:.1} counts per rad/s (parameters accel_per_g, gyro_per_rad_s)",
            scale.accel_per_g, scale.gyro_per_rad_s
        )
    });
    (scale, note)
}

/// Runs the node: the exit status, or a message and the status.
pub fn run(args: &Args) -> Result<u8, (String, u8)> {
    let params = parameters(args).map_err(|e| (e, USAGE))?;
    let domain =
        ros::domain_id(std::env::var("ROS_DOMAIN_ID").ok().as_deref()).map_err(|e| (e, USAGE))?;
    let firmware = connect::generation_or(&args.port, args.firmware, connect::DEFAULT_FIRMWARE)
        .map_err(|e| (e, 1))?;
    match firmware {
        Firmware::V1_0_0 => run_on::<v1::DriverCore>(args, params, domain),
        _ => run_on::<DriverCore>(args, params, domain),
    }
}

fn run_on<K: Generation>(args: &Args, params: Params, domain: u16) -> Result<u8, (String, u8)> {
    let driver = K::open(&args.port).map_err(|e| (e, 1))?;
    let (imu, imu_note) = imu_scale(&params, K::NAME);
    if K::NAME == DriverCore::NAME && crate::odom::scale(&params).1 {
        let (scale, _) = crate::odom::scale(&params);
        tell!(
            "{}: the 2020 board's velocity unit is not stated (decision A8): assuming {} raw units per m/s and {} per rad/s (parameters speed_scale, turn_scale; docs/odometry.md says how to measure them)",
            args.name,
            scale.per_m_s,
            scale.per_rad_s
        );
    }
    if let Some(note) = imu_note {
        tell!("{}: {note}", args.name);
    }
    let mut ros =
        Ros::new(&args.name, domain, args.stamped, params.publish_tf).map_err(|e| (e, 1))?;
    tell!("ready: {} on {}", K::NAME, args.port);
    let settings = Settings {
        name: args.name.clone(),
        port: args.port.clone(),
        params,
        imu,
    };
    let mut latency = Latency::default();
    let end = node::run(driver, &settings, &mut ros, &mut latency);
    if args.stats {
        tell!("{}", latency.line());
    }
    let words = end.stopped.words::<K>();
    match end.ending {
        Some(ending) => {
            tell!("{}: {}: {words}", args.name, ending.words());
            Ok(ending.exit_status())
        }
        None => {
            tell!("{}: {words}", args.name);
            Ok(0)
        }
    }
}
