//! What the node's tests share: a simulated board of either generation served on a
//! pseudo-terminal (the node opens its path as it opens a real port), every byte the node
//! sends to it logged with its time; and a scripted ROS side ([`Script`]) that gives the node
//! its commands at set times and keeps what it publishes.

#![allow(dead_code)]

use chassis_ros2::msg::{Header, Time, Twist, TwistStamped, Vector3};
use chassis_ros2::node::{Command, Incoming, Io, Out};
use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Bytes the node wrote, each read by the board at an instant.
pub type Log = Arc<Mutex<Vec<(Instant, Vec<u8>)>>>;

/// The board's end of the line: what it reads is logged; muted, what it writes is lost (a
/// board gone silent).
struct Tap<T> {
    inner: T,
    log: Log,
    mute: Arc<AtomicBool>,
}

impl<T: Read> Read for Tap<T> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if n > 0
            && let Ok(mut log) = self.log.lock()
        {
            log.push((Instant::now(), buf[..n].to_vec()));
        }
        Ok(n)
    }
}

impl<T: Write> Write for Tap<T> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.mute.load(Ordering::Relaxed) {
            return Ok(buf.len());
        }
        self.inner.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// A simulated board served on a pseudo-terminal until dropped.
pub struct Sim {
    /// The path the node opens.
    pub path: String,
    /// What the node sent.
    pub log: Log,
    /// Set: the board's bytes no longer reach the node.
    pub mute: Arc<AtomicBool>,
    stop: Arc<AtomicBool>,
    /// The board's true pose when it stopped: x, y (m), yaw (rad).
    thread: Option<JoinHandle<Option<(f64, f64, f64)>>>,
    /// The other end, kept open so that the line stays up between the node's opens.
    _slave: serialport::TTYPort,
}

impl Sim {
    /// Serves `board` on a new pseudo-terminal.
    pub fn serve<B: chassis_protocol::sim::Simulated + Send + 'static>(board: B) -> Sim {
        use serialport::SerialPort as _;
        let (mut master, slave) = serialport::TTYPort::pair().expect("a pseudo-terminal");
        master
            .set_timeout(Duration::from_millis(1))
            .expect("a timeout");
        let path = slave.name().expect("the pty's path");
        let log: Log = Arc::default();
        let stop = Arc::new(AtomicBool::new(false));
        let mute = Arc::new(AtomicBool::new(false));
        let tap = Tap {
            inner: master,
            log: Arc::clone(&log),
            mute: Arc::clone(&mute),
        };
        let stopping = Arc::clone(&stop);
        let thread = std::thread::spawn(move || {
            chassis_protocol::sim::serve(board, tap, &stopping)
                .ok()
                .and_then(|board| chassis_protocol::sim::Simulated::pose(&board))
        });
        Sim {
            path,
            log,
            mute,
            stop,
            thread: Some(thread),
            _slave: slave,
        }
    }

    /// A 2020 board (the simulator's fixed mecanum geometry).
    pub fn v2020() -> Sim {
        Sim::serve(chassis_protocol::sim::Board::new(
            chassis_protocol::sim::SimConfig::default(),
        ))
    }

    /// A v1.0.0 board.
    pub fn v1() -> Sim {
        Sim::serve(chassis_protocol::sim::v1::Board::new(
            chassis_protocol::sim::v1::SimConfig::default(),
        ))
    }

    /// The 2020 velocity frames the board took, with when: (time, x, y, z).
    pub fn velocities_2020(&self) -> Vec<(Instant, i32, i32, i32)> {
        settle();
        let mut parser = chassis_protocol::UplinkParser::new();
        let mut out = Vec::new();
        for (at, bytes) in self.log.lock().unwrap().iter() {
            for byte in bytes {
                if let Some(chassis_protocol::command::Command::Velocity(v)) = parser.push(*byte) {
                    out.push((*at, v.x, v.y, v.z));
                }
            }
        }
        out
    }

    /// The v1.0.0 body-velocity frames the board took: (time, vx, vy, wz, forced stop).
    pub fn velocities_v1(&self) -> Vec<(Instant, i16, i16, i16, bool)> {
        settle();
        let mut parser = chassis_protocol::v1::UplinkParser::new();
        let mut out = Vec::new();
        for (at, bytes) in self.log.lock().unwrap().iter() {
            for byte in bytes {
                if let Some(chassis_protocol::v1::Command::BodyVelocity(v)) = parser.push(*byte) {
                    let stop = v == chassis_protocol::v1::BodyVelocity::FORCED_STOP;
                    out.push((*at, v.vx_mm_s, v.vy_mm_s, v.wz_mrad_s, stop));
                }
            }
        }
        out
    }
}

