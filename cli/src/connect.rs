//! Which firmware the board runs, before a command talks to it: `--firmware` when given, else
//! [`chassis_protocol::detect`] on the port (it listens first, and only on a quiet line sends
//! its two harmless probes); what `chassis detect` says when nothing decided.

use crate::port;
use chassis_protocol::detect::{self, Detection, Firmware};
use chassis_protocol::driver::Config;
use chassis_protocol::driver::host::MonotonicClock;

/// The generation a silent line is taken as when the command's arguments do not say, and the
/// one `chassis sim` serves unless told.
pub const DEFAULT_FIRMWARE: Firmware = Firmware::V2020;

/// Whether `name` names a setting of the v1.0.0 firmware only (a readback or one of its
/// fields, and no 2020 register).
pub fn only_v1_name(name: &str) -> bool {
    let v1 = chassis_protocol::v1::Readback::from_name(name).is_some()
        || chassis_protocol::v1::FIELDS.iter().any(|(n, _)| *n == name);
    v1 && chassis_protocol::Register::from_name(name).is_none()
}

/// `--firmware`: exactly `2020`, `v1.0.0` or `v1`.
pub fn firmware_arg(name: &str) -> Result<Firmware, String> {
    Firmware::from_name(name).ok_or_else(|| "the board runs firmware 2020 or v1.0.0 (or v1)".into())
}

/// Exit status of `chassis detect` when nothing came from the board.
pub const SILENT: u8 = 3;
/// Exit status of `chassis detect` when bytes came, but frames of neither generation.
pub const NEITHER: u8 = 4;

/// Listens on `path` (and probes it if it is quiet).
pub fn listen(path: &str) -> Result<Detection, String> {
    let mut serial = port::open_serial(path)?;
    let mut clock = MonotonicClock::new();
    detect::detect(&mut serial, &mut clock, &Config::HOST)
        .map_err(|e| format!("serial port {path}: {}", e.0))
}

/// The line `chassis detect` prints when nothing decided, and its exit status.
pub fn undecided(path: &str, found: &Detection) -> (String, u8) {
    let seconds = found.elapsed_ms as f64 / 1000.0;
    if found.heard.bytes == 0 {
        (
            format!(
                "nothing came from the board on {path} in {seconds:.1} s, not even an answer to a register read of either firmware (is it powered, TX wired to RX and RX to TX, at 115200 bps?)"
            ),
            SILENT,
        )
    } else {
        (
            format!(
                "{} bytes came from {path} in {seconds:.1} s, but no frame of either firmware (2020: FF FA/FB/FC; v1.0.0: 7B … BCC 7D): another device, or a baud rate other than 115200?",
                found.heard.bytes
            ),
            NEITHER,
        )
    }
}

/// The firmware `chassis check` talks to: `given`, or found on `path` (a silent line: the
/// [`DEFAULT_FIRMWARE`]); bytes of neither generation fail its link check (exit status 10, as
/// the firmware's bring-up does), with nothing sent.
pub fn generation_for_check(path: &str, given: Option<Firmware>) -> Result<Firmware, (String, u8)> {
    if let Some(firmware) = given {
        return Ok(firmware);
    }
    let found = listen(path).map_err(|e| (e, 1))?;
    match found.firmware {
        Some(firmware) => Ok(firmware),
        None if found.heard.bytes == 0 => Ok(DEFAULT_FIRMWARE),
        None => Err((
            format!(
                "FAIL: link: {}; nothing was sent (--firmware 2020|v1.0.0 skips this check)",
                undecided(path, &found).0
            ),
            LINK_CHECK_FAILED,
        )),
    }
}

/// The exit status of `chassis check` when its link check fails.
const LINK_CHECK_FAILED: u8 = 10;

/// The firmware a command talks to: `given`, or found on `path` (it listens first, and only on
/// a quiet line sends its two harmless probes). A line that stays silent is taken as `silent`,
/// the generation the command's own arguments belong to, so that its error says that nothing
/// answered; bytes of neither generation are an error.
pub fn generation_or(
    path: &str,
    given: Option<Firmware>,
    silent: Firmware,
) -> Result<Firmware, String> {
    if let Some(firmware) = given {
        return Ok(firmware);
    }
    let found = listen(path)?;
    match found.firmware {
        Some(firmware) => Ok(firmware),
        None if found.heard.bytes == 0 => Ok(silent),
        None => Err(format!(
            "{}; --firmware 2020|v1.0.0 skips this check",
            undecided(path, &found).0
        )),
    }
}
