//! `chassis record`: what the board sends, time-stamped, into a file `chassis decode` reads
//! back exactly (a Saleae Logic 2 export: quiet lines are gaps in the time stamps, 40 ms as
//! the host driver judges them: `--quiet-ms 40`). Sends
//! nothing. Ends after `--for`, or on Ctrl-C (SIGINT, SIGTERM, SIGHUP) or its terminal or
//! input gone ([`crate::ending`]), with the file complete. The frames of both firmware
//! generations are counted (it sends nothing, so it never asks which).

use crate::ending;
use crate::port::{self, Recorder};
use crate::stopping::explain;
use chassis_protocol::driver::Event;
use std::cell::Cell;
use std::rc::Rc;
use std::time::{Duration, Instant};

/// `chassis record --out FILE [--for SECONDS]`.
pub fn record(path: &str, out: &str, seconds: Option<f64>) -> Result<(), String> {
    if let Some(s) = seconds {
        if !(s > 0.0 && s <= 86_400.0) {
            return Err(format!(
                "--for: {s} s is out of range (more than 0, up to 86400)"
            ));
        }
    }
    // The file first: a path that cannot be written fails before the port is touched.
    let recorder = Recorder::create(out)?;
    let mut driver = port::open(path, Some(recorder))?;
    // The 2020 frames are the driver's; the v1.0.0 ones are counted beside it.
    let v1_frames = Rc::new(Cell::new(0u64));
    let count = Rc::clone(&v1_frames);
    let mut v1 = chassis_protocol::v1::DownlinkParser::new();
    driver.uart_mut().listen(move |bytes| {
        for &byte in bytes {
            if v1.push(byte).is_some() {
                count.set(count.get().saturating_add(1));
            }
        }
    });
    let start = Instant::now();
    let (frames, error) = take_in(&mut driver, seconds, &v1_frames);
    let counts = driver
        .uart_mut()
        .finish_recording()
        .unwrap_or(Ok(port::Counts::default()))?;
    let frames = frames + v1_frames.get();
    let summary = format!(
        "recorded {} bytes from the board ({frames} frames) in {:.1} s to {out}; read it back: chassis decode {out} --input saleae-csv --quiet-ms 40",
        counts.board_bytes,
        start.elapsed().as_secs_f64()
    );
    match error {
        Some(e) => Err(format!("{e} (what came before is in {out}: {summary})")),
        None => {
            if counts.board_bytes == 0 {
                tell!(
                    "chassis record: nothing came from the board (is it powered, TX wired to RX, at 115200 bps?)"
                );
            }
            say!("{summary}");
            Ok(())
        }
    }
}

/// Takes in what the board sends until `seconds` have passed (or for ever) or the command must
/// end, a spinner on stderr: the 2020 frames the driver took, and the error that ended it, if
/// one did.
fn take_in(
    driver: &mut port::Board,
    seconds: Option<f64>,
    v1_frames: &Cell<u64>,
) -> (u64, Option<String>) {
    let bar = indicatif::ProgressBar::with_draw_target(
        None,
        indicatif::ProgressDrawTarget::stderr_with_hz(5),
    );
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{spinner} recording {msg} (Ctrl-C ends it)")
    {
        bar.set_style(style);
    }
    let start = Instant::now();
    let end = seconds.map(|s| start + Duration::from_secs_f64(s));
    let mut frames = 0u64;
    let mut error = None;
    while ending::ended().is_none() && end.is_none_or(|end| Instant::now() < end) {
        match driver.poll() {
            Ok(Some(Event::Telemetry(_) | Event::Reply(_) | Event::StrayReply(_))) => frames += 1,
            // The poll waited up to a millisecond for a byte.
            Ok(None) => {}
            // A wait the ending cut short: the recording ends as it would on Ctrl-C.
            Err(_) if ending::ended().is_some() => break,
            Err(e) => {
                error = Some(explain(driver, e));
                break;
            }
        }
        let bytes = driver
            .uart()
            .recorder()
            .map_or(0, |r| r.counts().board_bytes);
        bar.set_message(format!(
            "{} frames, {bytes} bytes, {:.0} s",
            frames + v1_frames.get(),
            start.elapsed().as_secs_f64()
        ));
    }
    bar.finish_and_clear();
    (frames, error)
}
