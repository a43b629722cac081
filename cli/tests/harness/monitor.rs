//! What the monitor tests of both generations share: the failsafe's hold, seen from the board
//! and on the screen.

use super::{Terminal, TestBoard};
use chassis_protocol::sim::Simulated;
use std::fmt::Debug;
use std::time::Duration;

/// A driving monitor in `term` on `board`, a key's velocity being re-sent, when the board goes
/// quiet and comes back: the failsafe stops the chassis and nothing drives it while the board
/// is quiet, the screen says so (NO LINK, STALE, and every one of `stale`); once the link is
/// back, the hold stays and nothing moves. `driven` gives what the board was sent after the
/// last stop that moves the chassis.
pub fn assert_failsafe_holds<B, T>(
    board: &TestBoard<B>,
    term: &Terminal,
    driven: impl Fn(&[u8]) -> Vec<T>,
    stale: &[&str],
) where
    B: Simulated + Send + 'static,
    T: Debug,
{
    board.go_silent(true);
    std::thread::sleep(Duration::from_secs(2));
    let quiet = driven(&board.heard());
    assert!(
        quiet.is_empty(),
        "the failsafe stopped it and nothing drove it again while the board was quiet: {quiet:?}"
    );
    term.wait_for_text("stopped by the failsafe");
    term.wait_for_text("NO LINK");
    term.wait_for_text("STALE");
    for text in stale {
        term.wait_for_text(text);
    }

    // The link comes back: still nothing moves.
    board.go_silent(false);
    term.wait_for_text("LINK UP");
    std::thread::sleep(Duration::from_secs(1));
    let screen = term.text();
    assert!(screen.contains("stopped by the failsafe"), "{screen}");
    assert!(!screen.contains("STALE"), "live again: {screen}");
    let back = driven(&board.heard());
    assert!(
        back.is_empty(),
        "the link back alone does not re-drive it: {back:?}"
    );
}
