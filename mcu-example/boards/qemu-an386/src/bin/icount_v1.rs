//! Instructions per byte of the v1.0.0 board → master parser (`chassis_protocol::v1::DownlinkParser`)
//! on the Cortex-M itself, measured as `icount` measures the 2020 parser (its own binary, so
//! that the 2020 figures stay those of a binary with nothing else in it): run under QEMU with
//! `-icount shift=0`, SysTick counts instructions (40 a tick on mps2-an386, Cortex-M4 at 25 MHz;
//! 62.5 on the micro:bit, Cortex-M0 at 16 MHz). The same code is built for thumbv7em and
//! thumbv6m; the core's CPUID tells which machine it runs on.
//!
//! It prints one line per figure over semihosting (plain text, each starting with `v1`) and
//! exits 0. `cargo xtask icount` runs it on both machines beside `icount` and prints the table.

#![no_std]
#![no_main]

use board_qemu_an386::time;
use chassis_protocol::v1;
use core::hint::black_box;

/// The board's stream: about five seconds of it.
const MIX_LEN: usize = 4_096;
/// Random bytes.
const RANDOM_LEN: usize = 4_096;

/// A small deterministic generator (the same stream on both machines).
struct Lcg(u32);

impl Lcg {
    fn next(&mut self) -> u32 {
        self.0 = self.0.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        self.0 >> 8
    }
    /// A sensor value near 0 (±`range`): at rest a gyro reads small numbers, and -6..-4 are
    /// `FF FA`..`FF FC`: false headers are ordinary traffic.
    fn small(&mut self, range: u32) -> i16 {
        (self.next() % (2 * range + 1)) as i16 - range as i16
    }
}

/// The v1.0.0 board's stream: 32-byte telemetry at 22 Hz (a chassis driving and turning: the
/// velocity steps about, the quaternion × 1000 turns about z, the battery near 12 V) with a
/// readback reply every second, back to back; the frame ends are recorded.
fn v1_mix(buf: &mut [u8; MIX_LEN], ends: &mut [u16; 512]) -> (usize, usize) {
    let mut rng = Lcg(2026);
    let mut len = 0;
    let mut frames = 0;
    // The heading as (cos, sin) of half the angle, Q14.
    let (mut c, mut s) = (16_384i32, 0i32);
    let mut velocity = [0i16; 3];
    for tick in 0u32.. {
        for (v, limit) in velocity.iter_mut().zip([600, 1_000, 2_500]) {
            *v = (*v + rng.small(60)).clamp(-limit, limit);
        }
        // Half of wz × 45 ms, in Q14 radians: wz (mrad/s) × 0.0225 × 16.384.
        let half = i32::from(velocity[2]) * 369 / 1_000;
        let (c2, s2) = (c - ((s * half) >> 14), s + ((c * half) >> 14));
        // Back onto the unit circle (one Newton step).
        let n2 = (c2 * c2 + s2 * s2) >> 14;
        let k = (3 * 16_384 - n2) / 2;
        (c, s) = ((c2 * k) >> 14, (s2 * k) >> 14);
        let t = v1::Telemetry {
            velocity: [
                velocity[0] + rng.small(4),
                velocity[1] + rng.small(4),
                velocity[2] + rng.small(4),
            ],
            accel: [rng.small(120), rng.small(120), 16_384 + rng.small(120)],
            gyro: [rng.small(6), rng.small(6), velocity[2] + rng.small(8)],
            quaternion: [
                ((c * 1_000) >> 14) as i16,
                rng.small(2),
                rng.small(2),
                ((s * 1_000) >> 14) as i16,
            ],
            battery_mv: 12_000 + rng.small(200),
        };
        let frame = t.encode();
        if len + frame.len() > MIX_LEN || frames >= ends.len() {
            break;
        }
        buf[len..len + frame.len()].copy_from_slice(&frame);
        len += frame.len();
        ends[frames] = len as u16;
        frames += 1;
        if tick % 22 == 11 {
            let request = v1::Readback::ALL[rng.next() as usize % v1::Readback::ALL.len()];
            let mut payload = [0u8; 10];
            for b in payload.iter_mut().skip(2) {
                *b = rng.next() as u8;
            }
            let frame = v1::Reply { request, payload }.encode();
            if len + frame.len() > MIX_LEN || frames >= ends.len() {
                break;
            }
            buf[len..len + frame.len()].copy_from_slice(&frame);
            len += frame.len();
            ends[frames] = len as u16;
            frames += 1;
        }
    }
    (len, frames)
}

