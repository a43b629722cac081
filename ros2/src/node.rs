//! The node's main loop, apart from DDS: commands in, the watchdog, the driver polled, readings
//! fed to the odometry, messages out, the stop at the end. It talks to the ROS graph through
//! [`Io`], so that it runs against a simulated board with no network in the tests.

use crate::board::{COMMAND_PERIOD_MS, Generation, Reading};
use crate::convert::{self, Frames, ImuScale};
use crate::diagnostics::{self, Counters};
use crate::msg::{
    BatteryState, DiagnosticArray, Header, Imu, Odometry, TfMessage, Time, Twist, TwistStamped,
};
use crate::odom::{self, RawScale, Twist2};
use crate::params::{DriveKind, Params};
use crate::stats::Latency;
use crate::watchdog::{Verdict, Wanted, Watchdog};
use chassis_cli::ending::{self, Ending};
use chassis_cli::stopping::{self, HostDriver, Stopped};
use std::collections::HashSet;
use std::time::{Duration, Instant};

/// A velocity command from `/cmd_vel`.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// `geometry_msgs/Twist`.
    Twist(Twist),
    /// `geometry_msgs/TwistStamped` (`--stamped`).
    Stamped(TwistStamped),
}

/// A command and when it reached the node, ns on the node's clock.
#[derive(Clone, Debug, PartialEq)]
pub struct Incoming {
    /// The command.
    pub command: Command,
    /// When it arrived, ns since the clock's epoch.
    pub arrived_ns: i64,
}

/// A message to publish.
#[derive(Clone, Debug, PartialEq)]
pub enum Out {
    /// On `/odom`.
    Odom(Box<Odometry>),
    /// On `/tf`.
    Tf(TfMessage),
    /// On `/imu/data_raw`.
    Imu(Imu),
    /// On `/battery_state`.
    Battery(BatteryState),
    /// On `/diagnostics`.
    Diagnostics(DiagnosticArray),
}

/// The node's side of the ROS graph.
pub trait Io {
    /// The next command that came, if any.
    fn take(&mut self) -> Option<Incoming>;
    /// The node's clock (ROS time), ns since its epoch.
    fn now_ns(&self) -> i64;
    /// Publishes `out`.
    fn publish(&mut self, out: Out);
    /// Whether the loop should end now though no signal came (the tests' end).
    fn finished(&mut self) -> bool {
        false
    }
    /// Waits until a command may have come, `at_most` (the loop's turn: the board is read
    /// after it).
    fn wait(&mut self, at_most: Duration) {
        std::thread::sleep(at_most);
    }
}

/// How the loop ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct End {
    /// The ending that ended it (`None`: [`Io::finished`]).
    pub ending: Option<Ending>,
    /// What the stop on the way out did.
    pub stopped: Stopped,
}

/// What the node was started with.
#[derive(Clone, Debug)]
pub struct Settings {
    /// The node's name (in the diagnostics).
    pub name: String,
    /// The board's port.
    pub port: String,
    /// The parameters.
    pub params: Params,
    /// The IMU's scale (the parameters', or the generation's default).
    pub imu: ImuScale,
}

/// The loop's state.
struct Node<'a, K: Generation, I: Io> {
    driver: HostDriver<K>,
    settings: &'a Settings,
    io: &'a mut I,
    frames: Frames,
    start: Instant,
    watchdog: Watchdog<Twist2>,
    odometry: odom::Odometry,
    scale: RawScale,
    counters: Counters,
    latency: &'a mut Latency,
    /// A command not yet sent, and when it arrived (ns).
    fresh: Option<i64>,
    last_sent_ms: Option<u64>,
    next_odom_ms: u64,
    next_diagnostics_ms: u64,
    next_battery_ms: u64,
    failsafe_seen: u32,
    said: HashSet<String>,
}

