//! The firmware in an emulator against the simulated chassis: starts the simulated board on a
//! loopback TCP port, boots a firmware ELF in `qemu-system-arm` with its UART0 connected to it,
//! records every frame the firmware sends (with the board's time), applies a [`Scenario`]'s
//! faults, and returns what happened. Used by `cargo xtask demo`, the board's `cargo run`
//! runner, and the end-to-end tests (`tests/qemu.rs`).
//!
//! The board is either generation ([`Served`]): [`run`]`::<`[`Board`]`>` serves the 2020 board
//! (`FF FE` frames, what callers get by default through [`Run`]'s and [`Progress`]'s default
//! type), `run::<`[`v1::Board`]`>` the v1.0.0 one (`7B … BCC 7D`); the firmware finds out which
//! by itself.

use chassis_protocol::sim::{Board, Faults, SimConfig, Simulated, v1};
use chassis_protocol::v1::Parser as _;
use chassis_protocol::{Command, UplinkParser};
use std::io::{self, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command as Process, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// What the simulated board does to the firmware.
#[derive(Clone, Copy, Debug, Default)]
pub struct Scenario {
    /// Seed of the board's noise and faults.
    pub seed: u64,
    /// Line faults from the start (per million bytes), and whether replies never come.
    pub faults: Faults,
    /// The board goes silent (no telemetry, no replies) this long after the firmware first
    /// commands a motion, ms.
    pub silent_after_motion_ms: Option<u64>,
}

/// A simulated board the harness serves: the 2020 [`Board`] or the v1.0.0 [`v1::Board`].
pub trait Served: Simulated + Sized {
    /// A frame the firmware sends it.
    type Command: Clone + std::fmt::Debug + PartialEq;
    /// Its parser of the firmware's bytes.
    type Parser;

    /// The board just powered up, its noise and faults seeded with `seed`.
    fn power_up(seed: u64) -> Self;
    /// Line faults from now on.
    fn set_faults(&mut self, faults: Faults);
    /// A parser that has seen nothing.
    fn parser() -> Self::Parser;
    /// The frames `bytes` complete, in order.
    fn parse(parser: &mut Self::Parser, bytes: &[u8]) -> Vec<Self::Command>;
    /// Whether `command` makes the chassis move.
    fn moves(command: &Self::Command) -> bool;
}

impl Served for Board {
    type Command = Command;
    type Parser = UplinkParser;

    fn power_up(seed: u64) -> Self {
        Board::new(SimConfig {
            seed,
            ..SimConfig::default()
        })
    }
    fn set_faults(&mut self, faults: Faults) {
        Board::set_faults(self, faults);
    }
    fn parser() -> UplinkParser {
        UplinkParser::new()
    }
    fn parse(parser: &mut UplinkParser, bytes: &[u8]) -> Vec<Command> {
        parser.frames(bytes).collect()
    }
    fn moves(command: &Command) -> bool {
        is_motion(command)
    }
}

impl Served for v1::Board {
    type Command = chassis_protocol::v1::Command;
    type Parser = chassis_protocol::v1::UplinkParser;

    fn power_up(seed: u64) -> Self {
        v1::Board::new(v1::SimConfig {
            seed,
            ..v1::SimConfig::default()
        })
    }
    fn set_faults(&mut self, faults: Faults) {
        v1::Board::set_faults(self, faults);
    }
    fn parser() -> Self::Parser {
        chassis_protocol::v1::UplinkParser::new()
    }
    fn parse(parser: &mut Self::Parser, bytes: &[u8]) -> Vec<Self::Command> {
        parser.frames(bytes).collect()
    }
    fn moves(command: &Self::Command) -> bool {
        is_motion_v1(command)
    }
}

/// A frame the firmware sent, with the board's time when it arrived (a 2020 [`Command`] by
/// default, or a v1.0.0 one).
#[derive(Clone, Debug, PartialEq)]
pub struct Sent<C = Command> {
    /// Board time, ms since the firmware connected.
    pub at_ms: u64,
    /// The frame.
    pub command: C,
}

/// How a run ended (against the 2020 board by default, or the v1.0.0 one).
#[derive(Debug)]
pub struct Run<B: Served = Board> {
    /// QEMU's exit status (the firmware's semihosting exit code); `None` if it was killed at
    /// the time limit.
    pub status: Option<ExitStatus>,
    /// Everything the firmware sent, in order.
    pub sent: Vec<Sent<B::Command>>,
    /// When the board went silent (board time, ms), if it did.
    pub silenced_at_ms: Option<u64>,
    /// The board at the end (registers or settings, motion, what it received).
    pub board: B,
    /// What the board sent, as written to the link: (board time in ms, bytes).
    pub downlink: Vec<(u64, Vec<u8>)>,
    /// The firmware's raw stdout (defmt frames over semihosting).
    pub log: Vec<u8>,
    /// Wall time from QEMU's start to its end.
    pub elapsed: Duration,
}

impl<B: Served> Run<B> {
    /// The exit code, if QEMU exited by itself.
    pub fn exit_code(&self) -> Option<i32> {
        self.status.and_then(|s| s.code())
    }
}

/// Where the emulator is and how long a run may take.
#[derive(Clone, Debug)]
pub struct Emulator {
    /// The `qemu-system-arm` binary.
    pub qemu: PathBuf,
    /// QEMU's machine and CPU arguments.
    pub machine: &'static [&'static str],
    /// A run is killed after this.
    pub limit: Duration,
}

