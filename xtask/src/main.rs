//! The workspace's tasks, run with `cargo xtask <task>` (an alias in `.cargo/config.toml`).
//!
//! | task | what it does |
//! |---|---|
//! | `demo` | the main job: the bring-up firmware in QEMU (mps2-an386, Cortex-M4) against the simulated chassis over TCP, its log decoded, a verdict |
//! | `test` | everything CI checks: format, lints, tests, docs, the published crates' packages, the protocol crate's public API against its snapshot, `no_std` builds for Cortex-M, the link-time no-panic proofs (host and firmware), every board's firmware, the size and instruction-count budgets, the end-to-end tests in QEMU, and a short, repeatable run of every fuzz target (fixed seed and run count) |
//! | `package` | the crates published to the registry packaged together, each built from its package alone; the protocol crate's file list and size (part of `test`) |
//! | `public-api [--bless]` | the protocol crate's public API (every feature) against `protocol/public-api.txt`; `--bless` writes the snapshot (the check is part of `test`) |
//! | `size` | flash and RAM of every board's firmware, and the protocol crate's share (size probes) |
//! | `icount` | the downlink parsers' (2020 and v1.0.0) instructions per byte on the emulated Cortex-M4 and Cortex-M0; with `--profile`, where the 2020 parser's go on each core, by function and by byte, and its costliest bytes |
//! | `fuzz [SECONDS]` | only the fuzz targets, each for SECONDS (default 30), exploring: random seed, corpora kept |
//! | `sweep [--seed N] [--v1]` | the full noise sweep of the downlink parser over every stream model (a few minutes; not part of `test`), then the v1.0.0 board → master parser's (`--v1`: only that one, about 15 s) |
//! | `bench [--runs N]` | the parser beside its peers (sbus-rs, uf-crsf, crsf) and the v1.0.0 parser in one run (or N: the median of each run's ratios): a table with the ratios (not part of `test`, which only builds it) |
//! | `ros2` | the ROS 2 node (`chassis-ros2`) and the CLI built, then checked from outside by an independent DDS peer (Python, Cyclone DDS, `host-tests/ros2/`) in a private network namespace, against the simulated board of each generation: motion, odometry drift, the `/cmd_vel` timeout, the stop on signals, every message's bytes against an independent CDR encoder (part of `test`; needs root for the namespace) |
//! | `ros2-bench [ARGS]` | the node's figures: `/cmd_vel` to the wire p50/p99, CPU at the link's full rate, the stripped binary's size (not part of `test`) |
//! | `python` | the Python package built into a virtual environment (`target/python-venv`) as `pip install ./python` builds it, its pytest suite and `mypy --strict` on its examples (part of `test`) |
//! | `host-demo` | frames built and a noisy board stream parsed, on the host |
//! | `qemu ELF [--scenario NAME]` | boots a firmware in QEMU against the simulated chassis (the QEMU board's cargo runner) |
//!
//! Each task installs what it needs (rustup targets, `qemu-system-arm` through apt when run as
//! root, defmt-print, the nightly toolchain, cargo-fuzz, cargo-public-api, cargo-hack and cargo-nextest) before it runs, so
//! a fresh machine with rustup and cargo needs nothing else.
//!
//! A module per family of tasks: [`mod@test`], [`package`], [`public_api`], [`python`], [`ros2`], [`mod@bench`]
//! (and `sweep`), [`fuzz`], [`firmware`] (`demo`, `qemu`, `size`, `icount`, the firmware half
//! of `test`); [`cmd`] runs the tools they drive, [`tools`] installs them.

mod bench;
mod cmd;
mod firmware;
mod fuzz;
mod package;
mod public_api;
mod python;
mod ros2;
mod test;
mod tools;

use std::process::ExitCode;

fn main() -> ExitCode {
    let task = std::env::args().nth(1).unwrap_or_default();
    let args: Vec<String> = std::env::args().skip(2).collect();
    let result = match task.as_str() {
        "demo" => firmware::demo(),
        "host-demo" => cmd::host_tests("--example", "demo", &[]),
        "size" => firmware::size(),
        "icount" => match args.as_slice() {
            [] => firmware::icount(),
            [flag] if flag == "--profile" => firmware::profile(),
            _ => Err("usage: cargo xtask icount [--profile]".to_string()),
        },
        "qemu" => firmware::qemu(&args),
        "test" => test::test(),
        "python" => python::python(),
        "ros2" => ros2::ros2(),
        "ros2-bench" => ros2::ros2_bench(&args),
        "package" => package::package(),
        "public-api" => public_api::public_api(&args),
        "sweep" => bench::sweep(&args),
        "bench" => bench::bench(&args),
        "fuzz" => {
            let seconds = args.first().map_or("30", String::as_str);
            match seconds.parse::<u32>() {
                Ok(s) if s > 0 => fuzz::fuzz(fuzz::FuzzRun::Explore(s)),
                _ => Err(format!(
                    "fuzz takes a number of seconds per target, not {seconds:?}"
                )),
            }
        }
        _ => {
            eprintln!(
                "usage: cargo xtask <demo | test | python | ros2 | ros2-bench | package | public-api [--bless] | size | \
                 icount [--profile] | sweep [--seed N] [--v1] | bench [--runs N] | fuzz [SECONDS] | host-demo | \
                 qemu FIRMWARE.elf>"
            );
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("xtask {task}: {message}");
            ExitCode::FAILURE
        }
    }
}
