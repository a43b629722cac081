//! What the generations' screen tests share: the text a screen draws, the monitor's part of a
//! screen driving, and the check of what a screen shows.

use crate::monitor::Status;
use ratatui::Frame;

/// The text a screen `render` draws from `view` on a 100 × 24 terminal (ratatui's test
/// backend), a line per row.
pub fn screen_text<V>(render: fn(&mut Frame<'_>, &V), view: &V) -> String {
    let mut terminal =
        ratatui::Terminal::new(ratatui::backend::TestBackend::new(100, 24)).expect("a terminal");
    let _ = terminal.draw(|f| render(f, view));
    let buffer = terminal.backend().buffer().clone();
    let mut text = String::new();
    for y in 0..buffer.area.height {
        for x in 0..buffer.area.width {
            text.push_str(buffer[(x, y)].symbol());
        }
        text.push('\n');
    }
    text
}

/// Driving forward at speed 300 on `/dev/ttyUSB0`, the link up; `message` the last one.
pub fn driving(message: &str) -> Status {
    Status {
        port: "/dev/ttyUSB0".into(),
        link_alive: true,
        stale_ms: None,
        driving: true,
        held: false,
        speed: 300,
        velocity: [0, 300, 0],
        message: message.into(),
    }
}

/// `text` shows every one of `shown` and none of `hidden`.
pub fn assert_screen(text: &str, shown: &[&str], hidden: &[&str]) {
    for needle in shown {
        assert!(text.contains(needle), "{needle:?} on the screen:\n{text}");
    }
    for needle in hidden {
        assert!(
            !text.contains(needle),
            "no {needle:?} on the screen:\n{text}"
        );
    }
}
