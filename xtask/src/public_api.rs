//! `cargo xtask public-api [--bless]`: the protocol crate's public API (every feature) against
//! its checked-in snapshot.

use crate::cmd::{cargo_stdout_with, target_dir, workspace_root};
use crate::tools::{install_cargo_tool, install_nightly};

/// The checked-in public API of `chassis-protocol` with every feature, one item per line, as
/// cargo-public-api lists it.
const PUBLIC_API_SNAPSHOT: &str = "protocol/public-api.txt";

/// cargo-public-api's version, pinned: each release reads the rustdoc JSON of a range of
/// nightlies (0.52.0 reads that of nightly 2026-05-19, the one installed here).
const CARGO_PUBLIC_API: &str = "0.52.0";

/// How many removed or added lines a failed check shows.
const PUBLIC_API_SHOWN: usize = 40;

/// The protocol crate's public API (every feature) against its snapshot; `--bless` writes the
/// snapshot instead. A difference fails: a removed or changed item is a breaking change, an
/// added one a feature, and either way the snapshot and the changelog say so in the same
/// commit.
pub(crate) fn public_api(args: &[String]) -> Result<(), String> {
    let bless = match args {
        [] => false,
        [flag] if flag == "--bless" => true,
        _ => return Err("usage: cargo xtask public-api [--bless]".to_string()),
    };
    let current = current_public_api()?;
    let path = workspace_root()?.join(PUBLIC_API_SNAPSHOT);
    if bless {
        std::fs::write(&path, &current)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        eprintln!(
            "wrote {PUBLIC_API_SNAPSHOT}: {} lines",
            current.lines().count()
        );
        return Ok(());
    }
    let snapshot = std::fs::read_to_string(&path).map_err(|e| {
        format!(
            "cannot read {PUBLIC_API_SNAPSHOT} ({e}): write it with `cargo xtask public-api --bless`"
        )
    })?;
    let snapshot = snapshot.replace("\r\n", "\n");
    if snapshot == current {
        eprintln!(
            "chassis-protocol's public API: as in {PUBLIC_API_SNAPSHOT} ({} lines)",
            current.lines().count()
        );
        return Ok(());
    }
    Err(difference(&snapshot, &current))
}

/// The protocol crate's public API now, as cargo-public-api lists it from the nightly rustdoc's
/// JSON (its own target directory: the nightly's artefacts would only evict the main ones).
/// Left out: blanket impls (`impl<T> From<T> for T`: the standard library's, not this crate's)
/// and the auto traits stable Rust cannot name (`Freeze`, `UnsafeUnpin`: they come and go with
/// the nightly). `Send`, `Sync`, `Unpin` and the unwind-safety traits stay: losing one breaks
/// users.
fn current_public_api() -> Result<String, String> {
    install_nightly()?;
    install_cargo_tool(
        "public-api",
        "cargo-public-api",
        Some(CARGO_PUBLIC_API),
        // A debug build: a minute of compiling less than a release one on two cores, and it
        // reads this crate's JSON in about a second all the same.
        &["--debug"],
    )?;
    let target = target_dir()?.join("public-api");
    let listed = cargo_stdout_with(
        &[
            "public-api",
            "--manifest-path",
            &workspace_root()?.join("Cargo.toml").to_string_lossy(),
            "-p",
            "chassis-protocol",
            "--all-features",
            "--omit",
            "blanket-impls",
            "--color",
            "never",
        ],
        &[("CARGO_TARGET_DIR", &target)],
    )?;
    let unstable_auto_trait = |line: &str| {
        line.starts_with("impl")
            && (line.contains(" core::marker::Freeze for ")
                || line.contains(" core::marker::UnsafeUnpin for "))
    };
    let mut api = String::new();
    for line in listed.lines().filter(|l| !unstable_auto_trait(l)) {
        api.push_str(line);
        api.push('\n');
    }
    Ok(api)
}

/// What differs between the snapshot and the current API, shown on standard error, and the
/// error that says what to do about it.
fn difference(snapshot: &str, current: &str) -> String {
    let old: std::collections::BTreeSet<&str> = snapshot.lines().collect();
    let new: std::collections::BTreeSet<&str> = current.lines().collect();
    let show = |title: &str, sign: char, lines: Vec<&&str>| {
        if lines.is_empty() {
            return;
        }
        eprintln!("{title} ({}):", lines.len());
        for line in lines.iter().take(PUBLIC_API_SHOWN) {
            eprintln!("  {sign} {line}");
        }
        if lines.len() > PUBLIC_API_SHOWN {
            eprintln!("  … and {} more", lines.len() - PUBLIC_API_SHOWN);
        }
    };
    show(
        "removed or changed: a breaking change",
        '-',
        old.difference(&new).collect(),
    );
    show("added", '+', new.difference(&old).collect());
    if old == new {
        eprintln!("(the same lines, in another order or repeated another number of times)");
    }
    format!(
        "the public API of chassis-protocol (every feature) differs from {PUBLIC_API_SNAPSHOT} \
         (above). A removed or changed line is a breaking change (the next release is a major \
         one: 0.x → 0.(x+1)); an added one is a feature. If the change is intended, update the \
         snapshot with `cargo xtask public-api --bless` and add an entry under [Unreleased] in \
         protocol/CHANGELOG.md, in the same commit."
    )
}
