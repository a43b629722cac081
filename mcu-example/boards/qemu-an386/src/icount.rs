//! The work of the instruction-count runs (`src/bin/icount.rs`, the 2020 board → master parser;
//! `src/bin/icount_v1.rs`, the v1.0.0 one), written once for any [`Parser`]: each binary names
//! its [`Generation`] (its parser, how it is fed, its board's stream, its lines' prefix) and
//! calls [`run`].
//!
//! Run under QEMU with `-icount shift=0` (virtual time then advances one nanosecond per
//! instruction), SysTick, counting the core clock, counts instructions: one tick is 40
//! instructions on mps2-an386 (25 MHz, Cortex-M4) and 62.5 on the micro:bit (16 MHz,
//! Cortex-M0). The same code is built for thumbv7em and thumbv6m; the core's CPUID tells which
//! machine it runs on. A run prints one line per figure over semihosting (plain text) and exits
//! 0; `cargo xtask icount` runs both binaries on both machines and prints the table.
//!
//! The figures hang on the code of the whole run, not only on the code measured. A figure is a
//! count of whole ticks, so an instruction more or less anywhere before a measurement (building
//! the stream, say) can move it by a tick; and the run is one function (`main`, [`run`] and its
//! helpers inlined into it with `#[inline(always)]`, as when each binary had its own `main`),
//! so a change anywhere in it, even to the printing, can change how the compiler lays out the
//! loops measured. Compare each binary's output before and after any change here.

use crate::time;
use chassis_protocol::stream::Parser;
use core::hint::black_box;

/// The board's stream, in bytes at most: about two seconds of the 2020 board's output, five of
/// the v1.0.0 board's.
pub const MIX_LEN: usize = 4_096;
/// The random bytes, in bytes.
pub const RANDOM_LEN: usize = 4_096;
/// The board's stream, in frames at most.
pub const MAX_FRAMES: usize = 512;

/// A small deterministic generator (the same stream on both machines).
pub struct Lcg(pub u32);

impl Lcg {
    /// The next value, 24 bits.
    #[inline]
    pub fn next_value(&mut self) -> u32 {
        self.0 = self.0.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        self.0 >> 8
    }

    /// A sensor value near 0 (±`range`): at rest a gyro reads small numbers, and -6..-4 are
    /// `FF FA`..`FF FC`: false headers are ordinary traffic.
    #[inline]
    pub fn small(&mut self, range: u32) -> i16 {
        (self.next_value() % (2 * range + 1)) as i16 - range as i16
    }
}

/// A firmware generation as the run measures it: its board → master parser, how the parser is
/// fed, its board's stream and its lines. What has a default goes through [`Parser`] alone.
pub trait Generation {
    /// The board → master parser.
    type Parser: Parser;

    /// What starts each of the parser's lines.
    const PREFIX: Prefix;

    /// Whether a frame from `push` is followed by `poll` until nothing more comes out (the
    /// parser wants it); otherwise each byte is only pushed, as an interrupt handler does, and
    /// a frame held back comes out of a later `push`.
    const POLL: bool;

    /// A fresh parser.
    fn parser() -> Self::Parser;

    /// Writes the board's stream into `buf`, back to back, and where each frame ends into
    /// `ends`, until either is full: the stream's length in bytes, and its frames.
    fn mix(buf: &mut [u8; MIX_LEN], ends: &mut [u16; MAX_FRAMES]) -> (usize, usize);

    /// Feeds `byte` to `parser`. By default [`Parser::push`].
    fn push(parser: &mut Self::Parser, byte: u8) -> Option<<Self::Parser as Parser>::Frame> {
        parser.push(byte)
    }

    /// Every frame of `bytes` through the parser's slice path. By default [`Parser::frames`].
    fn frames<'a>(
        parser: &'a mut Self::Parser,
        bytes: &'a [u8],
    ) -> impl Iterator<Item = <Self::Parser as Parser>::Frame> {
        parser.frames(bytes)
    }
}

