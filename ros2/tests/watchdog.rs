//! The `/cmd_vel` watchdog and the stale-stamp rule against the simulated boards, through a
//! pseudo-terminal and the node's real port, driver and loop (no DDS): what reaches the board
//! and when.

mod common;

use chassis_protocol::driver::{DriverCore, v1};
use chassis_ros2::board::Generation;
use chassis_ros2::msg::DiagnosticStatus;
use chassis_ros2::node::{self, Out};
use chassis_ros2::params::{DriveKind, Params};
use chassis_ros2::stats::Latency;
use common::{Script, Sim, ms_between, settings, stamped, steady, twist};

/// Runs the 2020 node on `sim` with `params` through `script`.
fn run_2020(sim: &Sim, params: Params, script: &mut Script) -> node::End {
    let driver = DriverCore::open(&sim.path).expect("the pty opens");
    let mut latency = Latency::default();
    node::run(driver, &settings(&sim.path, params), script, &mut latency)
}

#[test]
fn a_silent_cmd_vel_stops_the_chassis_after_the_timeout() {
    let sim = Sim::v2020();
    // 0.3 m/s forward every 100 ms from 0 to 300 ms; then nothing.
    let mut script = Script::new(steady(twist(0.3, 0.0, 0.0), 0, 300, 100), 1_500);
    let end = run_2020(&sim, Params::default(), &mut script);
    assert!(end.stopped.confirmed(), "{:?}", end.stopped);
    let frames = sim.velocities_2020();
    let first_given = script.given[0];
    let last_given = *script.given.last().unwrap();
    // Forward is the board's Y, at the simulator's 1000 raw per m/s.
    let moving: Vec<_> = frames
        .iter()
        .filter(|f| (f.1, f.2, f.3) == (0, 300, 0))
        .collect();
    let first = moving.first().expect("the chassis was driven");
    assert!(
        ms_between(first_given, first.0) < 30.0,
        "the first command went out at once: {} ms",
        ms_between(first_given, first.0)
    );
    let stop = frames
        .iter()
        .find(|f| (f.1, f.2, f.3) == (0, 0, 0) && f.0 > last_given)
        .expect("a stop after the last command");
    let silence = ms_between(last_given, stop.0);
    assert!(
        (500.0..=580.0).contains(&silence),
        "stopped {silence:.1} ms after the last command (timeout 500 ms)"
    );
    // Held: re-sent every 50 ms until the stop, and nothing moved it after.
    let held: Vec<_> = moving.iter().filter(|f| f.0 > last_given).collect();
    assert!(held.len() >= 8, "re-sent {} times while held", held.len());
    for pair in held.windows(2) {
        let gap = ms_between(pair[0].0, pair[1].0);
        assert!((40.0..=80.0).contains(&gap), "re-sent after {gap:.1} ms");
    }
    assert!(
        frames
            .iter()
            .filter(|f| f.0 > stop.0)
            .all(|f| (f.1, f.2, f.3) == (0, 0, 0)),
        "nothing moved the chassis after the watchdog's stop"
    );
}

#[test]
fn a_stale_twist_stamped_is_ignored_and_a_fresh_one_followed() {
    let sim = Sim::v2020();
    let forward = twist(0.2, 0.0, 0.0);
    // Stamped 600 ms ago (more than the 500 ms timeout), four times; then one 100 ms old.
    let commands = vec![
        (0, stamped(forward, 600)),
        (100, stamped(forward, 600)),
        (200, stamped(forward, 700)),
        (300, stamped(forward, 10_000)),
        (600, stamped(forward, 100)),
    ];
    let mut script = Script::new(commands, 900);
    run_2020(&sim, Params::default(), &mut script);
    let frames = sim.velocities_2020();
    let fresh_given = script.given[4];
    let moving: Vec<_> = frames
        .iter()
        .filter(|f| (f.1, f.2, f.3) != (0, 0, 0))
        .collect();
    assert!(
        moving.iter().all(|f| f.0 >= fresh_given),
        "nothing moved the chassis before the fresh command"
    );
    assert_eq!(
        (moving[0].1, moving[0].2, moving[0].3),
        (0, 200, 0),
        "the fresh command was followed"
    );
}

