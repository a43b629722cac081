//! Drives a `chassis-ros2` node from another ROS 2 participant, with no ROS install: publishes
//! a `geometry_msgs/Twist` on `/cmd_vel` at a rate for a while, listens to `/odom`, and prints
//! how many odometry messages came and the last pose.
//!
//! ```sh
//! chassis sim --pty &                                  # e.g. /dev/pts/3
//! chassis-ros2 --port /dev/pts/3 --stats &
//! cargo run -p chassis-ros2 --example cmd_vel -- --vx 0.2 --wz 0.5 --rate 20 --for 3
//! ```

use chassis_ros2::msg::{Header, Message, Odometry, Time, Twist, TwistStamped};
use clap::Parser;
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, NodeName, NodeOptions, QosProfile,
};
use std::time::{Duration, Instant};

/// Publishes /cmd_vel at a rate for a while; counts /odom.
#[derive(Parser)]
struct Args {
    /// Forward, m/s.
    #[arg(long, default_value = "0.0", allow_hyphen_values = true)]
    vx: f64,
    /// To the left, m/s.
    #[arg(long, default_value = "0.0", allow_hyphen_values = true)]
    vy: f64,
    /// Counter-clockwise, rad/s.
    #[arg(long, default_value = "0.0", allow_hyphen_values = true)]
    wz: f64,
    /// Messages per second.
    #[arg(long, default_value = "20")]
    rate: f64,
    /// Seconds.
    #[arg(long = "for", default_value = "3")]
    seconds: f64,
    /// Seconds to wait for the node before publishing.
    #[arg(long, default_value = "2")]
    wait: f64,
    /// Publish geometry_msgs/TwistStamped, stamped now (for a node run with --stamped).
    #[arg(long)]
    stamped: bool,
}

/// The system clock, ns since the Unix epoch.
fn now_ns() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_nanos()).unwrap_or(i64::MAX))
}

fn main() -> Result<(), String> {
    let args = Args::parse();
    let domain = chassis_ros2::ros::domain_id(std::env::var("ROS_DOMAIN_ID").ok().as_deref())?;
    let context = Context::with_options(ContextOptions::new().domain_id(domain))
        .map_err(|e| format!("{e:?}"))?;
    let mut node = context
        .new_node(
            NodeName::new("/", "cmd_vel_example").map_err(|e| format!("{e:?}"))?,
            NodeOptions::new().enable_rosout(false),
        )
        .map_err(|e| format!("{e:?}"))?;
    let qos = QosProfile::publisher_default()
        .reliability_reliable(WhenFull::DEFAULT)
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 10 });
    let topic = |node: &mut ros2_client::Node, name: &str, package: &str, ty: &str| {
        node.create_topic(
            &Name::new("/", name).map_err(|e| format!("{e:?}"))?,
            MessageTypeName::new(package, ty),
            &qos,
        )
        .map_err(|e| format!("{e:?}"))
    };
    let (package, ty) = if args.stamped {
        (TwistStamped::PACKAGE, TwistStamped::NAME)
    } else {
        (Twist::PACKAGE, Twist::NAME)
    };
    let cmd_topic = topic(&mut node, "cmd_vel", package, ty)?;
    let odom_topic = topic(&mut node, "odom", Odometry::PACKAGE, Odometry::NAME)?;
    let plain = node
        .create_publisher::<Twist>(&cmd_topic, None)
        .map_err(|e| format!("{e:?}"))?;
    let stamped = node
        .create_publisher::<TwistStamped>(&cmd_topic, None)
        .map_err(|e| format!("{e:?}"))?;
    let odom = node
        .create_subscription::<Odometry>(&odom_topic, None)
        .map_err(|e| format!("{e:?}"))?;
    let spinner = node.spinner().map_err(|e| format!("{e:?}"))?;
    std::thread::spawn(move || futures::executor::block_on(spinner.spin()));

    let mut twist = Twist::default();
    (twist.linear.x, twist.linear.y, twist.angular.z) = (args.vx, args.vy, args.wz);
    let period = Duration::from_secs_f64(1.0 / args.rate.max(0.1));
    let start = Instant::now();
    let publish_from = start + Duration::from_secs_f64(args.wait.max(0.0));
    let end = publish_from + Duration::from_secs_f64(args.seconds.max(0.0));
    let (mut sent, mut heard, mut last) = (0u32, 0u32, None);
    let mut next = publish_from;
    while Instant::now() < end + Duration::from_secs(1) {
        let now = Instant::now();
        if now >= next && now < end {
            let published = if args.stamped {
                let header = Header {
                    stamp: Time::from_nanos(now_ns()),
                    frame_id: "base_link".into(),
                };
                stamped.publish(TwistStamped { header, twist }).is_ok()
            } else {
                plain.publish(twist).is_ok()
            };
            if published {
                sent += 1;
            }
            next += period;
        }
        while let Ok(Some((message, _))) = odom.take() {
            heard += 1;
            last = Some(message.pose.pose.position);
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    println!("sent {sent} /cmd_vel; heard {heard} /odom; last position {last:?}");
    Ok(())
}
