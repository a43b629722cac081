//! `chassis sim`: the simulated board in real time on a pseudo-terminal or a TCP port, so that
//! every command can be tried without hardware (and the QEMU firmware has a chassis to drive).
//! Either firmware generation: the 2020 board (`FF FE` frames) or the v1.0.0 one (`7B … 7D`).

use chassis_protocol::sim::{
    self, Board, Faults, SimConfig, Simulated, serve, serve_observed, write_pose,
};
use std::io::{self, BufWriter, Read, Write};
use std::net::TcpListener;
use std::path::Path;
use std::sync::atomic::AtomicBool;

use chassis_protocol::detect::Firmware;

/// Line faults from a rate of errors per byte: a third each dropped, changed and added.
fn faults(rate: f64) -> Result<Faults, String> {
    if !(0.0..=0.5).contains(&rate) {
        return Err(format!(
            "--faults: {rate} errors per byte is out of range (0..=0.5)"
        ));
    }
    let per_million = (rate * 1e6 / 3.0).round() as u32;
    Ok(Faults {
        drop_per_million: per_million,
        corrupt_per_million: per_million,
        insert_per_million: per_million,
        ..Faults::default()
    })
}

/// The 2020 board with `seed` and `faults`.
pub fn board(seed: u64, faults: Faults) -> Board {
    let mut board = Board::new(SimConfig {
        seed,
        ..SimConfig::default()
    });
    board.set_faults(faults);
    board
}

/// The v1.0.0 board with `seed` and `faults`.
pub fn board_v1(seed: u64, faults: Faults) -> sim::v1::Board {
    let mut board = sim::v1::Board::new(sim::v1::SimConfig {
        seed,
        ..sim::v1::SimConfig::default()
    });
    board.set_faults(faults);
    board
}

/// `chassis sim`: serves the simulated board of `firmware` (2020 unless given) on a new
/// pseudo-terminal (`pty`) or to each client of a TCP listener on `tcp`, until the process is
/// stopped; prints where. With `pose`, the board's true pose goes to that file every 10 ms of
/// board time (`t_ms x_m y_m yaw_rad`, REP-103 axes), for an odometry to be measured against.
pub fn run(
    pty: bool,
    tcp: Option<&str>,
    firmware: Option<Firmware>,
    rate: f64,
    seed: u64,
    pose: Option<&Path>,
) -> Result<(), String> {
    let faults = faults(rate)?;
    let at = match (pty, tcp) {
        (true, _) => Where::Pty,
        (false, Some(addr)) => Where::Tcp(addr),
        (false, None) => return Err("sim: give --pty or --tcp ADDR".into()),
    };
    if let Some(file) = pose {
        // Made now, so that a path that cannot be written is said before anything is served.
        std::fs::File::create(file).map_err(|e| format!("--pose {}: {e}", file.display()))?;
    }
    crate::generation::of(firmware.unwrap_or(crate::connect::DEFAULT_FIRMWARE)).simulate(
        &Place { at, pose },
        seed,
        faults,
    )
}

/// Where the board is served, and where its true pose is written.
pub struct Place<'a> {
    /// A pseudo-terminal or a TCP listener.
    pub at: Where<'a>,
    /// The file the true pose goes to, if any.
    pub pose: Option<&'a Path>,
}

/// Where the board is served.
pub enum Where<'a> {
    /// A new pseudo-terminal.
    Pty,
    /// A TCP listener on this address.
    Tcp(&'a str),
}

impl Place<'_> {
    /// Serves boards `fresh` makes; `commands` says how many commands one took; `hint` (with
    /// `{path}` in it) follows a pseudo-terminal's path on stderr.
    pub fn serve<B: Simulated>(
        &self,
        fresh: impl Fn() -> B,
        commands: impl Fn(&B) -> u32,
        hint: &str,
    ) -> Result<(), String> {
        match self.at {
            Where::Pty => on_pty(fresh(), self.pose, hint),
            Where::Tcp(addr) => on_tcp(addr, fresh, commands, self.pose),
        }
    }
}