/// The parser of `G` over `bytes`, one byte at a time ([`Generation::push`], and `poll` after
/// a frame until nothing more if [`Generation::POLL`]), from a fresh parser; the frames it
/// gave.
fn parse_all<G: Generation>(bytes: &[u8]) -> u32 {
    let mut parser = G::parser();
    let mut frames = 0u32;
    if G::POLL {
        for &byte in bytes {
            let mut out = G::push(&mut parser, byte);
            while let Some(frame) = out {
                black_box(&frame);
                frames += 1;
                out = parser.poll();
            }
        }
    } else {
        for &byte in bytes {
            if let Some(frame) = G::push(&mut parser, byte) {
                black_box(&frame);
                frames += 1;
            }
        }
    }
    frames
}

/// The parser of `G` over `bytes` through its slice path ([`Generation::frames`]), from a
/// fresh parser; the frames it gave.
fn parse_slices<G: Generation>(bytes: &[u8]) -> u32 {
    let mut parser = G::parser();
    let mut frames = 0u32;
    for frame in G::frames(&mut parser, bytes) {
        black_box(&frame);
        frames += 1;
    }
    frames
}

/// SysTick ticks for `f`, less the cost of the measurement itself (`overhead`).
fn measure(overhead: u64, f: impl FnOnce()) -> u64 {
    let start = time::cycles();
    f();
    time::cycles()
        .saturating_sub(start)
        .saturating_sub(overhead)
}

/// What starts each of the parser's lines: `cargo xtask icount` tells the parsers apart by it.
#[derive(Clone, Copy)]
pub enum Prefix {
    /// Nothing: the 2020 parser.
    None,
    /// `v1 `: the v1.0.0 parser.
    V1,
}

/// Prints the figures of a run over semihosting, a line each, the parser's lines starting with
/// its [`Prefix`]: `lines!(prefix; machine, instr, turns, ticks_loop, mix_len, mix_frames, got,
/// ticks_mix, got_slices, ticks_slices, got_random, ticks_random, timed, completing)`, the
/// run's variables (`instr` turns ticks into instructions).
///
/// Each line's text is one literal with the prefix in it, as each binary printed it when it
/// had its own `main`: passed as an argument, the prefix changes the code of the whole run,
/// and with it the figures.
macro_rules! lines {
    ($prefix:expr; $($figure:ident),+ $(,)?) => {
        match $prefix {
            Prefix::None => lines!(@ ""; $($figure),+),
            Prefix::V1 => lines!(@ "v1 "; $($figure),+),
        }
    };
    (@ $prefix:literal;
        $machine:ident, $instr:ident, $turns:ident, $ticks_loop:ident, $mix_len:ident,
        $mix_frames:ident, $got:ident, $ticks_mix:ident, $got_slices:ident,
        $ticks_slices:ident, $got_random:ident, $ticks_random:ident, $timed:ident,
        $completing:ident
    ) => {{
        semihosting::println!("machine: {}", $machine);
        semihosting::println!(
            "calibration: a loop of {} instructions measured as {}",
            2 * $turns,
            $instr($ticks_loop)
        );
        semihosting::println!(
            concat!(
                $prefix,
                "telemetry mix, push: {} bytes, {} frames sent, {} parsed, {} instructions, ",
                "{} milli-instructions per byte"
            ),
            $mix_len,
            $mix_frames,
            $got,
            $instr($ticks_mix),
            $instr($ticks_mix) * 1_000 / $mix_len as u64
        );
        semihosting::println!(
            concat!(
                $prefix,
                "telemetry mix, slices: {} frames parsed, {} instructions, ",
                "{} milli-instructions per byte"
            ),
            $got_slices,
            $instr($ticks_slices),
            $instr($ticks_slices) * 1_000 / $mix_len as u64
        );
        semihosting::println!(
            concat!(
                $prefix,
                "random bytes, push: {} bytes, {} frames parsed, {} instructions, ",
                "{} milli-instructions per byte"
            ),
            RANDOM_LEN,
            $got_random,
            $instr($ticks_random),
            $instr($ticks_random) * 1_000 / RANDOM_LEN as u64
        );
        semihosting::println!(
            concat!(
                $prefix,
                "frame-completing byte: {} frames, {} milli-instructions each on average"
            ),
            $timed,
            $instr($completing) * 1_000 / $timed.max(1)
        );
    }};
}