impl Sim {
    /// Stops the board: where it truly is (x, y in m, yaw in rad, REP-103).
    pub fn true_pose(mut self) -> (f64, f64, f64) {
        self.stop.store(true, Ordering::Relaxed);
        self.thread
            .take()
            .and_then(|t| t.join().ok().flatten())
            .expect("the board's pose")
    }
}

/// Lets the board read what was last written (it reads every millisecond).
fn settle() {
    std::thread::sleep(Duration::from_millis(50));
}

impl Drop for Sim {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The ROS side, scripted: commands given at set times after the start, what the node
/// publishes kept with its time, the end at a set time.
pub struct Script {
    pub start: Instant,
    /// (ms after the start, the command).
    pub commands: Vec<(u64, Command)>,
    next: usize,
    pub end_ms: u64,
    pub published: Vec<(Instant, Out)>,
    /// When each command was given to the node.
    pub given: Vec<Instant>,
    /// Something to do once, at a time (ms): raising a signal.
    pub at: Option<(u64, Box<dyn FnOnce()>)>,
}

impl Script {
    pub fn new(commands: Vec<(u64, Command)>, end_ms: u64) -> Script {
        Script {
            start: Instant::now(),
            commands,
            next: 0,
            end_ms,
            published: Vec::new(),
            given: Vec::new(),
            at: None,
        }
    }

    fn elapsed_ms(&self) -> u64 {
        self.start.elapsed().as_millis() as u64
    }
}

/// The system clock, ns since the Unix epoch (the node's ROS clock).
pub fn system_ns() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos() as i64)
        .unwrap_or(0)
}

impl Io for Script {
    fn take(&mut self) -> Option<Incoming> {
        let (ms, command) = self.commands.get(self.next)?;
        if self.elapsed_ms() < *ms {
            return None;
        }
        // A stamped command's stamp was made with the script: it is moved on by the time
        // since, so that its age when given is the age it was made with.
        let command = match command.clone() {
            Command::Stamped(mut s) => {
                let since = self.start.elapsed().as_nanos() as i64;
                s.header.stamp = Time::from_nanos(s.header.stamp.to_nanos() + since);
                Command::Stamped(s)
            }
            other => other,
        };
        self.next += 1;
        self.given.push(Instant::now());
        Some(Incoming {
            command,
            arrived_ns: system_ns(),
        })
    }

    fn now_ns(&self) -> i64 {
        system_ns()
    }

    fn publish(&mut self, out: Out) {
        self.published.push((Instant::now(), out));
    }

    fn finished(&mut self) -> bool {
        let due = self
            .at
            .as_ref()
            .is_some_and(|(ms, _)| self.elapsed_ms() >= *ms);
        if due && let Some((_, act)) = self.at.take() {
            act();
        }
        self.elapsed_ms() >= self.end_ms
    }
}

/// A `Twist`: forward `vx`, left `vy` (m/s), turning `wz` (rad/s).
pub fn twist(vx: f64, vy: f64, wz: f64) -> Twist {
    Twist {
        linear: Vector3 {
            x: vx,
            y: vy,
            z: 0.0,
        },
        angular: Vector3 {
            x: 0.0,
            y: 0.0,
            z: wz,
        },
    }
}

