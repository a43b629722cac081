//! What every generation's screen shows alike, each generation's screen drawn.

use super::Status;
use super::testing::{assert_screen, screen_text};
use crate::{v1, v2020};

/// Driving on `/dev/ttyUSB0`, the board gone quiet 3.2 s ago and the failsafe's hold on.
fn gone_quiet() -> Status {
    Status {
        port: "/dev/ttyUSB0".into(),
        stale_ms: Some(3_200),
        driving: true,
        held: true,
        ..Status::default()
    }
}

/// Watching `/dev/ttyACM0`, nothing heard yet.
fn silent() -> Status {
    Status {
        port: "/dev/ttyACM0".into(),
        ..Status::default()
    }
}

#[test]
fn a_silent_board_shows_no_link_and_waits() {
    for (text, waiting) in [
        (
            screen_text(
                v2020::monitor::render,
                &v2020::monitor::View {
                    status: silent(),
                    ..Default::default()
                },
            ),
            "waiting for the IMU",
        ),
        (
            screen_text(
                v1::monitor::render,
                &v1::monitor::View {
                    status: silent(),
                    ..Default::default()
                },
            ),
            "waiting for the telemetry",
        ),
    ] {
        assert_screen(
            &text,
            &[
                "NO LINK",
                waiting,
                "read only (start with --drive to drive)",
                "q quit",
            ],
            &[],
        );
    }
}

/// The stale figures and the hold of a board gone quiet: on every screen NO LINK, how long
/// ago, the hold, never a rate as if live (`live_rate`); and what the screen marks stale.
#[test]
fn a_board_gone_quiet_shows_stale_figures_and_the_hold() {
    let v2020 = screen_text(
        v2020::monitor::render,
        &v2020::monitor::View {
            status: gone_quiet(),
            streams: [v2020::monitor::StreamView {
                rate_millihertz: 100_000,
                frames: 50,
                missed: 0,
            }; 3],
            failsafe_stops: 1,
            ..Default::default()
        },
    );
    let v1 = screen_text(
        v1::monitor::render,
        &v1::monitor::View {
            status: gone_quiet(),
            telemetry: Some(chassis_protocol::v1::Telemetry {
                battery_mv: 12_000,
                quaternion: [1000, 0, 0, 0],
                ..Default::default()
            }),
            rate_millihertz: 22_000,
            failsafe_stops: 1,
            ..Default::default()
        },
    );
    for (text, live_rate) in [(&v2020, "100.0 Hz"), (&v1, "22.0 Hz")] {
        assert_screen(
            text,
            &[
                "NO LINK",
                "STALE 3.2 s",
                "stopped by the failsafe: press a key",
            ],
            &[live_rate],
        );
    }
    assert_screen(&v2020, &["stale", "failsafe stops 1"], &[]);
    assert_screen(
        &v1,
        &[
            "measured (stale)",
            "telemetry       stale",
            "failsafe stops  1",
            "12.00 V",
        ],
        &[],
    );
}
