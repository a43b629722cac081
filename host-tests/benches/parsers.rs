//! This crate's board → master parser beside published parsers of other serial protocols with
//! frames of similar sizes, each on a stream of its own protocol, in the same run: sbus-rs
//! (SBUS, 25-byte frames, byte at a time), uf-crsf and crsf (CRSF RC-channels packets, 26
//! bytes, slices). `cargo xtask bench` runs them and prints the table with the ratios.
//!
//! Beside them, a floor for byte paths (`StoreOnly`: store each byte, call out of line at a
//! frame's end, nothing else): what the byte-at-a-time interface itself costs here.
//!
//! Streams: about 1 MB each, built here. Ours is the board's telemetry mix at rest (IMU 100 Hz,
//! encoders 25 Hz, battery 1 Hz, replies), back to back; random bytes for the worst case.
//!
//! Beside them, in the same run, the v1.0.0 firmware's board → master parser
//! (`chassis_protocol::v1::DownlinkParser`) on about 1 MB of its own board's stream (32-byte
//! telemetry of a driven chassis, a reply a second: `chassis_host_tests::v1::Board`), frames back
//! to back, and on the same random bytes.

use chassis_host_tests::BoardStream;
use chassis_protocol::DownlinkParser;
use chassis_protocol::v1::{self, Parser as _};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;
use std::time::Duration;

const STREAM_BYTES: usize = 1 << 20;

fn telemetry() -> Vec<u8> {
    let (bytes, _) = BoardStream::new(2026, 2.0).take(STREAM_BYTES / 14);
    bytes
}

/// The v1.0.0 board's stream: frames until there is 1 MiB.
fn v1_telemetry() -> (Vec<u8>, usize) {
    let stream = chassis_host_tests::v1::Board::new(2026, 1.0).take(STREAM_BYTES / 31);
    (stream.bytes, stream.frames.len())
}

fn random() -> Vec<u8> {
    let mut rng = Pcg64Mcg::seed_from_u64(7);
    (0..STREAM_BYTES).map(|_| rng.random()).collect()
}

/// SBUS frames: `0F`, 16 channels of 11 bits packed in 22 bytes, flags, `00`.
fn sbus() -> Vec<u8> {
    let mut rng = Pcg64Mcg::seed_from_u64(8);
    let mut out = Vec::with_capacity(STREAM_BYTES);
    while out.len() < STREAM_BYTES {
        let channels: [u16; 16] = std::array::from_fn(|_| rng.random_range(172..1812));
        let mut frame = [0u8; 25];
        frame[0] = 0x0F;
        sbus_rs::pack_channels(&mut frame, &channels);
        frame[24] = 0x00;
        out.extend_from_slice(&frame);
    }
    out
}

/// CRC-8/DVB-S2 (polynomial 0xD5), as CRSF uses it.
fn crc8_dvb_s2(bytes: &[u8]) -> u8 {
    let mut crc = 0u8;
    for b in bytes {
        crc ^= b;
        for _ in 0..8 {
            crc = if crc & 0x80 != 0 {
                (crc << 1) ^ 0xD5
            } else {
                crc << 1
            };
        }
    }
    crc
}

/// CRSF RC-channels packets: `C8`, length 24, type `16`, 22 bytes of channels, CRC.
fn crsf() -> Vec<u8> {
    let mut rng = Pcg64Mcg::seed_from_u64(9);
    let mut out = Vec::with_capacity(STREAM_BYTES);
    while out.len() < STREAM_BYTES {
        let mut frame = vec![0xC8, 24, 0x16];
        frame.extend((0..22).map(|_| rng.random::<u8>()));
        let crc = crc8_dvb_s2(&frame[2..]);
        frame.push(crc);
        out.extend_from_slice(&frame);
    }
    out
}

fn ours_bytewise(bytes: &[u8]) -> usize {
    let mut parser = DownlinkParser::new();
    let mut n = 0;
    for b in bytes {
        n += usize::from(parser.push(*b).is_some());
    }
    n
}

fn ours_slices(bytes: &[u8]) -> usize {
    let mut parser = DownlinkParser::new();
    let mut n = 0;
    for chunk in bytes.chunks(64) {
        n += parser.frames(chunk).count();
    }
    n
}

fn v1_bytewise(bytes: &[u8]) -> usize {
    let mut parser = v1::DownlinkParser::new();
    let mut n = 0;
    for b in bytes {
        if parser.push(*b).is_some() {
            n += 1;
            // A frame found inside a damaged one may follow.
            while parser.poll().is_some() {
                n += 1;
            }
        }
    }
    n
}

fn v1_slices(bytes: &[u8]) -> usize {
    let mut parser = v1::DownlinkParser::new();
    let mut n = 0;
    for chunk in bytes.chunks(64) {
        n += parser.frames(chunk).count();
    }
    n
}

