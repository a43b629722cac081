//! Puts `memory.x` where the linker finds it and links with cortex-m-rt's, embassy-rp's and
//! defmt's scripts.

include!("../link-memory-x.rs");

fn main() {
    link_with_memory_x(
        include_bytes!("memory.x"),
        &["link.x", "link-rp.x", "defmt.x"],
    );
}
