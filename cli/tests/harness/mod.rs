//! What the CLI's tests share: a simulated board on a real pseudo-terminal that records every
//! byte it is sent and can go silent, a terminal for the commands that need one, and the spec's
//! stop frame; the golden captures and their decoding ([`decoding`]); the v1.0.0 board and its
//! frames ([`v1`]); the monitor's failsafe hold ([`monitor`]).

#![allow(dead_code)]

pub mod decoding;
pub mod monitor;
pub mod v1;

use chassis_protocol::sim::{Board, Faults, Motion, SimConfig, Simulated, serve};
use chassis_protocol::{Command, UplinkParser};
use serialport::{SerialPort as _, TTYPort};
use std::io::{self, Read, Write};
use std::process::{Child, Command as Process, Output, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The stop frame, from the spec's table 1A: velocity mode, X = Y = Z = 0, no direction bits.
pub const STOP: [u8; 10] = [0xFF, 0xFE, 0x01, 0, 0, 0, 0, 0, 0, 0];

/// The `chassis` binary under test: this package's, or the one `CHASSIS_BIN` names (the same
/// tests against another build: a release binary, an older commit).
pub fn bin() -> String {
    std::env::var("CHASSIS_BIN").unwrap_or_else(|_| env!("CARGO_BIN_EXE_chassis").to_string())
}

/// A pseudo-terminal pair, neither end passed on to the commands the test starts (a command
/// holding the other end would keep the line, or its terminal, from ever hanging up).
pub fn pty_pair() -> (TTYPort, TTYPort) {
    use nix::fcntl::{FcntlArg, FdFlag, fcntl};
    use std::os::fd::AsRawFd;
    let (a, b) = TTYPort::pair().expect("a pseudo-terminal");
    for end in [&a, &b] {
        fcntl(end.as_raw_fd(), FcntlArg::F_SETFD(FdFlag::FD_CLOEXEC)).expect("FD_CLOEXEC");
    }
    (a, b)
}

/// The board's end of the line: records what it reads, drops what it writes while silent,
/// drops the next `drop_replies` replies of the pending angle (`23 20 …`).
struct Tap {
    inner: TTYPort,
    heard: Arc<Mutex<Vec<u8>>>,
    /// When each read ended, and how many bytes had been heard by then.
    times: Arc<Mutex<Vec<(Instant, usize)>>>,
    silent: Arc<AtomicBool>,
    drop_replies: Arc<AtomicU32>,
    /// When the serving loop last read, and the times it did not for [`STALL`] or more: the
    /// machine starved the simulated board (when each began, how long).
    last_read: Option<Instant>,
    stalls: Arc<Mutex<Vec<(Instant, Duration)>>>,
}

/// A gap this long between two turns of the serving loop (which reads every millisecond or
/// so) is the machine starving the simulated board, not the board's behaviour.
const STALL: Duration = Duration::from_millis(100);

impl Read for Tap {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let now = Instant::now();
        if let Some(last) = self.last_read.replace(now) {
            if now.duration_since(last) >= STALL {
                self.stalls
                    .lock()
                    .unwrap()
                    .push((last, now.duration_since(last)));
            }
        }
        let n = self.inner.read(buf)?;
        let mut heard = self.heard.lock().unwrap();
        heard.extend_from_slice(&buf[..n]);
        if n > 0 {
            self.times
                .lock()
                .unwrap()
                .push((Instant::now(), heard.len()));
        }
        Ok(n)
    }
}

