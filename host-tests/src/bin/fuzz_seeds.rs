//! Writes the fuzz targets' seed corpora, generated from the board-stream model (never copied
//! by hand): `fuzz-seeds <corpus dir>` makes `<dir>/<target>/seed-N` for every target.

use chassis_host_tests::BoardStream;
use chassis_host_tests::channel::{Noise, transmit};
use chassis_protocol::{Command, Motors, Register, Setting, Turn, Velocity, v1};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

fn write(dir: &Path, target: &str, n: usize, bytes: &[u8]) -> std::io::Result<()> {
    let dir = dir.join(target);
    std::fs::create_dir_all(&dir)?;
    std::fs::write(dir.join(format!("seed-{n}")), bytes)
}

fn seeds(dir: &Path) -> std::io::Result<usize> {
    let mut written = 0;
    for n in 0..16u64 {
        // Board streams, clean and noisy: downlink, and spliced (whose input starts with a seed).
        let (bytes, _) = BoardStream::new(n, 4.0).take(40);
        let noisy = transmit(&bytes, &Noise::mixed(1e-2), &mut Pcg64Mcg::seed_from_u64(n));
        write(dir, "downlink", written, &bytes)?;
        write(dir, "downlink", written + 1, &noisy.bytes)?;
        let mut spliced = n.to_le_bytes().to_vec();
        spliced.extend_from_slice(&noisy.bytes[..noisy.bytes.len().min(80)]);
        write(dir, "spliced", written, &spliced)?;
        // Command streams: uplink and round trips.
        let commands = [
            Command::from(Velocity::new(n as i32 * 100, -(n as i32), 7)),
            Command::from(Turn::by_deci_degrees(900 - n as i32 * 120)),
            Command::from(Motors::open_loop_duty([2_500, -2_500, n as i32, 0])),
            Command::from(Setting::Read(
                Register::ALL[n as usize % Register::ALL.len()],
            )),
        ];
        let mut uplink: Vec<u8> = Vec::new();
        for command in &commands {
            uplink.extend_from_slice(&command.clone().encode());
        }
        write(dir, "uplink", written, &uplink)?;
        write(dir, "roundtrip", written, &uplink[..uplink.len().min(24)])?;
        // v1.0.0 (`7B … BCC 7D`): telemetry with replies, then commands, clean and noisy
        // (the fuzz input is a pair: the bytes, then the slice lengths).
        let mut v1_bytes = Vec::new();
        for i in 0..6i16 {
            let t = v1::Telemetry {
                velocity: [i, n as i16, -i],
                quaternion: [1_000, 0, 0, i],
                battery_mv: 11_800,
                ..v1::Telemetry::default()
            };
            v1_bytes.extend_from_slice(&t.encode());
            let r = v1::Readback::ALL[(n as usize + i as usize) % 5];
            v1_bytes.extend_from_slice(&v1::Command::Readback(r).encode());
        }
        v1_bytes.extend_from_slice(
            &v1::Command::BodyVelocity(v1::BodyVelocity::new(n as i16 * 10, 300, -50)).encode(),
        );
        let v1_noisy = transmit(
            &v1_bytes,
            &Noise::mixed(1e-2),
            &mut Pcg64Mcg::seed_from_u64(n),
        );
        write(dir, "v1", written, &v1_bytes)?;
        write(dir, "v1", written + 1, &v1_noisy.bytes)?;
        written += 2;
    }
    Ok(written)
}

fn main() -> ExitCode {
    let Some(dir) = std::env::args_os().nth(1).map(PathBuf::from) else {
        eprintln!("usage: fuzz-seeds <corpus dir>");
        return ExitCode::from(2);
    };
    match seeds(&dir) {
        Ok(n) => {
            println!("fuzz-seeds: {n} seeds per target in {}", dir.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("fuzz-seeds: cannot write under {}: {e}", dir.display());
            ExitCode::FAILURE
        }
    }
}
