//! `chassis ros2 ARGS…` from outside: the node beside the `chassis` program is run with every
//! argument as given and its exit status is the command's; without it, a clear error and 127.
//! The node here is a stand-in script that says what it was given.

#![cfg(unix)]

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::{Mutex, MutexGuard};

/// A fresh folder holding a copy of `chassis` (so that "beside the program" is this folder).
fn folder(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("chassis-ros2-front-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let _files = files();
    std::fs::copy(env!("CARGO_BIN_EXE_chassis"), dir.join("chassis")).unwrap();
    dir
}

/// Held while this test process writes a program (the copy of `chassis`, a script) and while
/// it starts one. A child forked by another test's thread while a program is open for writing
/// keeps it open, and running that program then fails with "text file busy"; with the lock no
/// fork falls while one is.
static FILES: Mutex<()> = Mutex::new(());

fn files() -> MutexGuard<'static, ()> {
    FILES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

trait OutputRetrying {
    /// `output()`, started under [`FILES`] (and tried again on "text file busy", which a
    /// process outside the lock can still cause).
    fn output_retrying(&mut self) -> Output;
}

impl OutputRetrying for Command {
    fn output_retrying(&mut self) -> Output {
        for _ in 0..50 {
            let output = {
                let _files = files();
                self.output()
            };
            match output {
                Err(e) if e.kind() == std::io::ErrorKind::ExecutableFileBusy => {
                    std::thread::sleep(std::time::Duration::from_millis(20));
                }
                other => return other.unwrap(),
            }
        }
        self.output().unwrap()
    }
}

/// An executable script at `path`.
fn script(path: &Path, text: &str) {
    let _files = files();
    std::fs::write(path, text).unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn the_node_beside_chassis_gets_every_argument_and_gives_its_status() {
    let dir = folder("beside");
    let said = dir.join("args");
    script(
        &dir.join("chassis-ros2"),
        &format!(
            "#!/bin/sh\nfor a in \"$@\"; do printf '%s\\n' \"$a\"; done > '{}'\nexit 7\n",
            said.display()
        ),
    );
    let out = Command::new(dir.join("chassis"))
        .args([
            "ros2",
            "--port",
            "/dev/null",
            "--stamped",
            "-p",
            "drive:=omni",
            "a b",
            "--help",
        ])
        .env("PATH", "")
        .output_retrying();
    assert_eq!(out.status.code(), Some(7), "{out:?}");
    assert_eq!(
        std::fs::read_to_string(&said).unwrap(),
        "--port\n/dev/null\n--stamped\n-p\ndrive:=omni\na b\n--help\n"
    );
    // The global options before `ros2` go to the node too.
    let out = Command::new(dir.join("chassis"))
        .args([
            "--port",
            "/dev/pts/9",
            "--firmware",
            "v1",
            "ros2",
            "--no-tf",
        ])
        .env("PATH", "")
        .output_retrying();
    assert_eq!(out.status.code(), Some(7), "{out:?}");
    assert_eq!(
        std::fs::read_to_string(&said).unwrap(),
        "--port\n/dev/pts/9\n--firmware\nv1.0.0\n--no-tf\n"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_node_on_path_is_found_and_none_is_a_clear_error() {
    let dir = folder("path");
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let out = Command::new(dir.join("chassis"))
        .args(["ros2", "--port", "/dev/null"])
        .env("PATH", &bin)
        .output_retrying();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(127), "{stderr}");
    assert!(
        stderr.contains("`chassis-ros2` is not installed"),
        "{stderr}"
    );
    assert!(stderr.contains("cargo install --path ros2"), "{stderr}");
    script(&bin.join("chassis-ros2"), "#!/bin/sh\nexit 0\n");
    let out = Command::new(dir.join("chassis"))
        .args(["ros2"])
        .env("PATH", &bin)
        .output_retrying();
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn record_is_refused_for_the_node() {
    let dir = folder("record");
    let out = Command::new(dir.join("chassis"))
        .args(["--record", "x.csv", "ros2", "--port", "/dev/null"])
        .env("PATH", "")
        .output_retrying();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--record is not for the ROS 2 node"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
