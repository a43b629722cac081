//! Puts `memory.x` where the linker finds it and links with cortex-m-rt's and defmt's scripts.

include!("../link-memory-x.rs");

fn main() {
    link_with_memory_x(include_bytes!("memory.x"), &["link.x", "defmt.x"]);
}
