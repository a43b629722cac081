//! SIGHUP stops the chassis at once and ends the node with status 129 (its own process: a
//! signal caught stays caught).

mod common;

#[test]
fn hup_stops_the_chassis_and_ends_with_129() {
    common::stops_on(signal_hook::consts::SIGHUP, 129);
}
