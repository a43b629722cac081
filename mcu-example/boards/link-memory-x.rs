// The linking the boards with a `memory.x` of their own share, written once: each one's
// `build.rs` takes it in with `include!` and calls `link_with_memory_x`.

use std::{env, fs, path::PathBuf};

/// Writes `memory_x` (the board's `memory.x`) to `OUT_DIR`, where the linker finds it, and links
/// the binaries with `--nmagic` and the linker scripts `scripts`, in that order.
fn link_with_memory_x(memory_x: &[u8], scripts: &[&str]) {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::write(out.join("memory.x"), memory_x).expect("OUT_DIR is writable");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rustc-link-arg-bins=--nmagic");
    for script in scripts {
        println!("cargo:rustc-link-arg-bins=-T{script}");
    }
}
