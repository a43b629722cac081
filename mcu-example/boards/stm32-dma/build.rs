//! Links with cortex-m-rt's and defmt's scripts (`memory.x` comes from embassy-stm32's
//! `memory-x` feature, for the chip chosen in Cargo.toml).

fn main() {
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
