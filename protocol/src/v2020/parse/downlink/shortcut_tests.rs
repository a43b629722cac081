//! The short ways against the general judgement alone: on noisy streams of every count model,
//! with quiet lines, replies and `expect_reply` between, the parser with its short ways (fed by
//! `push`, by `push_slice` in random slices, and by `frames()`) emits the same frames, leaves the
//! same statistics and the same lock as the parser that judges every decision with
//! [`rules::decide`](super::rules::decide) (fed one byte at a time, polled after each).
//!
//! `SHORTCUT_CASES` sets the number of streams (default 2 000, what CI runs).

use super::*;
use crate::{Battery, Encoders, Imu, Reply};
use std::cell::Cell;
use std::vec;
use std::vec::Vec;

std::thread_local! {
    /// Set: every decision goes through the general judgement (see [`short_ways`]).
    pub(super) static GENERAL_ONLY: Cell<bool> = const { Cell::new(false) };
}

/// A small deterministic generator (xorshift64*), so that a failing stream is a seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }
    fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
    /// A sensor value near rest: small (often -6..-4, a header's second byte), sometimes any.
    fn value(&mut self, rest: i16) -> i16 {
        if self.chance(0.1) {
            self.next() as i16
        } else {
            rest.wrapping_add(self.below(17) as i16 - 8)
        }
    }
}

/// What the caller does between bytes.
#[derive(Clone, Debug)]
enum Op {
    Bytes(Vec<u8>),
    Quiet(u32),
    Expect(Option<Register>),
}

/// The board's side: its counts under one of the count models A10 allows.
struct Board {
    rng: Rng,
    /// 0: a 10 ms tick; 1, 2, 3: a counter per stream stepping by 1, 3 or 7; 4: one counter
    /// shared by all streams.
    model: u64,
    counts: [u8; 3],
}

impl Board {
    fn count(&mut self, stream: usize, tick: u64) -> u8 {
        let step = [1, 1, 3, 7, 1][self.model as usize];
        let i = if self.model == 4 { 0 } else { stream };
        let count = match self.model {
            0 => self.counts[0].wrapping_add(tick as u8),
            _ => self.counts[i].wrapping_add(step),
        };
        self.counts[i] = if self.model == 0 {
            self.counts[i]
        } else {
            count
        };
        count
    }

    /// What the board sends in 10 ms `tick`: an IMU frame, every fourth tick an encoder frame,
    /// every fiftieth a battery frame (more often than the board, for more of them), and at
    /// times a reply.
    fn frames(&mut self, tick: u64) -> Vec<Downlink> {
        let seq = self.count(0, tick);
        let r = &mut self.rng;
        let mut frames = vec![Downlink::Imu(Imu {
            accel: [r.value(0), r.value(0), r.value(16_384)],
            gyro: [r.value(-5), r.value(-5), r.value(0)],
            seq,
        })];
        if tick.is_multiple_of(4) {
            let seq = self.count(1, tick);
            let r = &mut self.rng;
            frames.push(Downlink::Encoders(Encoders {
                ticks: [r.value(-5), r.value(0), r.value(-4), r.value(0)],
                seq,
            }));
        }
        if tick % 50 == 7 {
            let seq = self.count(2, tick);
            let r = &mut self.rng;
            frames.push(Downlink::Battery(Battery {
                centivolts: 1_100 + r.below(100) as u16,
                percent: r.below(101) as u16,
                seq,
            }));
        }
        frames
    }
}

/// The master's side: the bytes it reads, with the calls it makes between them.
struct Script {
    rng: Rng,
    /// Bytes substituted, dropped or inserted, each with this chance a byte.
    rate: f64,
    ops: Vec<Op>,
    burst: Vec<u8>,
}

impl Script {
    /// The bytes so far, then `op`.
    fn then(&mut self, op: Op) {
        self.ops.push(Op::Bytes(core::mem::take(&mut self.burst)));
        self.ops.push(op);
    }