/// The v1.0.0 parser's slice path over `bytes`; the frames it gave.
fn v1_parse_slices(bytes: &[u8]) -> u32 {
    use v1::Parser as _;
    let mut parser = v1::DownlinkParser::new();
    let mut frames = 0u32;
    for frame in parser.frames(bytes) {
        black_box(&frame);
        frames += 1;
    }
    frames
}

/// The v1.0.0 parser over `bytes`, one byte at a time (`push`, then `poll` after a frame until
/// nothing more); the frames it gave.
fn v1_parse_all(bytes: &[u8]) -> u32 {
    let mut parser = v1::DownlinkParser::new();
    let mut frames = 0u32;
    for &byte in bytes {
        let mut out = parser.push(byte);
        while let Some(frame) = out {
            black_box(&frame);
            frames += 1;
            out = parser.poll();
        }
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

#[cortex_m_rt::entry]
fn main() -> ! {
    // SAFETY: taken once, before anything else runs.
    let mut core = unsafe { cortex_m::Peripherals::steal() };
    // Cortex-M4 (part number 0xC24): mps2-an386 at 25 MHz; otherwise the micro:bit at 16 MHz.
    let m4 = (core.CPUID.base.read() >> 4) & 0xFFF == 0xC24;
    let (machine, clock_hz) = if m4 {
        ("mps2-an386 Cortex-M4 thumbv7em", 25_000_000u32)
    } else {
        ("microbit Cortex-M0 thumbv6m", 16_000_000u32)
    };
    time::start_cycles(&mut core.SYST);
    // Instructions per 1 000 ticks (1e9 ns per s / clock, ×1 000).
    let milli_instr_per_tick = 1_000_000_000_000u64 / u64::from(clock_hz);
    let instr = |ticks: u64| ticks * milli_instr_per_tick / 1_000;

    let overhead = (0..16).map(|_| measure(0, || {})).min().unwrap_or(0);

    let mut buf = [0u8; MIX_LEN];
    let mut ends = [0u16; 512];
    let (len, frames) = v1_mix(&mut buf, &mut ends);
    let bytes = &buf[..len];
    let mut random = [0u8; RANDOM_LEN];
    let mut rng = Lcg(7);
    for b in random.iter_mut() {
        *b = rng.next() as u8;
    }

    let mut got = 0;
    let ticks_mix = measure(overhead, || got = v1_parse_all(black_box(bytes)));
    let mut got_slices = 0;
    let ticks_slices = measure(overhead, || got_slices = v1_parse_slices(black_box(bytes)));
    let mut got_random = 0;
    let ticks_random = measure(overhead, || got_random = v1_parse_all(black_box(&random)));

    // The byte that completes a frame: everything before it untimed.
    let mut parser = v1::DownlinkParser::new();
    let mut start = 0usize;
    let mut completing = 0u64;
    let mut timed = 0u64;
    for &end in &ends[..frames] {
        let end = usize::from(end);
        for &byte in &bytes[start..end - 1] {
            black_box(parser.push(byte));
        }
        let last = bytes[end - 1];
        completing += measure(overhead, || {
            black_box(parser.push(black_box(last)));
        });
        timed += 1;
        start = end;
    }

    // The tick-to-instruction factor, checked on a loop of known length: 2 instructions (subs,
    // bne) per turn.
    let turns = 100_000u32;
    let ticks_loop = measure(overhead, || {
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
    semihosting::println!("machine: {}", machine);
    semihosting::println!(
        "calibration: a loop of {} instructions measured as {}",
        2 * turns,
        instr(ticks_loop)
    );
    semihosting::println!(
        "v1 telemetry mix, push: {} bytes, {} frames sent, {} parsed, {} instructions, {} milli-instructions per byte",
        len,
        frames,
        got,
        instr(ticks_mix),
        instr(ticks_mix) * 1_000 / len as u64
    );
    semihosting::println!(
        "v1 telemetry mix, slices: {} frames parsed, {} instructions, {} milli-instructions per byte",
        got_slices,
        instr(ticks_slices),
        instr(ticks_slices) * 1_000 / len as u64
    );
    semihosting::println!(
        "v1 random bytes, push: {} bytes, {} frames parsed, {} instructions, {} milli-instructions per byte",
        RANDOM_LEN,
        got_random,
        instr(ticks_random),
        instr(ticks_random) * 1_000 / RANDOM_LEN as u64
    );
    semihosting::println!(
        "v1 frame-completing byte: {} frames, {} milli-instructions each on average",
        timed,
        instr(completing) * 1_000 / timed.max(1)
    );
    semihosting::process::exit(0)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    semihosting::println!("panic: {}", info);
    semihosting::process::exit(101)
}