/// The machine whose core's CPUID base register reads `cpuid`: a Cortex-M4 (part number
/// 0xC24) is mps2-an386 at 25 MHz, anything else the micro:bit at 16 MHz. Its name, and its
/// clock in Hz.
#[inline(always)]
fn machine_of(cpuid: u32) -> (&'static str, u32) {
    if (cpuid >> 4) & 0xFFF == 0xC24 {
        ("mps2-an386 Cortex-M4 thumbv7em", 25_000_000)
    } else {
        ("microbit Cortex-M0 thumbv6m", 16_000_000)
    }
}

/// Measures the parser of `G` and prints the figures; exits 0. Call it once, as the binary's
/// `main`: it takes the core peripherals. (Inlined into `main`: a call would be one more frame,
/// and the compiler, the call never returning, would keep it out of line.)
#[inline(always)]
pub fn run<G: Generation>() -> ! {
    // SAFETY: taken once, before anything else runs.
    let mut core = unsafe { cortex_m::Peripherals::steal() };
    let (machine, clock_hz) = machine_of(core.CPUID.base.read());
    time::start_cycles(&mut core.SYST);
    // Instructions per 1 000 ticks (1e9 ns per s / clock, ×1 000).
    let milli_instr_per_tick = 1_000_000_000_000u64 / u64::from(clock_hz);
    let instr = |ticks: u64| ticks * milli_instr_per_tick / 1_000;

    let overhead = (0..16).map(|_| measure(0, || {})).min().unwrap_or(0);

    let mut mix = [0u8; MIX_LEN];
    let mut ends = [0u16; MAX_FRAMES];
    let (mix_len, mix_frames) = G::mix(&mut mix, &mut ends);
    let mix = &mix[..mix_len];
    let mut random = [0u8; RANDOM_LEN];
    let mut rng = Lcg(7);
    for b in random.iter_mut() {
        *b = rng.next_value() as u8;
    }

    let mut got = 0;
    let ticks_mix = measure(overhead, || got = parse_all::<G>(black_box(mix)));
    let mut got_slices = 0;
    let ticks_slices = measure(overhead, || got_slices = parse_slices::<G>(black_box(mix)));
    let mut got_random = 0;
    let ticks_random = measure(overhead, || got_random = parse_all::<G>(black_box(&random)));

    // The byte that completes a frame: everything before it untimed.
    let mut parser = G::parser();
    let mut start = 0usize;
    let mut completing = 0u64;
    let mut timed = 0u64;
    for &end in &ends[..mix_frames] {
        let end = usize::from(end);
        for &byte in &mix[start..end - 1] {
            black_box(G::push(&mut parser, byte));
        }
        let last = mix[end - 1];
        completing += measure(overhead, || {
            black_box(G::push(&mut parser, black_box(last)));
        });
        timed += 1;
        start = end;
    }

    let (turns, ticks_loop) = calibrate(overhead);
    lines!(
        G::PREFIX;
        machine, instr, turns, ticks_loop, mix_len, mix_frames, got, ticks_mix, got_slices,
        ticks_slices, got_random, ticks_random, timed, completing
    );
    semihosting::process::exit(0)
}

/// The tick-to-instruction factor, checked on a loop of known length: 2 instructions (subs,
/// bne) per turn. The turns, and the ticks they took.
#[inline(always)]
fn calibrate(overhead: u64) -> (u32, u64) {
    let turns = 100_000u32;
    let ticks = measure(overhead, || {
        // SAFETY: a register-only loop: no memory, no stack.
        unsafe {
            core::arch::asm!(
                "2:",
                "subs {n}, #1",
                "bne 2b",
                n = inout(reg) turns => _,
                options(nomem, nostack),
            );
        }
    });
    (turns, ticks)
}
