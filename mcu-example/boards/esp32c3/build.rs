//! Links with esp-hal's scripts (`linkall.x`: the ESP32-C3's memory map, its ROM functions and
//! esp-riscv-rt's start-up) and defmt's. No `memory.x`: esp-hal brings the chip's.

fn main() {
    println!("cargo:rustc-link-arg-bins=-Tlinkall.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