    /// `frame` through the channel; rarely, the line goes quiet inside it.
    fn send(&mut self, frame: &Downlink) {
        for byte in frame.encode().as_ref() {
            if self.rng.chance(self.rate) {
                match self.rng.below(3) {
                    0 => self.burst.push(self.rng.next() as u8),
                    1 => {}
                    _ => self.burst.extend([*byte, self.rng.next() as u8]),
                }
            } else {
                self.burst.push(*byte);
            }
            if self.rng.chance(0.002) {
                let ms = 1 + self.rng.below(30) as u32;
                self.then(Op::Quiet(ms));
            }
        }
    }
}

/// One board stream: telemetry at the board's rates with replies, through a channel that
/// substitutes, drops and inserts bytes, quiet lines between bursts (and, rarely, inside a
/// frame), `expect_reply` calls, and a capture that starts anywhere.
fn stream(seed: u64) -> Vec<Op> {
    let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let mut board = Board {
        model: rng.below(5),
        counts: [rng.next() as u8, rng.next() as u8, rng.next() as u8],
        rng: Rng(rng.next() | 1),
    };
    let mut master = Script {
        rate: [0.0, 1e-3, 1e-2, 3e-2][rng.below(4) as usize],
        rng: Rng(rng.next() | 1),
        ops: Vec::new(),
        burst: Vec::new(),
    };
    for tick in 0..(60 + rng.below(140)) {
        let mut frames = board.frames(tick);
        if rng.chance(0.08) {
            let register = Register::ALL[rng.below(Register::ALL.len() as u64) as usize];
            if rng.chance(0.6) {
                master.then(Op::Expect(Some(register)));
            }
            frames.push(Downlink::Reply(Reply {
                code: register.reply_code(),
                value: u32::from(rng.value(-5) as u16),
            }));
        }
        for frame in &frames {
            master.send(frame);
        }
        if rng.chance(0.3) {
            master.then(Op::Quiet(1 + rng.below(12) as u32));
        }
        if rng.chance(0.05) {
            master.then(Op::Expect(None));
        }
    }
    master.then(Op::Quiet(5));
    let mut ops = master.ops;
    let start = rng.below(40) as usize;
    if let Some(Op::Bytes(first)) = ops
        .iter_mut()
        .find(|op| matches!(op, Op::Bytes(b) if !b.is_empty()))
    {
        first.drain(..start.min(first.len()));
    }
    ops
}

/// How the bytes are fed.
#[derive(Clone, Copy, Debug)]
enum Way {
    /// The general judgement alone, one byte at a time, polled after each.
    General,
    /// `push`, never polled but by `quiet`.
    Push,
    /// `push_slice` in slices of 1 to 40 bytes, its frames polled out before the next slice.
    Slices,
    /// `frames()` over each run of bytes whole.
    Frames,
}

fn run(ops: &[Op], way: Way, seed: u64) -> (Vec<Downlink>, DownlinkStats, Lock) {
    GENERAL_ONLY.with(|g| g.set(matches!(way, Way::General)));
    let mut rng = Rng(seed | 1);
    let mut p = DownlinkParser::new();
    let mut out = Vec::new();
    for op in ops {
        match op {
            Op::Bytes(bytes) => match way {
                Way::General => {
                    for b in bytes {
                        out.extend(p.push(*b));
                        out.extend(core::iter::from_fn(|| p.poll()));
                    }
                }
                Way::Push => out.extend(bytes.iter().filter_map(|b| p.push(*b))),
                Way::Slices => {
                    let mut rest = bytes.as_slice();
                    while !rest.is_empty() {
                        let n = (1 + rng.below(40) as usize).min(rest.len());
                        let (mut slice, after) = rest.split_at(n);
                        while !slice.is_empty() {
                            let (frame, left) = p.push_slice(slice);
                            out.extend(frame);
                            slice = left;
                        }
                        out.extend(core::iter::from_fn(|| p.poll()));
                        rest = after;
                    }
                }
                Way::Frames => out.extend(p.frames(bytes)),
            },
            Op::Quiet(ms) => out.extend(core::iter::from_fn(|| p.quiet(*ms))),
            Op::Expect(register) => p.expect_reply(*register),
        }
    }
    GENERAL_ONLY.with(|g| g.set(false));
    (out, *p.stats(), p.lock())
}