impl Write for Tap {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if self.silent.load(Ordering::SeqCst) {
            return Ok(buf.len());
        }
        if self.drop_replies.load(Ordering::SeqCst) > 0 {
            if let Some(at) = buf.windows(2).position(|w| w == [0x23, 0x20]) {
                if at + 6 <= buf.len() {
                    self.drop_replies.fetch_sub(1, Ordering::SeqCst);
                    let mut kept = buf[..at].to_vec();
                    kept.extend_from_slice(&buf[at + 6..]);
                    self.inner.write_all(&kept)?;
                    return Ok(buf.len());
                }
            }
        }
        self.inner.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// A simulated board (the 2020 one unless `B` says) served on a pseudo-terminal in a thread of
/// the test.
pub struct TestBoard<B = Board> {
    /// The path the CLI opens.
    pub path: String,
    stop: Arc<AtomicBool>,
    silent: Arc<AtomicBool>,
    drop_replies: Arc<AtomicU32>,
    heard: Arc<Mutex<Vec<u8>>>,
    times: Arc<Mutex<Vec<(Instant, usize)>>>,
    stalls: Arc<Mutex<Vec<(Instant, Duration)>>>,
    thread: Option<JoinHandle<io::Result<B>>>,
    _keep: TTYPort,
}

impl TestBoard {
    /// A board with factory settings.
    pub fn start() -> TestBoard {
        TestBoard::with(|_| {})
    }

    /// A board `setup` prepared (faults, registers).
    pub fn with(setup: impl FnOnce(&mut Board)) -> TestBoard {
        let mut board = Board::new(SimConfig::default());
        setup(&mut board);
        TestBoard::serving(board)
    }
}

impl<B: Simulated + Send + 'static> TestBoard<B> {
    /// `board`, served.
    pub fn serving(board: B) -> TestBoard<B> {
        let (mut board_end, path_end) = pty_pair();
        board_end.set_timeout(Duration::from_millis(1)).unwrap();
        let path = path_end.name().expect("its path");
        let stop = Arc::new(AtomicBool::new(false));
        let silent = Arc::new(AtomicBool::new(false));
        let drop_replies = Arc::new(AtomicU32::new(0));
        let heard = Arc::new(Mutex::new(Vec::new()));
        let times = Arc::new(Mutex::new(Vec::new()));
        let stalls = Arc::new(Mutex::new(Vec::new()));
        let tap = Tap {
            last_read: None,
            stalls: Arc::clone(&stalls),
            inner: board_end,
            heard: Arc::clone(&heard),
            times: Arc::clone(&times),
            silent: Arc::clone(&silent),
            drop_replies: Arc::clone(&drop_replies),
        };
        let flag = Arc::clone(&stop);
        let thread = std::thread::spawn(move || serve(board, tap, &flag));
        TestBoard {
            path,
            stop,
            silent,
            drop_replies,
            heard,
            times,
            stalls,
            thread: Some(thread),
            _keep: path_end,
        }
    }

    /// The board stops sending (it still hears everything).
    pub fn go_silent(&self, silent: bool) {
        self.silent.store(silent, Ordering::SeqCst);
    }

    /// The next `n` replies to reads of the pending angle are lost on the line.
    pub fn lose_pending_angle_replies(&self, n: u32) {
        self.drop_replies.store(n, Ordering::SeqCst);
    }

    /// Every byte the board was sent so far.
    pub fn heard(&self) -> Vec<u8> {
        self.heard.lock().unwrap().clone()
    }

    /// When the board had heard its first `len` bytes (`None`: not yet).
    pub fn heard_by(&self, len: usize) -> Option<Instant> {
        self.times
            .lock()
            .unwrap()
            .iter()
            .find(|(_, total)| *total >= len)
            .map(|(at, _)| *at)
    }

    /// Whether the machine starved the simulated board (its serving loop did not turn for 100 ms
    /// or more) in a stretch that began before `at`.
    pub fn stalled_before(&self, at: Instant) -> bool {
        self.stalls
            .lock()
            .unwrap()
            .iter()
            .any(|(began, _)| *began < at)
    }

    /// `chassis --port PATH args`, run to its end.
    pub fn run(&self, args: &[&str]) -> Output {
        let mut all = vec!["--port", self.path.as_str()];
        all.extend_from_slice(args);
        chassis(&all)
    }

    /// `chassis --port PATH args`, started.
    pub fn spawn(&self, args: &[&str]) -> Child {
        let mut all = vec!["--port", self.path.as_str()];
        all.extend_from_slice(args);
        Process::new(bin())
            .args(&all)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    }

    /// Stops serving: the board as it ends, and every byte it was sent.
    pub fn finish(mut self) -> (B, Vec<u8>) {
        self.stop.store(true, Ordering::SeqCst);
        let board = self
            .thread
            .take()
            .unwrap()
            .join()
            .unwrap()
            .expect("the board served to the end");
        (board, self.heard())
    }
}

