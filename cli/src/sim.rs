//! `chassis sim`: the simulated board in real time on a pseudo-terminal or a TCP port, so that
//! every command can be tried without hardware (and the QEMU firmware has a chassis to drive).

use chassis_protocol::sim::{Board, Faults, SimConfig, serve};
use std::net::TcpListener;
use std::sync::atomic::AtomicBool;

/// Line faults from a rate of errors per byte: a third each dropped, changed and added.
pub fn faults(rate: f64) -> Result<Faults, String> {
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

fn board(seed: u64, faults: Faults) -> Board {
    let mut board = Board::new(SimConfig {
        seed,
        ..SimConfig::default()
    });
    board.set_faults(faults);
    board
}

/// Serves a simulated board on a new pseudo-terminal until the process is stopped; prints the
/// path to open.
#[cfg(unix)]
pub fn pty(seed: u64, faults: Faults) -> Result<(), String> {
    use serialport::SerialPort as _;
    let (mut board_end, master_end) =
        serialport::TTYPort::pair().map_err(|e| format!("cannot make a pseudo-terminal: {e}"))?;
    board_end
        .set_timeout(std::time::Duration::from_millis(1))
        .map_err(|e| format!("pseudo-terminal: {e}"))?;
    let path = master_end.name().ok_or("the pseudo-terminal has no path")?;
    say!("{path}");
    tell!(
        "chassis sim: a simulated board on {path} (115200 8N1); try `chassis --port {path} settings`. Ctrl-C stops it."
    );
    // The other end stays open here, so the board's end never reads an end of file while no
    // client has the path open.
    let keep = master_end;
    let stop = AtomicBool::new(false);
    let result = serve(board(seed, faults), board_end, &stop);
    drop(keep);
    result
        .map(|_| ())
        .map_err(|e| format!("pseudo-terminal: {e}"))
}

/// No pseudo-terminals off Unix.
#[cfg(not(unix))]
pub fn pty(_seed: u64, _faults: Faults) -> Result<(), String> {
    Err("--pty needs a Unix pseudo-terminal; use --tcp".into())
}

/// Serves a simulated board to each client of a TCP listener on `addr`, one at a time, a fresh
/// board each.
pub fn tcp(addr: &str, seed: u64, faults: Faults) -> Result<(), String> {
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
        match serve(board(seed, faults), stream, &stop) {
            Ok(board) => tell!(
                "chassis sim: {peer} left after {:.1} s ({} commands)",
                board.now_ms() as f64 / 1000.0,
                board.commands()
            ),
            Err(e) => tell!("chassis sim: {peer}: {e}"),
        }
    }
}
