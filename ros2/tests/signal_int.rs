//! SIGINT stops the chassis at once and ends the node with status 130 (its own process: a
//! signal caught stays caught).

mod common;

#[test]
fn int_stops_the_chassis_and_ends_with_130() {
    common::stops_on(signal_hook::consts::SIGINT, 130);
}
