//! The simulated board in real time on an OS byte stream (feature `std`): a pseudo-terminal,
//! a TCP socket, a serial port. What a host program, the CLI and the emulator tests talk to.

use super::Board;
use std::io::{self, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Runs `board` in real time on `io` until `stop` is set or `io` closes, then gives the board
/// back (to inspect what it was told). `io`'s reads must time out (1 ms or so): each turn of
/// the loop takes in what the master sent, moves the board's clock to the wall clock, and
/// writes what the board has sent since. A read that times out or would block is no error; an
/// end of stream ends the run.
pub fn serve<T: Read + Write>(mut board: Board, mut io: T, stop: &AtomicBool) -> io::Result<Board> {
    let start = Instant::now();
    let offset = board.now_ms();
    let mut buf = [0u8; 256];
    while !stop.load(Ordering::Relaxed) {
        match io.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => board.receive(buf.get(..n).unwrap_or(&[])),
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock
                ) =>
            {
                std::thread::sleep(Duration::from_micros(200));
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
        let elapsed = u64::try_from(start.elapsed().as_millis()).unwrap_or(u64::MAX);
        board.advance(offset.saturating_add(elapsed));
        loop {
            let n = board.transmit(&mut buf);
            if n == 0 {
                break;
            }
            io.write_all(buf.get(..n).unwrap_or(&[]))?;
        }
        io.flush()?;
    }
    Ok(board)
}
