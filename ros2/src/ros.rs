//! The node on the ROS 2 graph (ros2-client over RustDDS): its publishers and its `/cmd_vel`
//! subscription with ROS 2's default QoS (reliable, volatile, keep last 10), the domain from
//! `ROS_DOMAIN_ID`, and the spinner on a thread of its own (no async runtime).

use crate::msg::{
    BatteryState, DiagnosticArray, Imu, Message, Odometry, TfMessage, Twist, TwistStamped,
};
use crate::node::{Command, Incoming, Io, Out};
use ros2_client::dds::rustdds::mio1;
use ros2_client::qos::{Durability, History};
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, Node, NodeName, NodeOptions, Publisher,
    QosProfile, ROSTime, Subscription,
};
use serde::Serialize;
use std::time::Duration;

/// ROS 2's default QoS for topics: reliable, volatile, keep last 10.
fn qos() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(ros2_client::qos::WhenFull::DEFAULT)
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 10 })
}

/// The DDS domain: `ROS_DOMAIN_ID` (0 when unset or empty), 0..=232 as ROS 2 allows.
pub fn domain_id(value: Option<&str>) -> Result<u16, String> {
    match value.map(str::trim) {
        None | Some("") => Ok(0),
        Some(text) => text
            .parse::<u16>()
            .ok()
            .filter(|d| *d <= 232)
            .ok_or_else(|| format!("ROS_DOMAIN_ID={text:?} is not a domain id (0 to 232)")),
    }
}

/// Where `/cmd_vel` comes in.
enum CmdVel {
    Twist(Subscription<Twist>),
    Stamped(Subscription<TwistStamped>),
}

/// The node's publishers and subscription.
pub struct Ros {
    node: Node,
    cmd_vel: CmdVel,
    odom: Publisher<Odometry>,
    tf: Option<Publisher<TfMessage>>,
    imu: Publisher<Imu>,
    battery: Publisher<BatteryState>,
    diagnostics: Publisher<DiagnosticArray>,
    /// Wakes the loop when a `/cmd_vel` sample comes.
    poll: mio1::Poll,
    events: mio1::Events,
    /// Errors said once each.
    said: std::collections::HashSet<String>,
}

/// A topic `name` under `namespace` of message type `M`.
fn topic<M: Message>(
    node: &mut Node,
    namespace: &str,
    name: &str,
) -> Result<ros2_client::dds::rustdds::Topic, String> {
    let ros_name =
        Name::new(namespace, name).map_err(|e| format!("topic {namespace}/{name}: {e:?}"))?;
    node.create_topic(&ros_name, MessageTypeName::new(M::PACKAGE, M::NAME), &qos())
        .map_err(|e| format!("topic {name}: {e:?}"))
}

fn publisher<M: Message + Serialize>(
    node: &mut Node,
    namespace: &str,
    name: &str,
) -> Result<Publisher<M>, String> {
    let topic = topic::<M>(node, namespace, name)?;
    node.create_publisher(&topic, Some(qos()))
        .map_err(|e| format!("publisher {name}: {e:?}"))
}

/// `/cmd_vel` of type `M`, its samples waking `poll`.
fn subscribe<M: Message + serde::de::DeserializeOwned + 'static>(
    node: &mut Node,
    poll: &mio1::Poll,
) -> Result<Subscription<M>, String> {
    let topic = topic::<M>(node, "/", "cmd_vel")?;
    let mut subscription = node
        .create_subscription(&topic, Some(qos()))
        .map_err(|e| format!("subscription cmd_vel: {e:?}"))?;
    poll.registry()
        .register(&mut subscription, mio1::Token(0), mio1::Interest::READABLE)
        .map_err(|e| format!("cannot poll /cmd_vel: {e}"))?;
    Ok(subscription)
}

