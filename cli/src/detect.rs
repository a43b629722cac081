//! `chassis detect`: which firmware the board runs, in one line.

use crate::connect::{listen, undecided};

/// `chassis detect`: one line naming the firmware and what was heard (exit 0), or why none
/// ([`crate::connect::SILENT`], [`crate::connect::NEITHER`]).
pub fn detect_command(path: &str) -> Result<(), (String, u8)> {
    let found = listen(path).map_err(|e| (e, 1))?;
    let Some(firmware) = found.firmware else {
        return Err(undecided(path, &found));
    };
    say!(
        "firmware {} ({}) on {path}: heard {}{}",
        firmware.name(),
        firmware.framing(),
        crate::generation::of(firmware).heard(&found.heard, found.elapsed_ms as f64 / 1000.0),
        if found.probed {
            " (after a register read of each firmware: the board was quiet)"
        } else {
            " (listening only: nothing was sent)"
        }
    );
    Ok(())
}