/// Runs the node on `driver` until a signal (or `io` says it is finished), then stops the
/// chassis. `latency` gets a sample per command sent as it came.
pub fn run<K: Generation, I: Io>(
    driver: HostDriver<K>,
    settings: &Settings,
    io: &mut I,
    latency: &mut Latency,
) -> End {
    let (scale, _) = odom::scale(&settings.params);
    let mut node = Node {
        driver,
        settings,
        io,
        frames: Frames {
            odom: settings.params.odom_frame.clone(),
            base: settings.params.base_frame.clone(),
        },
        start: Instant::now(),
        watchdog: Watchdog::new((settings.params.cmd_vel_timeout * 1000.0).round() as u64),
        odometry: odom::odometry(&settings.params),
        scale,
        counters: Counters::default(),
        latency,
        fresh: None,
        last_sent_ms: None,
        next_odom_ms: 0,
        next_diagnostics_ms: 0,
        next_battery_ms: 0,
        failsafe_seen: 0,
        said: HashSet::new(),
    };
    let ending = loop {
        if let Some(ending) = ending::ended() {
            break Some(ending);
        }
        if node.io.finished() {
            break None;
        }
        node.step();
        node.io.wait(Duration::from_millis(1));
    };
    let stopped = stopping::stop(&mut node.driver);
    End { ending, stopped }
}

/// A period in ms from a rate in Hz (at least 1 ms).
fn period_ms(hz: f64) -> u64 {
    ((1000.0 / hz).round() as u64).max(1)
}

