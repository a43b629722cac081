//! A v1.0.0 board's motion: `stop` (the forced stop, then the board's next telemetry frame as
//! the evidence) and `drive` (a velocity in m/s and rad/s re-sent every 50 ms, then the forced
//! stop; cut short by any ending).

use super::explain;
use crate::driving;
use crate::ending;
use crate::port;
use crate::stopping::{self, Stopped};
use chassis_protocol::driver::v1::DriverCore;
use chassis_protocol::v1::BodyVelocity;
use std::time::{Duration, Instant};

/// How long `chassis stop` waits for the board's telemetry after the forced stop (it sends a
/// frame every 39-47 ms).
const STOP_EVIDENCE: Duration = Duration::from_millis(300);

/// `chassis stop` on v1.0.0: the forced stop, then the board's next telemetry frame as the
/// evidence that it is there (its velocity said); without one, the stop is not said to have
/// worked.
pub fn stop(path: &str) -> Result<(), String> {
    let mut driver = port::open_v1(path, None)?;
    let stopped = stopping::stop(&mut driver);
    if let Stopped::NotSent(_) = stopped {
        return Err(stopped.words::<DriverCore>());
    }
    let sent_at = driver.uart().now_ms();
    let until = Instant::now() + STOP_EVIDENCE;
    while Instant::now() < until {
        if let Err(e) = driver.poll() {
            return Err(format!(
                "the forced stop was sent, but not confirmed: {}",
                explain(&driver, e)
            ));
        }
        if let Some(t) = driver.core().telemetry().filter(|t| t.at_ms > sent_at) {
            let [vx, vy, wz] = t.value.velocity;
            if [vx, vy, wz] == [0; 3] {
                say!(
                    "stopped (the forced stop was sent; the board's next frame reports it standing still)"
                );
            } else {
                say!(
                    "the forced stop was sent; the board's next frame still reports vx {} m/s, vy {} m/s, wz {} rad/s (slowing down?)",
                    f64::from(vx) / 1000.0,
                    f64::from(vy) / 1000.0,
                    f64::from(wz) / 1000.0
                );
            }
            return Ok(());
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    Err(format!(
        "the forced stop was sent but not confirmed: {}",
        stopping::unheard(&driver).unwrap_or_else(|| format!(
            "no frame came from the board within {} ms after it",
            STOP_EVIDENCE.as_millis()
        ))
    ))
}

/// A speed in m/s (or rad/s) as the board's thousandths, range-checked.
pub fn milli(value: f64, name: &str, unit: &str) -> Result<i16, String> {
    let m = (value * 1000.0).round();
    if !m.is_finite() || !(f64::from(i16::MIN)..=f64::from(i16::MAX)).contains(&m) {
        // A huge value in exponent form, not 300 digits.
        let shown = if value.abs() < 1e6 {
            format!("{value}")
        } else {
            format!("{value:e}")
        };
        return Err(format!(
            "--{name}: {shown} {unit} is out of range (±32.767, the frame's 16 bits in thousandths)"
        ));
    }
    Ok(m as i16)
}

/// `chassis drive --vx --vy --wz --for S` on v1.0.0: the velocity re-sent every 50 ms, then
/// the forced stop; on a signal, the forced stop at once.
pub fn drive(path: &str, velocity: BodyVelocity, seconds: f64) -> Result<(), String> {
    let seconds = driving::drive_seconds(seconds)?;
    let mut driver = port::open_v1(path, None)?;
    ending::before_motion()?;
    let line = driving::drive_for(
        &mut driver,
        seconds,
        |driver| driver.set_velocity(velocity),
        "sent the forced stop",
    )?;
    say!("{line}");
    Ok(())
}
