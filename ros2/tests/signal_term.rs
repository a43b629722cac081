//! SIGTERM stops the chassis at once and ends the node with status 143 (its own process: a
//! signal caught stays caught).

mod common;

#[test]
fn term_stops_the_chassis_and_ends_with_143() {
    common::stops_on(signal_hook::consts::SIGTERM, 143);
}