impl<K: Generation, I: Io> Node<'_, K, I> {
    /// ms since the loop started (monotonic).
    fn now_ms(&self) -> u64 {
        u64::try_from(self.start.elapsed().as_millis()).unwrap_or(u64::MAX)
    }

    /// Says `line` on stderr, the first time only for each `what` (the counts go on in the
    /// diagnostics).
    fn once(&mut self, what: &str, line: String) {
        if self.said.insert(what.to_string()) {
            tell!("{}: {line}", self.settings.name);
        }
    }

    fn header(&self, frame: &str) -> Header {
        Header {
            stamp: Time::from_nanos(self.io.now_ns()),
            frame_id: frame.into(),
        }
    }

    /// One turn of the loop.
    fn step(&mut self) {
        while let Some(incoming) = self.io.take() {
            self.intake(incoming);
        }
        self.command();
        self.pump();
        self.publish_timed();
    }

    /// A command taken in: checked, then held by the watchdog.
    fn intake(&mut self, incoming: Incoming) {
        let now_ms = self.now_ms();
        let mut twist = match &incoming.command {
            Command::Twist(t) => convert::planar(t),
            Command::Stamped(s) => convert::planar(&s.twist),
        };
        if twist.vy != 0.0 && self.settings.params.drive == DriveKind::Differential {
            twist.vy = 0.0;
            self.counters.sideways_refused = self.counters.sideways_refused.saturating_add(1);
            self.once("sideways", "sideways speed (linear.y) refused: the chassis is differential (parameter drive); x and the turn are followed".into());
        }
        match incoming.command {
            Command::Twist(_) => self.watchdog.command(now_ms, twist),
            Command::Stamped(s) => {
                let stamp = s.header.stamp.to_nanos();
                if let Verdict::Stale { age_ns } =
                    self.watchdog
                        .stamped(now_ms, stamp, self.io.now_ns(), twist)
                {
                    self.counters.stale_commands = self.watchdog.stale();
                    self.once(
                        "stale",
                        format!(
                        "stale TwistStamped ignored: its stamp is {:.3} s old, more than cmd_vel_timeout {} s (clocks out of step, or a stamp of 0?)",
                        age_ns as f64 / 1e9,
                        self.settings.params.cmd_vel_timeout
                    ),
                    );
                    return;
                }
            }
        }
        self.fresh = Some(incoming.arrived_ns);
    }

    /// Sends what the watchdog wants: a new command at once, the one held every
    /// [`COMMAND_PERIOD_MS`], the stop once `/cmd_vel` went silent.
    fn command(&mut self) {
        let now_ms = self.now_ms();
        match self.watchdog.wanted(now_ms) {
            Wanted::Move(twist) => {
                let due = self
                    .last_sent_ms
                    .is_none_or(|t| now_ms.saturating_sub(t) >= COMMAND_PERIOD_MS);
                if self.fresh.is_none() && !due {
                    return;
                }
                let arrived = self.fresh.take();
                self.last_sent_ms = Some(now_ms);
                match K::send(&mut self.driver, twist, &self.scale) {
                    Ok(()) => {
                        if let Some(arrived) = arrived {
                            let ns = self.io.now_ns().saturating_sub(arrived);
                            self.latency.add(u64::try_from(ns).unwrap_or(0));
                        }
                    }
                    Err(_) if ending::ended().is_some() => {}
                    Err(e) => {
                        self.counters.send_errors = self.counters.send_errors.saturating_add(1);
                        let words = stopping::explain(&self.driver, e);
                        self.once("send", format!("the velocity could not be sent: {words}"));
                    }
                }
            }
            Wanted::Stop => {
                self.counters.watchdog_stops = self.watchdog.stops();
                self.last_sent_ms = None;
                self.fresh = None;
                if let Err(e) = self.driver.stop() {
                    let words = stopping::explain(&self.driver, e);
                    self.once(
                        "stop",
                        format!(
                            "/cmd_vel silent for {} s, but the stop could not be sent: {words}",
                            self.settings.params.cmd_vel_timeout
                        ),
                    );
                }
            }
            Wanted::Idle => {}
        }
    }

    /// Takes in what the board sent; says when the driver's failsafe stopped the chassis.
    fn pump(&mut self) {
        for _ in 0..64 {
            match self.driver.poll() {
                Ok(Some(event)) => {
                    for reading in K::readings(&event, &self.driver) {
                        self.reading(reading);
                    }
                }
                Ok(None) => break,
                // The port's waits end once a signal came: the loop's next turn stops.
                Err(_) if ending::ended().is_some() => break,
                Err(e) => {
                    let words = stopping::explain(&self.driver, e);
                    self.once("poll", format!("reading the board: {words} (still trying)"));
                    break;
                }
            }
        }
        let stops = self.driver.core().failsafe_stops();
        if stops > self.failsafe_seen {
            self.failsafe_seen = stops;
            let words = stopping::failsafe_words(&self.driver, "stopped the chassis");
            self.once(
                "failsafe",
                format!("{words} (still trying; /diagnostics counts the failsafe's stops)"),
            );
        }
    }

    fn reading(&mut self, reading: Reading) {
        match reading {
            Reading::Encoders { ticks, at_ms } => {
                self.odometry.encoders(ticks, at_ms);
            }
            Reading::Body { twist, yaw, at_ms } => self.odometry.body(twist, yaw, at_ms),
            Reading::Imu {
                accel,
                gyro,
                orientation,
            } => {
                let header = self.header(&self.settings.params.imu_frame);
                let imu = convert::imu(header, accel, gyro, orientation, &self.settings.imu);
                self.io.publish(Out::Imu(imu));
            }
            Reading::Battery { volts, fraction } => {
                let now_ms = self.now_ms();
                if now_ms >= self.next_battery_ms {
                    self.next_battery_ms = now_ms.saturating_add(900);
                    let header = self.header(&self.settings.params.base_frame);
                    self.io
                        .publish(Out::Battery(convert::battery(header, volts, fraction)));
                }
            }
        }
    }

    /// `/odom` and `/tf` at `odom_rate`, `/diagnostics` at `diagnostics_rate`.
    fn publish_timed(&mut self) {
        let now_ms = self.now_ms();
        let params = &self.settings.params;
        if now_ms >= self.next_odom_ms {
            self.next_odom_ms = now_ms.saturating_add(period_ms(params.odom_rate));
            let stamp = Time::from_nanos(self.io.now_ns());
            let pose = self.odometry.pose();
            let odom = convert::odometry(
                stamp,
                &self.frames,
                pose,
                self.odometry.twist(),
                self.odometry.pose_covariance(),
                self.odometry.twist_covariance(),
            );
            self.io.publish(Out::Odom(Box::new(odom)));
            if params.publish_tf {
                let tf = convert::transform(stamp, &self.frames, pose);
                self.io.publish(Out::Tf(tf));
            }
        }
        if now_ms >= self.next_diagnostics_ms {
            self.next_diagnostics_ms = now_ms.saturating_add(period_ms(params.diagnostics_rate));
            let link = K::link(&self.driver);
            let array = diagnostics::array(
                self.header(""),
                &self.settings.name,
                K::NAME,
                &self.settings.port,
                &link,
                &self.counters,
            );
            self.io.publish(Out::Diagnostics(array));
        }
    }
}
