//! `cargo xtask python`: the Python package built as a user builds it, its tests and its types.

use crate::cmd::{check, run, workspace_root};
use std::process::Command;

/// The Python of the virtual environment `target/<name>` (made with `$PYTHON`, else `python3`,
/// if it is not there yet), its pip upgraded.
pub(crate) fn venv_python(name: &str) -> Result<String, String> {
    let venv = workspace_root()?.join("target").join(name);
    let python = venv.join("bin").join("python");
    if !python.is_file() {
        let venv = venv.to_string_lossy();
        run(
            &std::env::var("PYTHON").unwrap_or_else(|_| "python3".into()),
            &["-m", "venv", &venv],
        )?;
    }
    let python = python.to_string_lossy().into_owned();
    run(
        &python,
        &["-m", "pip", "install", "--quiet", "--upgrade", "pip"],
    )?;
    Ok(python)
}

/// The Python package: built as a user builds it (`pip install ./python`, maturin as the build
/// backend) into a virtual environment under `target/`, then its tests (pytest, against the
/// simulated boards on pseudo-terminals) and its examples' types (`mypy --strict`).
pub(crate) fn python() -> Result<(), String> {
    let root = workspace_root()?;
    let venv = root.join("target").join("python-venv");
    let python = venv_python("python-venv")?;
    let package = root.join("python");
    let package = package.to_string_lossy();
    let with_tests = format!("{package}[test]");
    run(
        &python,
        &[
            "-m",
            "pip",
            "install",
            "--quiet",
            "--force-reinstall",
            &with_tests,
        ],
    )?;
    let tests = root.join("python").join("tests");
    run(&python, &["-m", "pytest", "-q", &tests.to_string_lossy()])?;
    let examples = root.join("python").join("examples");
    if examples.is_dir() {
        run(
            &python,
            &["-m", "mypy", "--strict", &examples.to_string_lossy()],
        )?;
    }
    // The type stubs against the built module (run away from the source tree, so that the
    // installed package is the one imported).
    eprintln!("$ python -m mypy.stubtest chassis.chassis_native");
    check(
        Command::new(&python)
            .args(["-m", "mypy.stubtest", "chassis.chassis_native"])
            .current_dir(&venv),
        &python,
        |status| {
            format!(
                "the type stubs (python/chassis/chassis_native.pyi) differ from the module ({status})"
            )
        },
    )
}