impl TestBoard {
    /// The commands the board was sent so far.
    pub fn commands(&self) -> Vec<Command> {
        commands(&self.heard())
    }

    /// Waits (up to 5 s) until the board was sent a command `want` accepts.
    pub fn wait_for(&self, what: &str, want: impl Fn(&Command) -> bool) {
        let start = Instant::now();
        while !self.commands().iter().any(&want) {
            assert!(
                start.elapsed() < Duration::from_secs(5),
                "the board was never sent {what}: {:?}",
                self.commands()
            );
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl<B> Drop for TestBoard<B> {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The commands in `bytes`, in order.
pub fn commands(bytes: &[u8]) -> Vec<Command> {
    let mut parser = UplinkParser::new();
    bytes.iter().filter_map(|b| parser.push(*b)).collect()
}

/// A command that sets the chassis moving.
pub fn moves(c: &Command) -> bool {
    match c {
        Command::Velocity(v) => v.x != 0 || v.y != 0 || v.z != 0,
        Command::Motors(m) => m.values.iter().any(|v| *v != 0),
        Command::Turn(t) => t.deci_degrees != 0 || t.x != 0 || t.y != 0,
        _ => false,
    }
}

/// The board ended still: told to stand still, and (with a turn cancelled) nothing left to
/// turn but what the cancel's read raced (a degree or two); the stop frame went out after
/// the last frame that moved it.
pub fn assert_stopped(board: &Board, heard: &[u8]) {
    assert_eq!(
        board.motion(),
        Motion::Velocity { x: 0, y: 0, z: 0 },
        "the board's last motion command stops it"
    );
    assert!(
        board.pending_deci_degrees().abs() <= 20,
        "no turn left pending: {} (0.1°)",
        board.pending_deci_degrees()
    );
    let last_stop = heard
        .windows(STOP.len())
        .rposition(|w| w == STOP)
        .expect("the stop frame, byte for byte");
    let cmds = commands(heard);
    let after_stop = commands(&heard[last_stop + STOP.len()..]);
    assert!(
        after_stop
            .iter()
            .all(|c| !matches!(c, Command::Velocity(_)) || !moves(c)),
        "nothing drove it after the stop: {after_stop:?} (all: {cmds:?})"
    );
}

/// `chassis args`, run to its end.
pub fn chassis(args: &[&str]) -> Output {
    Process::new(bin())
        .args(args)
        .stdin(Stdio::null())
        .output()
        .expect("the binary runs")
}

/// Sends `signal` ("INT", "TERM", "HUP", "KILL") to `child`.
pub fn signal(child: &Child, signal: &str) {
    let ok = Process::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok, "kill -{signal}");
}

/// Waits (up to `secs`) for `child` to end.
pub fn wait(child: Child, secs: u64) -> Output {
    let start = Instant::now();
    let mut child = child;
    loop {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        if start.elapsed() > Duration::from_secs(secs) {
            let _ = child.kill();
            let out = child.wait_with_output().unwrap();
            panic!(
                "did not end within {secs} s: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// A command run in a terminal of its own (a pseudo-terminal, 100 × 30): what it drew, and a
/// keyboard.
pub struct Terminal {
    /// The command.
    pub child: Child,
    master: Option<TTYPort>,
    /// The terminal's other end, held so that what the command wrote last stays readable after
    /// it exits (a terminal whose every other end is closed throws it away).
    slave: Option<TTYPort>,
    /// Columns and rows.
    size: (u16, u16),
    screen: Arc<Mutex<Vec<u8>>>,
    reader: Option<JoinHandle<()>>,
    done: Arc<AtomicBool>,
}

impl Terminal {
    /// Starts `chassis args` with its stdin, stdout and stderr on a new terminal.
    pub fn spawn(args: &[&str]) -> Terminal {
        Terminal::spawn_sized(args, 100, 30)
    }

    /// [`Terminal::spawn`] on a terminal of `cols` × `rows`.
    pub fn spawn_sized(args: &[&str], cols: u16, rows: u16) -> Terminal {
        let (master, slave) = pty_pair();
        let path = slave.name().unwrap();
        let open = || {
            std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .open(&path)
                .unwrap()
        };
        let ok = Process::new("stty")
            .args(["cols", &cols.to_string(), "rows", &rows.to_string()])
            .stdin(open())
            .status()
            .unwrap()
            .success();
        assert!(ok, "stty sets the terminal's size");
        let child = Process::new(bin())
            .args(args)
            .stdin(open())
            .stdout(open())
            .stderr(open())
            .spawn()
            .unwrap();
        let screen = Arc::new(Mutex::new(Vec::new()));
        let done = Arc::new(AtomicBool::new(false));
        let mut reading = master.try_clone_native().unwrap();
        reading.set_timeout(Duration::from_millis(20)).unwrap();
        let (into, stop) = (Arc::clone(&screen), Arc::clone(&done));
        let reader = std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while !stop.load(Ordering::SeqCst) {
                match reading.read(&mut buf) {
                    Ok(n) if n > 0 => into.lock().unwrap().extend_from_slice(&buf[..n]),
                    Ok(_) => {}
                    Err(e) if e.kind() == io::ErrorKind::TimedOut => {}
                    Err(_) => std::thread::sleep(Duration::from_millis(20)),
                }
            }
        });
        Terminal {
            child,
            master: Some(master),
            slave: Some(slave),
            size: (cols, rows),
            screen,
            reader: Some(reader),
            done,
        }
    }

    /// The screen as it stands (a terminal emulator replays everything drawn).
    pub fn text(&self) -> String {
        let mut parser = vt100::Parser::new(self.size.1, self.size.0, 0);
        parser.process(&self.screen.lock().unwrap());
        parser.screen().contents()
    }

    /// Everything written, escape sequences taken out (for a command that prints lines).
    pub fn written(&self) -> String {
        strip_escapes(&String::from_utf8_lossy(&self.screen.lock().unwrap()))
    }

    /// Waits (up to 5 s) until the screen shows `needle`.
    pub fn wait_for_text(&self, needle: &str) {
        let start = Instant::now();
        loop {
            let text = self.text();
            if text.contains(needle) {
                return;
            }
            assert!(
                start.elapsed() < Duration::from_secs(5),
                "{needle:?} never on the screen:\n{text}"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Types `keys`.
    pub fn press(&mut self, keys: &[u8]) {
        let master = self.master.as_mut().expect("the terminal is open");
        master.write_all(keys).unwrap();
        master.flush().unwrap();
    }

    /// Stops reading what the command writes, the terminal left open: once its buffer is full,
    /// the command's writes to it block (a stalled ssh link, a terminal paused).
    pub fn stop_reading(&mut self) {
        self.done.store(true, Ordering::SeqCst);
        if let Some(r) = self.reader.take() {
            let _ = r.join();
        }
    }

    /// Closes the terminal under the command, as a terminal window closed or an ssh session
    /// dropped does (the command is not the session's leader: no SIGHUP comes from the
    /// kernel; its terminal hangs up, reads end and writes fail).
    pub fn close(&mut self) {
        self.done.store(true, Ordering::SeqCst);
        if let Some(r) = self.reader.take() {
            let _ = r.join();
        }
        self.master = None;
        self.slave = None;
    }

    /// Waits (up to `secs`) for the command to end: its exit status.
    pub fn wait(&mut self, secs: u64) -> std::process::ExitStatus {
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status;
            }
            if start.elapsed() > Duration::from_secs(secs) {
                let _ = self.child.kill();
                panic!("did not end within {secs} s: {}", self.text());
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Drop for Terminal {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        self.done.store(true, Ordering::SeqCst);
        if let Some(r) = self.reader.take() {
            let _ = r.join();
        }
    }
}

/// `text` without ANSI escape sequences (CSI `ESC [ … letter`, and `ESC x`).
pub fn strip_escapes(text: &str) -> String {
    let mut out = String::new();
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        if c != '\u{1b}' {
            out.push(c);
            continue;
        }
        if chars.peek() == Some(&'[') {
            chars.next();
            for c in chars.by_ref() {
                if c.is_ascii_alphabetic() || c == '~' {
                    break;
                }
            }
        } else {
            chars.next();
        }
    }
    out
}

/// Faults that stop the board's replies (telemetry keeps coming).
pub fn no_replies() -> Faults {
    Faults {
        replies_stopped: true,
        ..Faults::default()
    }
}

/// The angles of the turns in `commands`, in 0.1°.
pub fn turns(commands: &[Command]) -> Vec<i32> {
    commands
        .iter()
        .filter_map(|c| match c {
            Command::Turn(t) => Some(t.deci_degrees),
            _ => None,
        })
        .collect()
}

/// A velocity command with this Y (forward).
pub fn forward(y: i32) -> impl Fn(&Command) -> bool {
    move |c| matches!(c, Command::Velocity(v) if v.y == y)
}

impl TestBoard {
    /// `chassis args`, started; once the board was sent what `want` accepts and `delay_ms`
    /// more have passed, `signal` ("INT"…) is sent; the command's end.
    pub fn signal_mid(
        &self,
        args: &[&str],
        what: &str,
        want: impl Fn(&Command) -> bool,
        delay_ms: u64,
        signal_name: &str,
    ) -> Output {
        let child = self.spawn(args);
        self.wait_for(what, want);
        std::thread::sleep(Duration::from_millis(delay_ms));
        signal(&child, signal_name);
        wait(child, 10)
    }

    /// `chassis monitor --drive` on this board in a terminal, the link up, `key` pressed and
    /// the board driven at Y = 300.
    pub fn monitor_driving(&self, key: &[u8], want: impl Fn(&Command) -> bool) -> Terminal {
        let mut term = Terminal::spawn(&["--port", &self.path, "monitor", "--drive"]);
        term.wait_for_text("LINK UP");
        term.press(key);
        self.wait_for("the key's velocity", want);
        term
    }
}

/// `chassis sim --pty EXTRA…` in the background: the process and the path it serves.
pub fn sim_pty(extra: &[&str]) -> (Child, String) {
    let mut child = Process::new(bin())
        .args(["sim", "--pty"])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut path = String::new();
    std::io::BufRead::read_line(
        &mut std::io::BufReader::new(child.stdout.take().unwrap()),
        &mut path,
    )
    .unwrap();
    (child, path.trim().to_string())
}

/// Another device on a pseudo-terminal, not the board: a steady stream of ASCII text (no `FF`,
/// no `7B`), and every byte it is sent.
pub struct OtherDevice {
    /// The path the CLI opens.
    pub path: String,
    stop: Arc<AtomicBool>,
    talker: Option<JoinHandle<Vec<u8>>>,
    _keep: TTYPort,
}

impl OtherDevice {
    /// Starts talking.
    pub fn start() -> OtherDevice {
        let (mut device_end, path_end) = pty_pair();
        device_end.set_timeout(Duration::from_millis(1)).unwrap();
        let path = path_end.name().expect("its path");
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let talker = std::thread::spawn(move || {
            let mut heard = Vec::new();
            let mut buf = [0u8; 64];
            let mut take_in = |device: &mut TTYPort, heard: &mut Vec<u8>| {
                while let Ok(n @ 1..) = device.read(&mut buf) {
                    heard.extend_from_slice(&buf[..n]);
                }
            };
            while !flag.load(Ordering::SeqCst) {
                let _ = device_end.write(b"temperature=21.5C\r\n");
                take_in(&mut device_end, &mut heard);
                std::thread::sleep(Duration::from_millis(5));
            }
            take_in(&mut device_end, &mut heard);
            heard
        });
        OtherDevice {
            path,
            stop,
            talker: Some(talker),
            _keep: path_end,
        }
    }

    /// Stops talking: every byte it was sent.
    pub fn finish(mut self) -> Vec<u8> {
        self.stop.store(true, Ordering::SeqCst);
        self.talker
            .take()
            .map(|t| t.join().unwrap())
            .unwrap_or_default()
    }
}

impl Drop for OtherDevice {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.talker.take() {
            let _ = t.join();
        }
    }
}