#[test]
fn sideways_is_refused_on_a_differential_chassis_and_followed_on_mecanum() {
    let turn_left = twist(0.2, 0.1, 0.5);
    for (drive, expected) in [
        // 0.2 m/s forward, 0.5 rad/s × 220; sideways dropped.
        (DriveKind::Differential, (0, 200, 110)),
        // Left is the board's −X.
        (DriveKind::Mecanum, (-100, 200, 110)),
    ] {
        let sim = Sim::v2020();
        let mut script = Script::new(steady(turn_left, 0, 100, 100), 300);
        let params = Params {
            drive,
            ..Params::default()
        };
        run_2020(&sim, params, &mut script);
        let frames = sim.velocities_2020();
        let first = frames
            .iter()
            .find(|f| (f.1, f.2, f.3) != (0, 0, 0))
            .expect("driven");
        assert_eq!((first.1, first.2, first.3), expected, "{drive:?}");
    }
}

#[test]
fn the_v1_board_gets_mm_per_s_and_the_forced_stop_after_the_timeout() {
    let sim = Sim::v1();
    // 0.3 m/s forward and 0.1 m/s to the left, 0.25 rad/s.
    let mut script = Script::new(steady(twist(0.3, 0.1, 0.25), 0, 200, 100), 1_200);
    let driver = v1::DriverCore::open(&sim.path).expect("the pty opens");
    let mut latency = Latency::default();
    let end = node::run(
        driver,
        &settings(&sim.path, Params::default()),
        &mut script,
        &mut latency,
    );
    assert!(end.stopped.confirmed(), "{:?}", end.stopped);
    assert_eq!(
        latency.len(),
        3,
        "one latency sample per command sent as it came"
    );
    let frames = sim.velocities_v1();
    let last_given = *script.given.last().unwrap();
    // The board's vx is to the right: 0.1 m/s to the left is −100 mm/s.
    assert!(frames.iter().any(|f| (f.1, f.2, f.3) == (-100, 300, 250)));
    let stop = frames
        .iter()
        .find(|f| f.4 && f.0 > last_given)
        .expect("the forced stop after the last command");
    let silence = ms_between(last_given, stop.0);
    assert!(
        (500.0..=580.0).contains(&silence),
        "forced stop {silence:.1} ms after the last command"
    );
}

#[test]
fn a_board_gone_silent_is_stale_in_the_diagnostics_and_the_node_goes_on() {
    let sim = Sim::v2020();
    let mut script = Script::new(steady(twist(0.1, 0.0, 0.0), 0, 2_500, 100), 2_600);
    let mute = std::sync::Arc::clone(&sim.mute);
    script.at = Some((
        1_200,
        Box::new(move || mute.store(true, std::sync::atomic::Ordering::Relaxed)),
    ));
    let end = run_2020(&sim, Params::default(), &mut script);
    let diagnostics: Vec<_> = script
        .published
        .iter()
        .filter_map(|(at, out)| match out {
            Out::Diagnostics(d) => Some((*at, d.status[0].clone())),
            _ => None,
        })
        .collect();
    let link = |s: &DiagnosticStatus| {
        s.values
            .iter()
            .find(|kv| kv.key == "link")
            .map(|kv| kv.value.clone())
            .unwrap()
    };
    let muted_at = script.start + std::time::Duration::from_millis(1_200);
    assert!(
        diagnostics
            .iter()
            .any(|(at, s)| *at < muted_at && link(s) == "up" && s.level == DiagnosticStatus::OK),
        "the link was up while the board talked"
    );
    let (_, last) = diagnostics.last().unwrap();
    assert_eq!(link(last), "stale");
    assert_eq!(last.level, DiagnosticStatus::ERROR);
    let failsafe = last
        .values
        .iter()
        .find(|kv| kv.key == "failsafe stops")
        .unwrap();
    assert_ne!(
        failsafe.value, "0",
        "the driver's failsafe stopped the chassis"
    );
    // The node kept sending what /cmd_vel asked (it keeps trying), and stopped at the end.
    let frames = sim.velocities_2020();
    assert!(
        frames
            .iter()
            .any(|f| f.0 > muted_at + std::time::Duration::from_millis(500) && f.2 == 100)
    );
    assert!(
        !end.stopped.confirmed(),
        "a silent board's stop is not confirmed"
    );
}
