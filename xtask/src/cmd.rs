//! Running the tools a task drives: a command echoed before it runs, cargo (the one that runs
//! the task), and where the workspace and its build directory are.

use std::process::{Command, ExitStatus};

/// Runs a command, echoing it; an error names the command if it fails.
pub(crate) fn run(program: &str, args: &[&str]) -> Result<(), String> {
    run_with(program, args, &[])
}

/// [`run`], with extra environment variables for the command.
pub(crate) fn run_with(program: &str, args: &[&str], env: &[(&str, &str)]) -> Result<(), String> {
    let name = std::path::Path::new(program)
        .file_name()
        .map_or_else(|| program.into(), |n| n.to_string_lossy());
    eprintln!("$ {name} {}", args.join(" "));
    check(
        Command::new(program).args(args).envs(env.iter().copied()),
        program,
        |status| format!("`{program} {}` failed ({status})", args.join(" ")),
    )
}

/// Runs `command`, already echoed: `Ok` if it succeeds, else the error `failed` makes of its
/// status (`could not start {what}: …` if it does not start).
pub(crate) fn check(
    command: &mut Command,
    what: &str,
    failed: impl FnOnce(ExitStatus) -> String,
) -> Result<(), String> {
    let status = command
        .status()
        .map_err(|e| format!("could not start {what}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(failed(status))
    }
}

/// The cargo that runs this task.
pub(crate) fn cargo_program() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string())
}

/// Runs the cargo that runs this task with `args`.
pub(crate) fn cargo(args: &[&str]) -> Result<(), String> {
    run(&cargo_program(), args)
}

/// What `cargo <args>` prints on standard output; its standard error is shown only if it fails.
pub(crate) fn cargo_stdout(args: &[&str]) -> Result<String, String> {
    cargo_stdout_with(args, &[])
}

/// [`cargo_stdout`], with extra environment variables, through the rustup proxy (so that a
/// `+toolchain` argument, or a tool that gives one itself, works).
pub(crate) fn cargo_stdout_with(
    args: &[&str],
    env: &[(&str, &std::path::Path)],
) -> Result<String, String> {
    eprintln!("$ cargo {}", args.join(" "));
    let output = Command::new("cargo")
        .args(args)
        .envs(env.iter().copied())
        .output()
        .map_err(|e| format!("could not start cargo: {e}"))?;
    if !output.status.success() {
        eprint!("{}", String::from_utf8_lossy(&output.stderr));
        return Err(format!(
            "`cargo {}` failed ({})",
            args.join(" "),
            output.status
        ));
    }
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

/// The build directory: `CARGO_TARGET_DIR`, or `target/` at the root.
pub(crate) fn target_dir() -> Result<std::path::PathBuf, String> {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) => Ok(dir.into()),
        None => Ok(workspace_root()?.join("target")),
    }
}

/// The workspace root: the parent of this crate's directory.
pub(crate) fn workspace_root() -> Result<std::path::PathBuf, String> {
    let manifest =
        std::env::var("CARGO_MANIFEST_DIR").map_err(|_| "run me with cargo xtask".to_string())?;
    std::path::Path::new(&manifest)
        .parent()
        .map(std::path::Path::to_path_buf)
        .ok_or_else(|| "no workspace root above xtask".to_string())
}

/// Runs a release build of a `chassis-host-tests` binary or example (`kind` is `--bin` or
/// `--example`).
pub(crate) fn host_tests(kind: &str, name: &str, args: &[&str]) -> Result<(), String> {
    let run = [
        "run",
        "--release",
        "--quiet",
        "-p",
        "chassis-host-tests",
        kind,
        name,
        "--",
    ];
    cargo(&[&run[..], args].concat())
}
