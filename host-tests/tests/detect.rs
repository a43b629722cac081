//! `detect`: which firmware a board runs, on an in-memory UART, against each simulated
//! generation, a silent line and bytes of neither; what it sends, byte for byte.

use chassis_protocol::detect::{self, Detection, Firmware, LISTEN_MS, PROBE_2020, PROBE_V1};
use chassis_protocol::driver::Config;
use chassis_protocol::sim::{self, SimClock, SimUart};
use core::cell::Cell;
use core::convert::Infallible;

/// A line: what a board (or nothing) sends, and everything the master wrote.
struct Line<F: FnMut(&mut [u8]) -> usize> {
    bytes: F,
    wrote: Vec<u8>,
}

impl<F: FnMut(&mut [u8]) -> usize> embedded_io::ErrorType for Line<F> {
    type Error = Infallible;
}
impl<F: FnMut(&mut [u8]) -> usize> embedded_io::Read for Line<F> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        Ok((self.bytes)(buf))
    }
}
impl<F: FnMut(&mut [u8]) -> usize> embedded_io::ReadReady for Line<F> {
    fn read_ready(&mut self) -> Result<bool, Infallible> {
        Ok(true)
    }
}
impl<F: FnMut(&mut [u8]) -> usize> embedded_io::Write for Line<F> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        self.wrote.extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

/// Runs `detect` on a line whose bytes `bytes` gives, with a clock of 1 ms a reading.
fn run_on(bytes: impl FnMut(&mut [u8]) -> usize) -> (Detection, Vec<u8>) {
    let mut line = Line {
        bytes,
        wrote: Vec::new(),
    };
    let mut now = 0u64;
    let mut clock = || {
        now += 1;
        now
    };
    let detection = detect::detect(&mut line, &mut clock, &Config::DEFAULT).unwrap();
    (detection, line.wrote)
}

#[test]
fn a_2020_board_is_told_by_listening_alone() {
    let time = Cell::new(0);
    let mut uart = SimUart::new(sim::Board::new(sim::SimConfig::default()), &time);
    let mut clock = SimClock(&time);
    let found = detect::detect(&mut uart, &mut clock, &Config::DEFAULT).unwrap();
    assert_eq!(found.firmware, Some(Firmware::V2020), "{found:?}");
    assert!(!found.probed, "nothing was sent");
    assert!(found.elapsed_ms < 100, "{found:?}");
    assert_eq!(found.heard.frames_v1, 0);
}

#[test]
fn a_v1_board_is_told_by_listening_alone_and_receives_nothing() {
    let time = Cell::new(0);
    let mut uart = SimUart::new(sim::v1::Board::new(sim::v1::SimConfig::default()), &time);
    let mut clock = SimClock(&time);
    let found = detect::detect(&mut uart, &mut clock, &Config::DEFAULT).unwrap();
    assert_eq!(found.firmware, Some(Firmware::V1_0_0), "{found:?}");
    assert!(!found.probed);
    assert!(found.elapsed_ms <= LISTEN_MS, "{found:?}");
    assert_eq!(found.heard.frames_2020, 0);
    assert_eq!(uart.board().total_commands(), 0, "the board heard nothing");
}

#[test]
fn a_v1_board_that_does_not_stream_is_told_by_its_reply_to_the_probe() {
    let time = Cell::new(0);
    let quiet = sim::v1::SimConfig {
        telemetry_period_ms: 1_000_000,
        ..sim::v1::SimConfig::default()
    };
    let mut uart = SimUart::new(sim::v1::Board::new(quiet), &time);
    let mut clock = SimClock(&time);
    let found = detect::detect(&mut uart, &mut clock, &Config::DEFAULT).unwrap();
    assert_eq!(found.firmware, Some(Firmware::V1_0_0), "{found:?}");
    assert!(found.probed);
    assert_eq!(found.heard.replies_v1, 1);
    // It heard the readback request and nothing it could act on.
    let heard: Vec<_> = uart.board().received().copied().collect();
    assert_eq!(
        heard,
        vec![chassis_protocol::v1::Command::Readback(
            chassis_protocol::v1::Readback::System
        )]
    );
}

#[test]
fn a_silent_line_gets_the_two_probes_only_and_no_verdict() {
    let (found, wrote) = run_on(|_| 0);
    assert_eq!(found.firmware, None);
    assert!(found.probed);
    assert_eq!(found.heard.bytes, 0);
    let mut expected = PROBE_2020.to_vec();
    expected.extend(PROBE_V1);
    assert_eq!(wrote, expected, "the probes, nothing else");
    assert!(
        found.elapsed_ms <= 2 * LISTEN_MS + 40,
        "ends within a second: {found:?}"
    );
}

#[test]
fn bytes_of_neither_generation_get_no_verdict() {
    // A device at another baud rate, or another device: bytes with no frame of either.
    let mut x = 0x9E37_79B9u32;
    let (found, wrote) = run_on(move |buf| {
        for b in buf.iter_mut().take(4) {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            *b = (x >> 24) as u8;
        }
        buf.len().min(4)
    });
    assert_eq!(found.firmware, None, "{found:?}");
    assert!(found.heard.bytes > 1_000);
    // The line was not quiet: no probe to a device that is not the board.
    assert!(!found.probed);
    assert!(wrote.is_empty(), "sent {wrote:02X?}");
}

#[test]
fn a_glitch_or_two_on_a_quiet_line_still_gets_the_probes() {
    let mut glitches = 2;
    let (found, wrote) = run_on(move |buf| {
        if glitches > 0 && !buf.is_empty() {
            glitches -= 1;
            buf[0] = 0x00;
            1
        } else {
            0
        }
    });
    assert!(found.probed);
    assert_eq!(found.heard.bytes, 2);
    let mut expected = PROBE_2020.to_vec();
    expected.extend(PROBE_V1);
    assert_eq!(wrote, expected);
}

#[test]
fn a_clock_that_stands_still_does_not_hang_it() {
    let mut line = Line {
        bytes: |_: &mut [u8]| 0,
        wrote: Vec::new(),
    };
    let found = detect::detect(&mut line, &mut || 7u64, &Config::DEFAULT).unwrap();
    assert_eq!(found.firmware, None);
}