/// A `TwistStamped` stamped `age_ms` before it is given ([`Script`] moves its stamp on).
pub fn stamped(twist: Twist, age_ms: i64) -> Command {
    Command::Stamped(TwistStamped {
        header: Header {
            stamp: Time::from_nanos(system_ns() - age_ms * 1_000_000),
            frame_id: "base_link".into(),
        },
        twist,
    })
}

/// `Command::Twist` every `every_ms` from `from_ms` to `to_ms` (inclusive).
pub fn steady(twist: Twist, from_ms: u64, to_ms: u64, every_ms: u64) -> Vec<(u64, Command)> {
    (from_ms..=to_ms)
        .step_by(every_ms as usize)
        .map(|t| (t, Command::Twist(twist)))
        .collect()
}

/// The settings the tests run the node with: the given parameters, the documented defaults
/// for the rest.
pub fn settings(path: &str, params: chassis_ros2::params::Params) -> chassis_ros2::node::Settings {
    chassis_ros2::node::Settings {
        name: "chassis".into(),
        port: path.into(),
        params,
        imu: chassis_ros2::convert::ImuScale {
            accel_per_g: 16_384.0,
            gyro_per_rad_s: 1000.0,
            accel_variance: 0.04,
            gyro_variance: 0.0004,
            orientation_variance: 0.001,
        },
    }
}

/// ms from `a` to `b` (negative when `b` is first).
pub fn ms_between(a: Instant, b: Instant) -> f64 {
    if b >= a {
        (b - a).as_secs_f64() * 1000.0
    } else {
        -((a - b).as_secs_f64() * 1000.0)
    }
}

/// Runs the 2020 node on a simulated board, commanded forward all along, and raises `signal`
/// in the process 400 ms in: the loop must end on it with the chassis stopped at once.
pub fn stops_on(signal: i32, status: u8) {
    use chassis_cli::ending::{self, Ending};
    use chassis_protocol::driver::DriverCore;
    use chassis_ros2::board::Generation;
    ending::catch_from_start();
    ending::for_command(ending::Kind::Brief);
    let sim = Sim::v2020();
    let mut script = Script::new(steady(twist(0.2, 0.0, 0.0), 0, 3_000, 100), 3_000);
    let raised = Arc::new(Mutex::new(None));
    let when = Arc::clone(&raised);
    script.at = Some((
        400,
        Box::new(move || {
            *when.lock().unwrap() = Some(Instant::now());
            signal_hook::low_level::raise(signal).expect("raised");
        }),
    ));
    let driver = DriverCore::open(&sim.path).expect("the pty opens");
    let mut latency = chassis_ros2::stats::Latency::default();
    let end = chassis_ros2::node::run(
        driver,
        &settings(&sim.path, chassis_ros2::params::Params::default()),
        &mut script,
        &mut latency,
    );
    let raised = raised.lock().unwrap().expect("the signal was raised");
    assert_eq!(end.ending, Some(Ending::Signal(signal)));
    assert_eq!(Ending::Signal(signal).exit_status(), status);
    assert!(end.stopped.confirmed(), "{:?}", end.stopped);
    assert!(
        ms_between(script.start, Instant::now()) < 2_000.0,
        "ended on the signal, not at the script's end"
    );
    let frames = sim.velocities_2020();
    let stop = frames
        .iter()
        .find(|f| f.0 > raised && (f.1, f.2, f.3) == (0, 0, 0))
        .expect("a stop after the signal");
    let after = ms_between(raised, stop.0);
    assert!(after < 50.0, "stopped {after:.1} ms after the signal");
    assert!(
        frames.iter().any(|f| f.0 < raised && f.2 == 200),
        "it was moving"
    );
    assert!(
        frames
            .iter()
            .filter(|f| f.0 > stop.0)
            .all(|f| (f.1, f.2, f.3) == (0, 0, 0)),
        "nothing moved it after the stop"
    );
}