/// `ops` fed a byte at a time and polled after each, with or without the short ways: each
/// frame with the bytes fed when it came out (the quiet lines count as a byte each). The same
/// list both ways: every frame comes out at the same byte.
fn timed(ops: &[Op], general: bool) -> Vec<(usize, Downlink)> {
    GENERAL_ONLY.with(|g| g.set(general));
    let mut p = DownlinkParser::new();
    let (mut out, mut at) = (Vec::new(), 0usize);
    for op in ops {
        match op {
            Op::Bytes(bytes) => {
                for b in bytes {
                    at += 1;
                    out.extend(p.push(*b).map(|f| (at, f)));
                    out.extend(core::iter::from_fn(|| p.poll()).map(|f| (at, f)));
                }
            }
            Op::Quiet(ms) => {
                at += 1;
                out.extend(core::iter::from_fn(|| p.quiet(*ms)).map(|f| (at, f)));
            }
            Op::Expect(register) => p.expect_reply(*register),
        }
    }
    GENERAL_ONLY.with(|g| g.set(false));
    out
}

#[test]
fn the_short_ways_decide_as_the_general_judgement_on_noisy_streams_of_every_count_model() {
    let cases: u64 = std::env::var("SHORTCUT_CASES")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(2_000);
    let mut frames = 0;
    for seed in 0..cases {
        let ops = stream(seed);
        let general = run(&ops, Way::General, seed);
        frames += general.0.len();
        assert!(
            timed(&ops, false) == timed(&ops, true),
            "seed {seed}: a frame came out at another byte with the short ways"
        );
        for way in [Way::Push, Way::Slices, Way::Frames] {
            let got = run(&ops, way, seed);
            assert!(
                got == general,
                "seed {seed}, {way:?}: {} frames, general {}; first difference at {:?}\n{:?}\n{:?}",
                got.0.len(),
                general.0.len(),
                got.0.iter().zip(&general.0).position(|(a, b)| a != b),
                got.1,
                general.1,
            );
        }
    }
    // The streams are not empty of frames: the comparison is not vacuous.
    assert!(frames > 100 * cases as usize, "{frames} frames");
}

/// `ops` fed a byte at a time by `push` (the general judgement polled after each), with or
/// without the short ways: the frames, the statistics, the lock and the bytes kept at the end.
fn state_after(ops: &[Op], general: bool) -> (Vec<Downlink>, DownlinkStats, Lock, usize) {
    GENERAL_ONLY.with(|g| g.set(general));
    let mut p = DownlinkParser::new();
    let mut out = Vec::new();
    for op in ops {
        match op {
            Op::Bytes(bytes) => {
                for b in bytes {
                    out.extend(p.push(*b));
                    if general {
                        out.extend(core::iter::from_fn(|| p.poll()));
                    }
                }
            }
            Op::Quiet(ms) => out.extend(core::iter::from_fn(|| p.quiet(*ms))),
            Op::Expect(register) => p.expect_reply(*register),
        }
    }
    out.extend(core::iter::from_fn(|| p.poll()));
    GENERAL_ONLY.with(|g| g.set(false));
    (out, *p.stats(), p.lock(), p.buffered())
}

#[test]
fn a_header_wait_ends_at_the_judgement_a_quiet_line_makes() {
    // Found by a differential fuzzer against the parser before the header wait: a battery
    // frame whose chain waits for its next header when the line goes quiet; the judgement
    // that the quiet line makes ends the wait, and the burst after it is judged from its own
    // bytes (a wait left over from before the quiet line took a header inside it for the
    // chain's, and kept 9 bytes the judgement throws away).
    let before = vec![
        0xFF, 0xFC, 0xFF, 0xF9, 0x00, 0x01, 0xCC, 0x23, 0x0A, 0xC5, 0x46, 0xA6, 0xAE,
    ];
    let after = [
        0xFF, 0xFA, 0xFF, 0xF7, 0x00, 0x00, 0xFF, 0xFF, 0xCF, 0xFF, 0xFB, 0x00, 0x00, 0xFF, 0xFB,
        0xFB, 0xD2,
    ];
    for n in 1..=after.len() {
        let ops = [
            Op::Bytes(before.clone()),
            Op::Quiet(1),
            Op::Bytes(after[..n].to_vec()),
        ];
        assert_eq!(
            state_after(&ops, false),
            state_after(&ops, true),
            "{n} bytes after"
        );
    }
}