impl Emulator {
    /// QEMU's mps2-an386 (Cortex-M4), found on `PATH`.
    pub fn mps2_an386() -> Self {
        Emulator {
            qemu: PathBuf::from("qemu-system-arm"),
            machine: &["-machine", "mps2-an386", "-cpu", "cortex-m4"],
            limit: Duration::from_secs(60),
        }
    }
}

/// What the run reports while it goes (for a live view): called about every 250 ms.
#[derive(Clone, Copy, Debug)]
pub struct Progress<'a, B: Served = Board> {
    /// Board time, ms.
    pub now_ms: u64,
    /// The board.
    pub board: &'a B,
    /// Frames the firmware sent so far.
    pub sent: usize,
    /// The last frame it sent.
    pub last: Option<&'a Sent<B::Command>>,
}

/// Boots `elf` in the emulator against a simulated board `B` (the 2020 [`Board`] or the
/// v1.0.0 [`v1::Board`]), until the firmware exits or the limit passes. `on_log` gets the
/// firmware's stdout as it comes (e.g. to pipe it to `defmt-print`), `on_progress` the board's
/// state about four times a second.
pub fn run<B: Served>(
    emulator: &Emulator,
    elf: &Path,
    scenario: &Scenario,
    mut on_log: impl FnMut(&[u8]),
    mut on_progress: impl FnMut(Progress<'_, B>),
) -> io::Result<Run<B>> {
    let listener = TcpListener::bind("127.0.0.1:0")?;
    let port = listener.local_addr()?.port();
    let started = Instant::now();
    let mut qemu = Process::new(&emulator.qemu)
        .args(emulator.machine)
        .args(["-display", "none", "-monitor", "none"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .arg("-kernel")
        .arg(elf)
        .arg("-serial")
        .arg(format!("tcp:127.0.0.1:{port},nodelay=on"))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| io::Error::new(e.kind(), format!("cannot start {:?}: {e}", emulator.qemu)))?;
    let guard = KillOnDrop(&mut qemu);
    let (log_tx, log_rx) = mpsc::channel::<Vec<u8>>();
    if let Some(mut stdout) = guard.0.stdout.take() {
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = stdout.read(&mut buf) {
                if n == 0 || log_tx.send(buf[..n].to_vec()).is_err() {
                    break;
                }
            }
        });
    }
    let stream = accept_within(&listener, guard.0, Duration::from_secs(10))?;
    stream.set_nodelay(true)?;
    // Non-blocking with a short sleep, not a read timeout: socket timeouts are counted in the
    // kernel's ticks (4 ms or more), which would hand the firmware its bytes in bursts.
    stream.set_nonblocking(true)?;
    let mut io = stream;

    let mut board = B::power_up(scenario.seed);
    board.set_faults(scenario.faults);
    let connected = Instant::now();
    let mut parser = B::parser();
    let mut sent: Vec<Sent<B::Command>> = Vec::new();
    let mut log = Vec::new();
    let mut downlink = Vec::new();
    let mut silenced_at_ms = None;
    let mut first_motion_ms = None;
    let mut next_progress = 0u64;
    let mut buf = [0u8; 512];
    let status = loop {
        while let Ok(chunk) = log_rx.try_recv() {
            on_log(&chunk);
            log.extend_from_slice(&chunk);
        }
        if let Some(status) = guard.0.try_wait()? {
            break Some(status);
        }
        if started.elapsed() > emulator.limit {
            break None;
        }
        let now_ms = u64::try_from(connected.elapsed().as_millis()).unwrap_or(u64::MAX);
        match io.read(&mut buf) {
            Err(e) if e.kind() == io::ErrorKind::ConnectionReset => {
                std::thread::sleep(Duration::from_millis(5));
            }
            Ok(0) => {
                // QEMU closed the link: it is exiting; wait for its status.
                std::thread::sleep(Duration::from_millis(5));
            }
            Ok(n) => {
                let bytes = &buf[..n];
                board.receive(bytes);
                for command in B::parse(&mut parser, bytes) {
                    if first_motion_ms.is_none() && B::moves(&command) {
                        first_motion_ms = Some(now_ms);
                    }
                    sent.push(Sent {
                        at_ms: now_ms,
                        command,
                    });
                }
            }
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::TimedOut
                        | io::ErrorKind::WouldBlock
                        | io::ErrorKind::Interrupted
                ) =>
            {
                std::thread::sleep(Duration::from_micros(200));
            }
            Err(e) => return Err(e),
        }
        if let (Some(after), Some(moved), None) = (
            scenario.silent_after_motion_ms,
            first_motion_ms,
            silenced_at_ms,
        ) {
            if now_ms >= moved + after {
                board.set_faults(Faults {
                    telemetry_stopped: true,
                    replies_stopped: true,
                    ..scenario.faults
                });
                silenced_at_ms = Some(now_ms);
            }
        }
        board.advance(now_ms);
        loop {
            let n = board.transmit(&mut buf);
            if n == 0 {
                break;
            }
            downlink.push((now_ms, buf[..n].to_vec()));
            // A closed link while QEMU exits is not an error of the run.
            if write_all_nonblocking(&mut io, &buf[..n]).is_err() {
                break;
            }
        }
        if now_ms >= next_progress {
            next_progress = now_ms + 250;
            on_progress(Progress {
                now_ms,
                board: &board,
                sent: sent.len(),
                last: sent.last(),
            });
        }
    };
    // The rest of the log.
    drop(io);
    let deadline = Instant::now() + Duration::from_millis(500);
    while Instant::now() < deadline {
        match log_rx.recv_timeout(Duration::from_millis(50)) {
            Ok(chunk) => {
                on_log(&chunk);
                log.extend_from_slice(&chunk);
            }
            Err(mpsc::RecvTimeoutError::Timeout) if status.is_none() => break,
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    Ok(Run {
        status,
        sent,
        silenced_at_ms,
        board,
        log,
        downlink,
        elapsed: started.elapsed(),
    })
}

/// Writes all of `bytes` to a non-blocking socket, waiting out a full send buffer.
fn write_all_nonblocking(io: &mut TcpStream, mut bytes: &[u8]) -> io::Result<()> {
    while !bytes.is_empty() {
        match io.write(bytes) {
            Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
            Ok(n) => bytes = &bytes[n..],
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => {
                std::thread::sleep(Duration::from_micros(200));
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// Decodes a firmware's defmt log with `defmt-print` (which needs the ELF for its strings):
/// one line per message, without time stamps.
pub fn decode_log(elf: &Path, raw: &[u8]) -> io::Result<String> {
    let mut child = Process::new("defmt-print")
        .arg("-e")
        .arg(elf)
        .args(["--log-format", "{L} {s}"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| {
            io::Error::new(
                e.kind(),
                format!("cannot start defmt-print ({e}): cargo install --locked defmt-print"),
            )
        })?;
    if let Some(mut stdin) = child.stdin.take() {
        stdin.write_all(raw)?;
    }
    let output = child.wait_with_output()?;
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

/// A frame that makes the chassis move (a non-zero velocity, a turn, a motor command).
pub fn is_motion(command: &Command) -> bool {
    match command {
        Command::Velocity(v) => v.x != 0 || v.y != 0 || v.z != 0,
        Command::Turn(_) | Command::Motors(_) => true,
        Command::Setting(_) => false,
    }
}

/// A v1.0.0 frame that makes the chassis move: a body or per-motor velocity that drives
/// (`ctl` 2) at something other than zero. The forced stop does not.
pub fn is_motion_v1(command: &chassis_protocol::v1::Command) -> bool {
    use chassis_protocol::v1::{BodyVelocity, Command as V1};
    match command {
        V1::BodyVelocity(v) => {
            v.ctl == BodyVelocity::DRIVE && (v.vx_mm_s != 0 || v.vy_mm_s != 0 || v.wz_mrad_s != 0)
        }
        V1::MotorVelocity(m) => m.ctl == BodyVelocity::DRIVE && m.speeds != [0; 4],
        _ => false,
    }
}

/// Kills QEMU if the run ends early (an error, a panic in a test).
struct KillOnDrop<'a>(&'a mut Child);

impl Drop for KillOnDrop<'_> {
    fn drop(&mut self) {
        if matches!(self.0.try_wait(), Ok(None)) {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }
}

fn accept_within(
    listener: &TcpListener,
    qemu: &mut Child,
    limit: Duration,
) -> io::Result<TcpStream> {
    listener.set_nonblocking(true)?;
    let start = Instant::now();
    loop {
        match listener.accept() {
            Ok((stream, _)) => {
                stream.set_nonblocking(false)?;
                return Ok(stream);
            }
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => {}
            Err(e) => return Err(e),
        }
        if let Some(status) = qemu.try_wait()? {
            let mut err = String::new();
            if let Some(mut stderr) = qemu.stderr.take() {
                let _ = stderr.read_to_string(&mut err);
            }
            return Err(io::Error::other(format!(
                "QEMU exited ({status}) before connecting its UART: {}",
                err.trim()
            )));
        }
        if start.elapsed() > limit {
            return Err(io::Error::new(
                io::ErrorKind::TimedOut,
                "QEMU did not connect its UART within 10 s",
            ));
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}
