//! `cargo xtask package`: the crates published to the registry packaged together, each built
//! from its package alone; the protocol crate's file list and size.

use crate::cmd::{cargo, cargo_stdout, target_dir};
use std::path::{Path, PathBuf};

/// The crates published to the registry, each after those it depends on. Every other member
/// keeps the workspace's `publish = false`.
const PUBLISHED: [&str; 4] = [
    "chassis-protocol",
    "chassis-bringup",
    "chassis-capture",
    "chassis-cli",
];

/// The published crates packaged together, as `cargo publish --workspace` would upload them:
/// each `.crate` is unpacked and built on its own, its local dependencies taken from their
/// packages (not from the workspace), so a file left out of a package, a path dependency
/// without a version or a manifest the registry would refuse fails here. Prints what goes into
/// the protocol crate's package and the size of its `.crate`.
///
/// `--allow-dirty`: the package is made of the files on disk, as the rest of `test` checks them
/// (CI's clone is clean anyway; a developer's work in progress must not fail this step).
pub(crate) fn package() -> Result<(), String> {
    let list = cargo_stdout(&[
        "package",
        "--quiet",
        "--allow-dirty",
        "--list",
        "-p",
        "chassis-protocol",
    ])?;
    forget_unpacked_packages()?;
    // Verified in a target directory of their own, whose builds of our crates are thrown away
    // first: cargo takes a registry crate of the same name and version as unchanged.
    let verify = target_dir()?.join("package-verify");
    for build in ours(&verify.join("debug").join(".fingerprint")) {
        let _ = std::fs::remove_dir_all(build);
    }
    let verify = verify.to_string_lossy().into_owned();
    let mut args = vec![
        "package",
        "--quiet",
        "--allow-dirty",
        "--target-dir",
        &verify,
    ];
    for name in PUBLISHED {
        args.extend(["-p", name]);
    }
    cargo(&args)?;
    let dir = target_dir()?.join("package-verify").join("package");
    print_protocol_package(&list, &dir)
}

/// Cargo unpacks the packages it verifies the others against into `$CARGO_HOME/registry/src`,
/// under a directory per temporary registry, and reuses what it finds there for the same name
/// and version: an earlier run's sources. Those of our own crates are removed first.
fn forget_unpacked_packages() -> Result<(), String> {
    let home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cargo")))
        .ok_or("neither CARGO_HOME nor HOME is set")?;
    let Ok(registries) = std::fs::read_dir(home.join("registry").join("src")) else {
        return Ok(());
    };
    for registry in registries.filter_map(Result::ok) {
        // Temporary registries are named "-<hash>"; the real ones after their host.
        if !registry.file_name().to_string_lossy().starts_with('-') {
            continue;
        }
        for unpacked in ours(&registry.path()) {
            std::fs::remove_dir_all(&unpacked)
                .map_err(|e| format!("cannot remove {}: {e}", unpacked.display()))?;
        }
    }
    Ok(())
}

/// What in `dir` belongs to a published crate of ours (named after it: `<crate>-…`); nothing
/// if `dir` cannot be read.
fn ours(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .filter_map(Result::ok)
        .filter(|entry| {
            let name = entry.file_name().to_string_lossy().into_owned();
            PUBLISHED.iter().any(|p| name.starts_with(&format!("{p}-")))
        })
        .map(|entry| entry.path())
        .collect()
}

/// Prints the protocol crate's package: its newest `.crate` in `dir`, its size, and `list`
/// (`cargo package --list`), one file a line.
fn print_protocol_package(list: &str, dir: &Path) -> Result<(), String> {
    let newest = std::fs::read_dir(dir)
        .map_err(|e| format!("cannot read {}: {e}", dir.display()))?
        .filter_map(Result::ok)
        .filter(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            name.starts_with("chassis-protocol-") && name.ends_with(".crate")
        })
        .filter_map(|e| Some((e.metadata().ok()?.modified().ok()?, e.path())))
        .max()
        .map(|(_, path)| path)
        .ok_or_else(|| format!("no chassis-protocol .crate in {}", dir.display()))?;
    let bytes = std::fs::metadata(&newest)
        .map_err(|e| format!("cannot read {}: {e}", newest.display()))?
        .len();
    let files: Vec<&str> = list.lines().filter(|l| !l.is_empty()).collect();
    println!(
        "chassis-protocol's package: {} files, {:.1} KiB ({})",
        files.len(),
        bytes as f64 / 1024.0,
        newest.file_name().unwrap_or_default().to_string_lossy()
    );
    for file in files {
        println!("  {file}");
    }
    Ok(())
}
