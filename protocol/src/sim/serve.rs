//! The simulated board in real time on an OS byte stream (feature `std`): a pseudo-terminal,
//! a TCP socket, a serial port. What a host program, the CLI and the emulator tests talk to.
//! Either board ([`Simulated`]): the 2020 [`Board`](super::Board) or a
//! [`v1::Board`](super::v1::Board).

use super::Simulated;
use std::io::{self, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Runs `board` in real time on `io` until `stop` is set or `io` closes, then gives the board
/// back (to inspect what it was told). `io`'s reads must time out (1 ms or so): each turn of
/// the loop takes in what the master sent, moves the board's clock to the wall clock, and
/// writes what the board has sent since. A read that times out or would block is no error; an
/// end of stream ends the run. Once stopped, what is already waiting is read before the board
/// is given back. Bytes the other end does not take (a write that times out or
/// would block) are dropped, as on a line nobody listens to: the board serves until stopped.
pub fn serve<B: Simulated, T: Read + Write>(board: B, io: T, stop: &AtomicBool) -> io::Result<B> {
    run(board, io, stop, None)
}

/// [`serve`], with `observe` called on the board at its start and then every `every_ms` ms of
/// board time (at exactly those times: the board's clock is stopped there for the call), for
/// a log of its true pose ([`write_pose`]) or anything else a board tells. `every_ms` 0 is
/// taken as 1.
///
/// ```no_run
/// # fn pty() -> std::fs::File { unimplemented!() }
/// use chassis_protocol::sim::{Board, SimConfig, serve_observed, write_pose};
/// use std::sync::atomic::AtomicBool;
///
/// let mut log = std::io::BufWriter::new(std::fs::File::create("pose.txt")?);
/// let stop = AtomicBool::new(false);
/// // One line `t_ms x_m y_m yaw_rad` every 10 ms of board time.
/// let mut observe = |board: &Board| {
///     let _ = write_pose(&mut log, board);
/// };
/// serve_observed(Board::new(SimConfig::default()), pty(), &stop, 10, &mut observe)?;
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn serve_observed<B: Simulated, T: Read + Write>(
    board: B,
    io: T,
    stop: &AtomicBool,
    every_ms: u64,
    observe: &mut dyn FnMut(&B),
) -> io::Result<B> {
    run(board, io, stop, Some((every_ms.max(1), observe)))
}

/// Writes one line, `t_ms x_m y_m yaw_rad` (the board's time; its true pose, REP-103 axes,
/// to the µm and µrad), and flushes it; nothing for a board that does not track its pose.
///
/// # Errors
///
/// What writing to `out` gives.
pub fn write_pose<B: Simulated, W: Write>(out: &mut W, board: &B) -> io::Result<()> {
    if let Some((x, y, yaw)) = board.pose() {
        writeln!(out, "{} {x:.6} {y:.6} {yaw:.6}", board.now_ms())?;
        out.flush()?;
    }
    Ok(())
}

/// What [`serve_observed`] calls, and how often (ms of board time).
type Observer<'o, B> = (u64, &'o mut dyn FnMut(&B));

/// The loop of [`serve`] and [`serve_observed`].
fn run<B: Simulated, T: Read + Write>(
    mut board: B,
    mut io: T,
    stop: &AtomicBool,
    mut observer: Option<Observer<'_, B>>,
) -> io::Result<B> {
    let start = Instant::now();
    let offset = board.now_ms();
    let mut next_observed = offset;
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
        let now = offset.saturating_add(elapsed);
        if let Some((every_ms, observe)) = observer.as_mut() {
            while next_observed <= now {
                board.advance(next_observed);
                observe(&board);
                next_observed = next_observed.saturating_add(*every_ms);
            }
        }
        board.advance(now);
        loop {
            let n = board.transmit(&mut buf);
            if n == 0 {
                break;
            }
            send(&mut io, buf.get(..n).unwrap_or(&[]))?;
        }
        match io.flush() {
            Err(e) if !nobody_reads(&e) => return Err(e),
            _ => {}
        }
    }
    // Stopped: what the master sent before that is still waiting is taken in, so the board
    // given back has heard every byte sent to it (a program that wrote and exited just now).
    loop {
        match io.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => board.receive(buf.get(..n).unwrap_or(&[])),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            // Nothing more waiting, or the stream gone: either way, done.
            Err(_) => break,
        }
    }
    Ok(board)
}

/// A write that times out or would block: the other end is not reading (a pseudo-terminal
/// whose buffer is full while no program has it open).
fn nobody_reads(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock
    )
}

/// Writes `bytes` as a line does: what nobody reads is lost, not waited for (a board keeps
/// talking whether or not anyone listens).
fn send<T: Write>(io: &mut T, mut bytes: &[u8]) -> io::Result<()> {
    while !bytes.is_empty() {
        match io.write(bytes) {
            Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
            Ok(n) => bytes = bytes.get(n..).unwrap_or(&[]),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) if nobody_reads(&e) => return Ok(()),
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::{Register, Setting};
    use crate::sim::{Board, SimConfig};

    /// The master sends one read, then never reads: every write times out (a pseudo-terminal's
    /// buffer full). After 300 turns of the loop it sets `stop`.
    struct NobodyReads<'a> {
        sent: bool,
        turns: u32,
        stop: &'a AtomicBool,
    }

    impl Read for NobodyReads<'_> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            self.turns += 1;
            if self.turns > 300 {
                self.stop.store(true, Ordering::Relaxed);
            }
            if !self.sent {
                self.sent = true;
                let frame = Setting::Read(Register::MaxSpeed).encode();
                buf[..frame.len()].copy_from_slice(&frame);
                return Ok(frame.len());
            }
            Err(io::ErrorKind::TimedOut.into())
        }
    }

    impl Write for NobodyReads<'_> {
        fn write(&mut self, _: &[u8]) -> io::Result<usize> {
            Err(io::ErrorKind::TimedOut.into())
        }
        fn flush(&mut self) -> io::Result<()> {
            Err(io::ErrorKind::TimedOut.into())
        }
    }

    #[test]
    fn a_board_nobody_reads_keeps_serving_until_stopped() {
        let stop = AtomicBool::new(false);
        let io = NobodyReads {
            sent: false,
            turns: 0,
            stop: &stop,
        };
        let board = serve(Board::new(SimConfig::default()), io, &stop)
            .expect("writes nobody takes are dropped, not an error");
        assert_eq!(board.commands(), 1, "the master's read was taken in");
        assert!(stop.load(Ordering::Relaxed), "it ran until stopped");
    }

    #[test]
    fn the_observer_sees_the_board_every_10_ms_of_its_time() {
        let stop = AtomicBool::new(false);
        let io = NobodyReads {
            sent: false,
            turns: 0,
            stop: &stop,
        };
        let mut lines = Vec::new();
        let mut observe = |board: &Board| write_pose(&mut lines, board).unwrap();
        let board = serve_observed(
            Board::new(SimConfig::default()),
            io,
            &stop,
            10,
            &mut observe,
        )
        .expect("writes nobody takes are dropped, not an error");
        let text = String::from_utf8(lines).unwrap();
        let times: Vec<u64> = text
            .lines()
            .map(|l| l.split(' ').next().unwrap().parse().unwrap())
            .collect();
        // From 0, every 10 ms, up to the board's last time.
        let expected: Vec<u64> = (0..=board.now_ms() / 10).map(|k| k * 10).collect();
        assert_eq!(times, expected);
        // Standing still at the origin all along: four fields, each 0 to the µm.
        assert!(
            text.lines()
                .all(|l| l.ends_with(" 0.000000 0.000000 0.000000"))
        );
    }
}