/// A floor for byte paths: a "parser" that only stores each byte through `&mut self`, counts to
/// a fixed frame length, and at a frame's end calls out of line (as any parser whose frame-end
/// work is not inlined into the caller's loop does): no header, no check, no decoding. Not a
/// parser: a reference for what the byte-at-a-time interface itself costs on this machine.
/// (With a call in the loop, the state lives in memory, and each byte waits for the last
/// byte's store of it.)
struct StoreOnly {
    buf: [u8; 16],
    pos: u8,
}

impl StoreOnly {
    #[inline]
    fn push(&mut self, byte: u8) -> Option<u8> {
        if let Some(slot) = self.buf.get_mut(usize::from(self.pos & 15)) {
            *slot = byte;
        }
        self.pos += 1;
        if self.pos == 15 {
            return self.frame_end();
        }
        None
    }

    #[inline(never)]
    fn frame_end(&mut self) -> Option<u8> {
        self.pos = 0;
        self.buf.get(14).copied()
    }
}

fn store_only_bytewise(bytes: &[u8]) -> usize {
    let mut floor = StoreOnly {
        buf: [0; 16],
        pos: 0,
    };
    let mut n = 0;
    for b in bytes {
        n += usize::from(floor.push(*b).is_some());
    }
    n
}

fn sbus_bytewise(bytes: &[u8]) -> usize {
    let mut parser = sbus_rs::StreamingParser::new();
    let mut n = 0;
    for b in bytes {
        n += usize::from(matches!(parser.push_byte(*b), Ok(Some(_))));
    }
    n
}

fn uf_crsf_slices(bytes: &[u8]) -> usize {
    let mut parser = uf_crsf::parser::CrsfParser::new();
    let mut n = 0;
    for chunk in bytes.chunks(64) {
        let mut input = chunk;
        n += parser
            .iter_packets(&mut input)
            .filter(Result::is_ok)
            .count();
    }
    n
}

fn crsf_slices(bytes: &[u8]) -> usize {
    let mut parser = crsf::PacketParser::<256>::new();
    let mut n = 0;
    for chunk in bytes.chunks(64) {
        parser.push_bytes(chunk);
        while let Some(packet) = parser.next_raw_packet() {
            n += usize::from(packet.is_ok());
        }
    }
    n
}

/// A benchmark: its name, its stream, and the parser run over it (frames found).
type Run<'a> = (&'a str, &'a [u8], fn(&[u8]) -> usize);

fn benches(c: &mut Criterion) {
    let telemetry = telemetry();
    let random = random();
    let sbus = sbus();
    let crsf = crsf();
    let (v1, v1_frames) = v1_telemetry();
    // Each parser must actually find its frames, or the comparison means nothing.
    assert_eq!(v1_bytewise(&v1), v1_frames);
    assert_eq!(v1_slices(&v1), v1_frames);
    assert!(ours_bytewise(&telemetry) > telemetry.len() / 16);
    assert_eq!(ours_slices(&telemetry), ours_bytewise(&telemetry));
    assert!(sbus_bytewise(&sbus) > sbus.len() / 26);
    eprintln!(
        "frames found: chassis {} of {} bytes; v1 {v1_frames} of {} bytes; sbus-rs {}, uf-crsf {}, crsf {} of {} packets",
        ours_bytewise(&telemetry),
        telemetry.len(),
        v1.len(),
        sbus_bytewise(&sbus),
        uf_crsf_slices(&crsf),
        crsf_slices(&crsf),
        crsf.len() / 26
    );
    // (uf-crsf loses packets that straddle two reads: its issue #95.)
    assert!(uf_crsf_slices(&crsf) > crsf.len() / 26 / 2);
    // crsf 2.0.1 pops 64 bytes per packet whatever its length, so on back-to-back packets it
    // finds about 40 % of them: shown for information, left out of the ratios.
    assert!(crsf_slices(&crsf) > 0);

    let mut group = c.benchmark_group("parsers");
    group
        .sample_size(11)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    let runs: [Run; 12] = [
        ("byte path: chassis telemetry", &telemetry, ours_bytewise),
        ("byte path: sbus-rs", &sbus, sbus_bytewise),
        (
            "byte path: store-only floor",
            &telemetry,
            store_only_bytewise,
        ),
        ("byte path: chassis random bytes", &random, ours_bytewise),
        ("slice path: chassis telemetry", &telemetry, ours_slices),
        ("slice path: uf-crsf", &crsf, uf_crsf_slices),
        ("slice path: crsf", &crsf, crsf_slices),
        ("slice path: chassis random bytes", &random, ours_slices),
        ("byte path: chassis v1 telemetry", &v1, v1_bytewise),
        ("byte path: chassis v1 random bytes", &random, v1_bytewise),
        ("slice path: chassis v1 telemetry", &v1, v1_slices),
        ("slice path: chassis v1 random bytes", &random, v1_slices),
    ];
    for (name, bytes, run) in runs {
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        group.bench_with_input(BenchmarkId::from_parameter(name), bytes, |b, bytes| {
            b.iter(|| run(black_box(bytes)))
        });
    }
    group.finish();
}

criterion_group!(parsers, benches);
criterion_main!(parsers);
