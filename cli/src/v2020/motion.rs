//! A 2020 board's motion: `stop` (the stop at once, then the pending angle read as the
//! evidence), `drive` (a velocity re-sent every 50 ms, then the stop) and `turn` (sent once;
//! followed until the pending angle is done; cancelled by any ending).

use super::{explain, open};
use crate::driving::{self, poll_for, progress, stop_after};
use crate::ending;
use crate::port::Board;
use chassis_protocol::Velocity;
use chassis_protocol::driver::{CoreError, Error, TurnState};
use std::time::{Duration, Instant};

/// `chassis stop`: stops the chassis at once, then reads the angle the board has pending and
/// cancels a turn it finds (left by a program that was killed, say). The read's answer is the
/// evidence that the board heard: without it, the stop is not said to have worked.
pub fn stop(port: &str) -> Result<(), String> {
    let mut driver = open(port)?;
    // Nothing cuts a stop short: it is what every ending asks for.
    driver.uart_mut().uninterrupted();
    let before = driver.uart().stops_sent();
    let first = driver.stop();
    if driver.uart().stops_sent() == before {
        let why = first.err().map_or_else(
            || "nothing was written".to_string(),
            |e| explain(&driver, e),
        );
        return Err(format!(
            "the stop could not be sent ({why}): the chassis may still be moving"
        ));
    }
    let pending = match driver.turn_remaining() {
        Ok(left) => left,
        Err(e) => {
            return Err(format!(
                "the stop was sent, but the board did not answer the read after it: not confirmed, and whether a turn is pending is not known: {}",
                explain(&driver, e)
            ));
        }
    };
    if !driver.core().turning() {
        say!("stopped (the board answered; no turn was pending)");
        return Ok(());
    }
    match driver.stop() {
        Ok(()) if driver.core().turn_state() == TurnState::Idle => {
            say!(
                "stopped; the {:.1}° turn the board had pending was cancelled",
                f64::from(pending) / 10.0
            );
            Ok(())
        }
        Ok(()) => Err(format!(
            "the stop was sent, but the {:.1}° turn the board has pending could not be cancelled: try again",
            f64::from(pending) / 10.0
        )),
        Err(e) => Err(format!(
            "the stop was sent, but the {:.1}° turn the board has pending was not cancelled: {}",
            f64::from(pending) / 10.0,
            explain(&driver, e)
        )),
    }
}

/// `chassis drive`: a velocity for a while, re-sent every 50 ms, then stop.
pub fn drive(port: &str, velocity: Velocity, seconds: f64) -> Result<(), String> {
    let seconds = driving::drive_seconds(seconds)?;
    let mut driver = open(port)?;
    ending::before_motion()?;
    let line = driving::drive_for(
        &mut driver,
        seconds,
        |driver| driver.set_velocity(velocity),
        "stopped it",
    )?;
    say!("{line}");
    Ok(())
}

/// `chassis turn DEGREES`: one turn, sent once; waits until the pending angle is done.
pub fn turn(port: &str, degrees: f64) -> Result<(), String> {
    let deci = turn_angle(degrees)?;
    let mut driver = open(port)?;
    ending::before_motion()?;
    send_turn(&mut driver, deci)?;
    let ended = follow_turn(&mut driver, deci);
    say!("{}", stop_after(&mut driver, ended)?);
    Ok(())
}

/// `degrees` in the board's steps of 0.1°, range-checked; zero is refused.
fn turn_angle(degrees: f64) -> Result<i32, String> {
    if !(-6_553.5..=6_553.5).contains(&degrees) {
        return Err(format!("{degrees}° is out of range (±6553.5)"));
    }
    let deci = (degrees * 10.0).round() as i32;
    if deci == 0 {
        return Err(format!(
            "{degrees}° rounds to 0.0° (the board turns in steps of 0.1°): nothing sent"
        ));
    }
    Ok(deci)
}

/// Sends the turn, once: refused while the board has one pending (it adds turns up); an error
/// after it may have gone out stops the chassis.
fn send_turn(driver: &mut Board, deci: i32) -> Result<(), String> {
    match driver.turn_by(deci) {
        Ok(()) => Ok(()),
        Err(Error::Core(CoreError::TurnInProgress)) => {
            let left = match driver.core().turn_state() {
                TurnState::Turning { deci_degrees } => f64::from(deci_degrees) / 10.0,
                _ => 0.0,
            };
            Err(format!(
                "the board still has {left:.1}° of an earlier turn pending (it adds turns up): not sent; wait for it to end, or `chassis stop` cancels it"
            ))
        }
        // Cut short before the turn went out (reading whether one is pending).
        Err(_) if driver.core().turn_state() == TurnState::Unknown && ending::ended().is_some() => {
            ending::before_motion()
        }
        Err(e) if driver.core().turn_state() == TurnState::Unknown => Err(format!(
            "the turn was not sent: whether the board has one pending is not known: {}",
            explain(driver, e)
        )),
        Err(e) => {
            let e = explain(driver, e);
            Err(
                stop_after(driver, Err(format!("the turn may have gone out: {e}")))
                    .err()
                    .unwrap_or(e),
            )
        }
    }
}

/// Follows a turn sent until the board has nothing of it left: `Ok` with the line to print, or
/// why it ended before (an ending, the board gone quiet, too long).
fn follow_turn(driver: &mut Board, deci: i32) -> Result<String, String> {
    let shown = f64::from(deci) / 10.0;
    // At 90°/s on the simulated board; a real one may be slower: allow twice, and 5 s.
    let limit = Duration::from_secs_f64(shown.abs() / 45.0 + 5.0);
    let start = Instant::now();
    let bar = progress(
        u64::from(deci.unsigned_abs()),
        "turning {bar:30} {msg} (Ctrl-C cancels)",
    );
    let mut left = deci;
    let mut unanswered = 0u32;
    let ended = loop {
        bar.set_position(u64::from(deci.abs_diff(left)));
        bar.set_message(format!(
            "{:.1}° of {shown:.1}°",
            f64::from(deci - left) / 10.0
        ));
        // The ending first: a read it cut short, or the stop it brought (its cancel of the
        // turn), leaves the core no longer turning, which is not the turn done.
        if ending::ended().is_some() {
            break Err(format!(
                "the {shown:.1}° turn was sent, {:.1}° of it left",
                f64::from(left) / 10.0
            ));
        }
        if !driver.core().turning() {
            break Ok(format!(
                "turned {shown:.1}° in {:.1} s",
                start.elapsed().as_secs_f64()
            ));
        }
        if driver.core().failsafe_stops() > 0 {
            break Err(format!(
                "the board went quiet during the {shown:.1}° turn (it was sent): the driver's failsafe stopped it"
            ));
        }
        if start.elapsed() > limit {
            break Err(format!(
                "the {shown:.1}° turn (sent) was not done after {:.0} s ({:.1}° left{})",
                limit.as_secs_f64(),
                f64::from(left) / 10.0,
                if unanswered > 0 {
                    format!(", {unanswered} reads of the pending angle unanswered")
                } else {
                    String::new()
                }
            ));
        }
        if let Err(e) = poll_for(driver, 100) {
            break Err(format!("the {shown:.1}° turn was sent: {e}"));
        }
        match driver.turn_remaining() {
            Ok(l) => left = l,
            // One read lost is no reason to give up: the limit above bounds the wait.
            Err(_) => unanswered += 1,
        }
    };
    bar.finish_and_clear();
    ended
}
