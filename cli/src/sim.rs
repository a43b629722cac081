//! `chassis sim`: the simulated board in real time on a pseudo-terminal or a TCP port, so that
//! every command can be tried without hardware (and the QEMU firmware has a chassis to drive).
//! Either firmware generation: the 2020 board (`FF FE` frames) or the v1.0.0 one (`7B … 7D`).

use chassis_protocol::sim::{self, Board, Faults, SimConfig, Simulated, serve};
use std::net::TcpListener;
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
/// stopped; prints where.
pub fn run(
    pty: bool,
    tcp: Option<&str>,
    firmware: Option<Firmware>,
    rate: f64,
    seed: u64,
) -> Result<(), String> {
    let faults = faults(rate)?;
    let place = match (pty, tcp) {
        (true, _) => Place::Pty,
        (false, Some(addr)) => Place::Tcp(addr),
        (false, None) => return Err("sim: give --pty or --tcp ADDR".into()),
    };
    crate::generation::of(firmware.unwrap_or(crate::connect::DEFAULT_FIRMWARE))
        .simulate(&place, seed, faults)
}

/// Where the board is served.
pub enum Place<'a> {
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
        match self {
            Place::Pty => on_pty(fresh(), hint),
            Place::Tcp(addr) => on_tcp(addr, fresh, commands),
        }
    }
}

/// Serves `board` on a new pseudo-terminal; `hint` (with `{path}` in it) follows the path on
/// stderr.
#[cfg(unix)]
fn on_pty<B: Simulated>(board: B, hint: &str) -> Result<(), String> {
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
    let result = serve(board, board_end, &stop);
    drop(keep);
    result
        .map(|_| ())
        .map_err(|e| format!("pseudo-terminal: {e}"))
}

/// No pseudo-terminals off Unix.
#[cfg(not(unix))]
fn on_pty<B: Simulated>(_board: B, _hint: &str) -> Result<(), String> {
    Err("--pty needs a Unix pseudo-terminal; use --tcp".into())
}

/// Serves a board `fresh` makes to each client of a TCP listener on `addr`; `commands` says
/// how many it took.
fn on_tcp<B: Simulated>(
    addr: &str,
    fresh: impl Fn() -> B,
    commands: impl Fn(&B) -> u32,
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
        match serve(fresh(), stream, &stop) {
            Ok(board) => tell!(
                "chassis sim: {peer} left after {:.1} s ({} commands)",
                board.now_ms() as f64 / 1000.0,
                commands(&board)
            ),
            Err(e) => tell!("chassis sim: {peer}: {e}"),
        }
    }
}