impl Ros {
    /// The node `name` on domain `domain`, subscribed to `/cmd_vel` (`TwistStamped` when
    /// `stamped`), publishing `/odom`, `/tf` (when `tf`), `/imu/data_raw`, `/battery_state`
    /// and `/diagnostics`; its spinner running.
    pub fn new(name: &str, domain: u16, stamped: bool, tf: bool) -> Result<Ros, String> {
        let context = Context::with_options(ContextOptions::new().domain_id(domain))
            .map_err(|e| format!("cannot start DDS on domain {domain}: {e:?}"))?;
        let node_name = NodeName::new("/", name)
            .map_err(|e| format!("--name {name:?} is not a ROS node name: {e:?}"))?;
        let mut node = context
            .new_node(
                node_name,
                NodeOptions::new()
                    .enable_rosout(false)
                    .start_parameter_services(false),
            )
            .map_err(|e| format!("cannot create the node {name}: {e:?}"))?;
        let poll = mio1::Poll::new().map_err(|e| format!("cannot poll: {e}"))?;
        let cmd_vel = if stamped {
            CmdVel::Stamped(subscribe(&mut node, &poll)?)
        } else {
            CmdVel::Twist(subscribe(&mut node, &poll)?)
        };
        let ros = Ros {
            odom: publisher(&mut node, "/", "odom")?,
            tf: if tf {
                Some(publisher(&mut node, "/", "tf")?)
            } else {
                None
            },
            imu: publisher(&mut node, "/imu", "data_raw")?,
            battery: publisher(&mut node, "/", "battery_state")?,
            diagnostics: publisher(&mut node, "/", "diagnostics")?,
            cmd_vel,
            poll,
            events: mio1::Events::with_capacity(4),
            said: Default::default(),
            node,
        };
        let mut ros = ros;
        let spinner = ros
            .node
            .spinner()
            .map_err(|e| format!("cannot start the node's spinner: {e:?}"))?;
        std::thread::Builder::new()
            .name("ros2-spinner".into())
            .spawn(move || {
                if let Err(e) = futures::executor::block_on(spinner.spin()) {
                    tell!("chassis-ros2: the node's spinner ended: {e:?}");
                }
            })
            .map_err(|e| format!("cannot start the spinner's thread: {e}"))?;
        Ok(ros)
    }

    /// Says an error once.
    fn once(&mut self, line: String) {
        if self.said.insert(line.clone()) {
            tell!("chassis-ros2: {line}");
        }
    }
}

/// When a sample reached the node: its reception time, else now.
fn arrived(info: &ros2_client::MessageInfo) -> i64 {
    info.received_timestamp()
        .unwrap_or_else(|| ROSTime::from(ros2_client::SystemTime::now()))
        .to_nanos()
}

impl Io for Ros {
    fn take(&mut self) -> Option<Incoming> {
        let taken = match &self.cmd_vel {
            CmdVel::Twist(s) => s.take().map(|m| {
                m.map(|(t, info)| Incoming {
                    command: Command::Twist(t),
                    arrived_ns: arrived(&info),
                })
            }),
            CmdVel::Stamped(s) => s.take().map(|m| {
                m.map(|(t, info)| Incoming {
                    command: Command::Stamped(t),
                    arrived_ns: arrived(&info),
                })
            }),
        };
        match taken {
            Ok(incoming) => incoming,
            Err(e) => {
                // A sample that does not decode (another type under the same name) is skipped.
                self.once(format!("a /cmd_vel sample could not be read: {e:?}"));
                None
            }
        }
    }

    fn now_ns(&self) -> i64 {
        self.node.time_now().to_nanos()
    }

    /// Wakes as soon as a `/cmd_vel` sample comes (a sample in the loop's next turn).
    fn wait(&mut self, at_most: Duration) {
        if self.poll.poll(&mut self.events, Some(at_most)).is_err() {
            std::thread::sleep(at_most);
        }
    }

    fn publish(&mut self, out: Out) {
        let (topic, result) = match out {
            Out::Odom(m) => ("/odom", self.odom.publish(*m).map_err(|e| format!("{e:?}"))),
            Out::Tf(m) => match &self.tf {
                Some(p) => ("/tf", p.publish(m).map_err(|e| format!("{e:?}"))),
                None => return,
            },
            Out::Imu(m) => (
                "/imu/data_raw",
                self.imu.publish(m).map_err(|e| format!("{e:?}")),
            ),
            Out::Battery(m) => (
                "/battery_state",
                self.battery.publish(m).map_err(|e| format!("{e:?}")),
            ),
            Out::Diagnostics(m) => (
                "/diagnostics",
                self.diagnostics.publish(m).map_err(|e| format!("{e:?}")),
            ),
        };
        if let Err(e) = result {
            self.once(format!("publishing on {topic}: {e}"));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_domain_id_is_read_and_checked() {
        assert_eq!(domain_id(None), Ok(0));
        assert_eq!(domain_id(Some("")), Ok(0));
        assert_eq!(domain_id(Some(" 42 ")), Ok(42));
        assert_eq!(domain_id(Some("232")), Ok(232));
        assert!(domain_id(Some("233")).unwrap_err().contains("0 to 232"));
        assert!(domain_id(Some("-1")).is_err());
        assert!(domain_id(Some("abc")).is_err());
    }
}
