//! `cargo xtask ros2` and `cargo xtask ros2-bench`: the ROS 2 node checked from outside by an
//! independent DDS peer (Python, Cyclone DDS; `host-tests/ros2/`), both in a private network
//! namespace with only loopback, against the simulated board of each firmware generation.

use crate::cmd::{cargo, run_with, target_dir, workspace_root};
use crate::python::venv_python;
use crate::tools::ensure_apt;
use std::process::Command;

/// The virtual environment of the peer, under `target/`.
const VENV: &str = "ros2-venv";

/// `cargo xtask ros2`: the node and the CLI built (the dev profile: `cargo test --workspace`
/// has built them already, and every bound of the suite holds with them), the peer's packages
/// installed, its pytest suite run (it makes its own network namespace as it starts).
pub(crate) fn ros2() -> Result<(), String> {
    let peer = prepare(Profile::Dev)?;
    let tests = peer.dir.join("tests");
    run_with(
        &peer.python,
        &["-m", "pytest", "-q", &tests.to_string_lossy()],
        &peer.env(),
    )
}

/// `cargo xtask ros2-bench [ARGS]`: the node's figures (`/cmd_vel` to the wire, CPU at the
/// link's full rate, the stripped binary's size), printed as a table; `ARGS` go to the script
/// (`--help`).
pub(crate) fn ros2_bench(args: &[String]) -> Result<(), String> {
    let peer = prepare(Profile::Release)?;
    let script = peer.dir.join("bench.py");
    let script = script.to_string_lossy();
    let mut all = vec![script.as_ref()];
    all.extend(args.iter().map(String::as_str));
    run_with(&peer.python, &all, &peer.env())
}

/// What the peer runs with: its Python, its directory, the binaries under test.
struct Peer {
    python: String,
    dir: std::path::PathBuf,
    chassis: String,
    node: String,
}

impl Peer {
    /// The environment that names the binaries to the peer.
    fn env(&self) -> [(&str, &str); 2] {
        [
            ("CHASSIS_BIN", self.chassis.as_str()),
            ("CHASSIS_ROS2_BIN", self.node.as_str()),
        ]
    }
}

/// The build profile of the node and the CLI the peer runs.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Profile {
    /// The tests'.
    Dev,
    /// The figures'.
    Release,
}

/// Checks that a private network namespace can be made, installs `ip` if missing, builds the
/// node and the CLI in `profile`, and installs the peer's pinned packages into
/// `target/ros2-venv`.
fn prepare(profile: Profile) -> Result<Peer, String> {
    namespace_permitted()?;
    ensure_apt(
        "ip",
        "-V",
        "iproute2",
        "Debian/Ubuntu: `sudo apt-get install -y iproute2`",
    )?;
    let mut build = vec!["build", "-p", "chassis-ros2", "-p", "chassis-cli"];
    if profile == Profile::Release {
        build.push("--release");
    }
    cargo(&build)?;
    let dir = workspace_root()?.join("host-tests").join("ros2");
    let python = venv_python(VENV)?;
    let requirements = dir.join("requirements.txt");
    run_with(
        &python,
        &[
            "-m",
            "pip",
            "install",
            "--quiet",
            "-r",
            &requirements.to_string_lossy(),
        ],
        &[],
    )?;
    let built = target_dir()?.join(match profile {
        Profile::Dev => "debug",
        Profile::Release => "release",
    });
    Ok(Peer {
        python,
        dir,
        chassis: built.join("chassis").to_string_lossy().into_owned(),
        node: built.join("chassis-ros2").to_string_lossy().into_owned(),
    })
}

/// An error that says so unless `unshare -n true` runs: the tests keep every DDS packet inside
/// a network namespace of their own, which needs root (or `CAP_SYS_ADMIN`).
fn namespace_permitted() -> Result<(), String> {
    eprintln!("$ unshare -n true");
    let output = Command::new("unshare")
        .args(["-n", "true"])
        .output()
        .map_err(|e| format!("`unshare` (util-linux) is needed to run the ROS 2 tests: {e}"))?;
    if output.status.success() {
        return Ok(());
    }
    Err(format!(
        "a private network namespace is not permitted here (`unshare -n true`: {}): the ROS 2 \
         tests run the node and the peer in one, so that no DDS traffic leaves the machine; run \
         them as root or with CAP_SYS_ADMIN",
        String::from_utf8_lossy(&output.stderr).trim()
    ))
}