/// [`serve`], the board's true pose written to `pose` (made afresh) every 10 ms of board time.
fn serve_posing<B: Simulated, T: Read + Write>(
    board: B,
    io: T,
    stop: &AtomicBool,
    pose: Option<&Path>,
) -> io::Result<B> {
    let Some(file) = pose else {
        return serve(board, io, stop);
    };
    let mut log = BufWriter::new(std::fs::File::create(file)?);
    let mut failed = false;
    let mut observe = |board: &B| {
        // A full disk ends the log, not the board.
        if !failed && write_pose(&mut log, board).is_err() {
            failed = true;
            tell!(
                "chassis sim: --pose {}: cannot write; no more poses",
                file.display()
            );
        }
    };
    let board = serve_observed(board, io, stop, 10, &mut observe)?;
    let _ = log.flush();
    Ok(board)
}

/// Serves `board` on a new pseudo-terminal; `hint` (with `{path}` in it) follows the path on
/// stderr.
#[cfg(unix)]
fn on_pty<B: Simulated>(board: B, pose: Option<&Path>, hint: &str) -> Result<(), String> {
    use serialport::SerialPort as _;
    let (mut board_end, master_end) =
        serialport::TTYPort::pair().map_err(|e| format!("cannot make a pseudo-terminal: {e}"))?;
    board_end
        .set_timeout(std::time::Duration::from_millis(1))
        .map_err(|e| format!("pseudo-terminal: {e}"))?;
    let path = master_end.name().ok_or("the pseudo-terminal has no path")?;
    say!("{path}");
    let hint = hint.replace("{path}", &path);
    tell!("chassis sim: a simulated board on {path} (115200 8N1); {hint}. Ctrl-C stops it.");
    // The other end stays open here, so the board's end never reads an end of file while no
    // client has the path open.
    let keep = master_end;
    let stop = AtomicBool::new(false);
    let result = serve_posing(board, board_end, &stop, pose);
    drop(keep);
    result
        .map(|_| ())
        .map_err(|e| format!("pseudo-terminal: {e}"))
}

/// No pseudo-terminals off Unix.
#[cfg(not(unix))]
fn on_pty<B: Simulated>(_board: B, _pose: Option<&Path>, _hint: &str) -> Result<(), String> {
    Err("--pty needs a Unix pseudo-terminal; use --tcp".into())
}

/// Serves a board `fresh` makes to each client of a TCP listener on `addr`; `commands` says
/// how many it took.
fn on_tcp<B: Simulated>(
    addr: &str,
    fresh: impl Fn() -> B,
    commands: impl Fn(&B) -> u32,
    pose: Option<&Path>,
) -> Result<(), String> {
    let listener = TcpListener::bind(addr).map_err(|e| format!("cannot listen on {addr}: {e}"))?;
    let local = listener.local_addr().map_err(|e| format!("{addr}: {e}"))?;
    say!("{local}");
    tell!("chassis sim: a simulated board on tcp {local}, one client at a time. Ctrl-C stops it.");
    loop {
        let (stream, peer) = listener
            .accept()
            .map_err(|e| format!("accepting on {local}: {e}"))?;
        let _ = stream.set_nodelay(true);
        // Non-blocking with a short sleep in `serve`: socket timeouts tick in 4 ms steps.
        stream
            .set_nonblocking(true)
            .map_err(|e| format!("{peer}: {e}"))?;
        tell!("chassis sim: {peer} connected");
        let stop = AtomicBool::new(false);
        match serve_posing(fresh(), stream, &stop, pose) {
            Ok(board) => tell!(
                "chassis sim: {peer} left after {:.1} s ({} commands)",
                board.now_ms() as f64 / 1000.0,
                commands(&board)
            ),
            Err(e) => tell!("chassis sim: {peer}: {e}"),
        }
    }
}
