//! `chassis monitor`: a live view of the board's telemetry; with `--drive`, keys drive it. This
//! module holds what both firmware generations share (the terminal, the driver, the keys, the
//! failsafe's hold, the link and its stale marks: [`Monitor`] over a [`Chassis`]; the screen's
//! title and keys lines and its drive panel); each generation's screen and board are in its own
//! module ([`crate::v2020::monitor`], [`crate::v1::monitor`]).
//!
//! The screen is drawn from a view (a plain value taken from the driver each frame), so a test
//! renders it with ratatui's test backend. Keys: arrows or WASD
//! drive at the set speed, space stops, `t` turns 90° once on the 2020 board (the pending angle
//! is read until it is done; v1.0.0 has no turn by an angle: `z` / `x` rotate at a fixed rate
//! there), `+`/`-` change the speed at once, `q`, Esc or Ctrl-C quit (stopping first); SIGINT,
//! SIGTERM and SIGHUP stop the chassis too. The driver's failsafe stays active: a board that
//! goes quiet is stopped, and stays stopped until the link is back and a key is pressed again;
//! the figures of a board gone quiet are marked stale.

mod terminal;
#[cfg(test)]
pub mod testing;
#[cfg(test)]
mod tests;

use crate::ending;
use crate::stopping::{self, HostDriver, Spoken};
use chassis_protocol::driver::host::SerialError;
use chassis_protocol::driver::{Core, Error};
use ratatui::Frame;
use ratatui::crossterm::event::{Event, KeyCode, KeyEventKind, KeyModifiers};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};
use std::time::{Duration, Instant};

/// What differs between the generations under the monitor: their motion frames, their turn,
/// what their screen keeps and shows. The host driver is the monitor's ([`Monitor`]: its pump,
/// its failsafe count, its stop, written once); each method that talks to the board is lent
/// it. Velocities are `[x, y, z]`: x sideways (right positive), y forward, z the rotation, in
/// the generation's own units.
pub trait Chassis {
    /// The generation's driver core.
    type Core: Spoken;

    /// What the generation's screen shows, taken each frame.
    type View;

    /// Keeps what the screen needs of an event the driver took in (the 2020 board: the gyro
    /// Z history). Does nothing unless implemented.
    fn took(&mut self, event: &<Self::Core as Core>::Event) {
        let _ = event;
    }

    /// Sends `velocity` through `driver` (re-sent every 50 ms while it is not zero).
    fn drive(
        &self,
        driver: &mut HostDriver<Self::Core>,
        velocity: [i32; 3],
    ) -> Result<(), Error<SerialError>>;

    /// The rate the rotate keys (`z`, `x`) turn at, in the generation's z unit; or why there
    /// are none.
    fn rotate_rate(&self) -> Result<i32, &'static str>;

    /// `t`, a turn by 90° sent once through `driver`, with the link `alive` or not:
    /// `Ok(message)` when it was sent (the chassis moves: the failsafe's hold ends),
    /// `Err(message)` when nothing was.
    fn turn(&mut self, driver: &mut HostDriver<Self::Core>, alive: bool) -> Result<String, String>;

    /// What follows the poll each tick (the 2020 board reads a turn's pending angle): a
    /// message to show, if any.
    fn follow_up(&mut self, driver: &mut HostDriver<Self::Core>) -> Option<String>;

    /// The screen's contents now, from the driver's `core`, `status` being the monitor's part.
    fn view(&self, core: &Self::Core, status: Status) -> Self::View;

    /// Draws the whole screen.
    fn render(frame: &mut Frame<'_>, view: &Self::View);
}

/// The monitor's own part of the screen, the same on both generations.
#[derive(Clone, Debug, Default)]
pub struct Status {
    /// The port.
    pub port: String,
    /// Whether a frame came lately.
    pub link_alive: bool,
    /// With the link down: how long ago the last frame came, in ms (the figures are that old).
    pub stale_ms: Option<u64>,
    /// Driving from the keyboard.
    pub driving: bool,
    /// The failsafe stopped the chassis: nothing moves until a key is pressed.
    pub held: bool,
    /// The speed keys drive at.
    pub speed: i32,
    /// The velocity being sent: x, y, z.
    pub velocity: [i32; 3],
    /// The last message (errors, refusals).
    pub message: String,
}

/// What every generation's screen has around its own panels: the title bar on top (the name,
/// the port, LINK UP / NO LINK, STALE, then `tail`) and the keys line at the bottom
/// (`driving_keys` while driving). The area between them, for the generation's panels.
pub fn screen_frame(
    frame: &mut Frame<'_>,
    status: &Status,
    tail: String,
    driving_keys: &str,
) -> Rect {
    let [title, body, keys] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(10),
        Constraint::Length(3),
    ])
    .areas(frame.area());
    title_bar(frame, title, status, tail);
    frame.render_widget(
        Paragraph::new(if status.driving {
            driving_keys
        } else {
            "q quit"
        })
        .block(Block::new().borders(Borders::TOP)),
        keys,
    );
    body
}

/// The top line: the name, the port, LINK UP / NO LINK, STALE, then `tail`.
fn title_bar(frame: &mut Frame<'_>, area: Rect, status: &Status, tail: String) {
    let link = if status.link_alive {
        Span::styled(" LINK UP ", Style::new().fg(Color::Black).bg(Color::Green))
    } else {
        Span::styled(" NO LINK ", Style::new().fg(Color::White).bg(Color::Red))
    };
    frame.render_widget(
        Paragraph::new(Line::from(vec![
            Span::styled(
                " chassis monitor ",
                Style::new().add_modifier(Modifier::BOLD),
            ),
            Span::raw(format!("{}  ", status.port)),
            link,
            Span::raw(match status.stale_ms {
                Some(ms) => format!("  STALE {:.1} s", ms as f64 / 1000.0),
                None => String::new(),
            }),
            Span::raw(tail),
        ])),
        area,
    );
}

/// A stream's rate, or "stale" while the link is down (no rate shown as if live).
pub fn rate_text(rate_millihertz: u32, stale_ms: Option<u64>) -> String {
    if stale_ms.is_some() {
        "stale".to_string()
    } else {
        format!("{:.1} Hz", f64::from(rate_millihertz) / 1000.0)
    }
}

/// The drive panel: the hold, what is being sent (`driving_line`), or read only; the message.
pub fn drive_panel(frame: &mut Frame<'_>, area: Rect, status: &Status, driving_line: String) {
    let first = if status.driving && status.held {
        "stopped by the failsafe: press a key to drive again (once LINK UP)".to_string()
    } else if status.driving {
        driving_line
    } else {
        "read only (start with --drive to drive)".to_string()
    };
    frame.render_widget(
        Paragraph::new(vec![Line::from(first), Line::from(status.message.clone())])
            .wrap(Wrap { trim: true })
            .block(Block::bordered().title(" drive ")),
        area,
    );
}

/// What a key asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Key {
    /// Drive forward (up, `w`).
    Forward,
    /// Drive backward (down, `s`).
    Backward,
    /// Drive left (left, `a`).
    Left,
    /// Drive right (right, `d`).
    Right,
    /// Rotate counter-clockwise at a fixed rate (`z`; v1.0.0 only).
    RotateLeft,
    /// Rotate clockwise at a fixed rate (`x`; v1.0.0 only).
    RotateRight,
    /// Stop (space).
    Stop,
    /// Turn 90° once (`t`; the 2020 firmware only).
    Turn,
    /// Faster (`+`).
    Faster,
    /// Slower (`-`).
    Slower,
    /// Quit, stopping first (`q`, Esc, Ctrl-C).
    Quit,
}

impl Key {
    /// The key a terminal event is, if any.
    pub fn of(event: &Event) -> Option<Key> {
        let Event::Key(key) = event else {
            return None;
        };
        if key.kind != KeyEventKind::Press {
            return None;
        }
        Some(match key.code {
            // Raw mode: Ctrl-C is a key, not a signal.
            KeyCode::Char('c') if key.modifiers.contains(KeyModifiers::CONTROL) => Key::Quit,
            KeyCode::Char('q') | KeyCode::Esc => Key::Quit,
            KeyCode::Up | KeyCode::Char('w') => Key::Forward,
            KeyCode::Down | KeyCode::Char('s') => Key::Backward,
            KeyCode::Left | KeyCode::Char('a') => Key::Left,
            KeyCode::Right | KeyCode::Char('d') => Key::Right,
            KeyCode::Char('z') => Key::RotateLeft,
            KeyCode::Char('x') => Key::RotateRight,
            KeyCode::Char(' ') => Key::Stop,
            KeyCode::Char('t') => Key::Turn,
            KeyCode::Char('+' | '=') => Key::Faster,
            KeyCode::Char('-' | '_') => Key::Slower,
            _ => return None,
        })
    }
}

/// The monitor's logic, apart from the terminal and from the generation: the board's driver,
/// what the keys did, the failsafe's hold, the link. [`run_monitor`] feeds it the terminal's
/// keys; a test feeds it keys of its own.
pub struct Monitor<C: Chassis> {
    driver: HostDriver<C::Core>,
    chassis: C,
    drive: bool,
    speed: i32,
    velocity: [i32; 3],
    /// The failsafe stopped the chassis: nothing moves until the link is back and a key is
    /// pressed.
    held: bool,
    failsafe_seen: u32,
    last_frame: Option<Instant>,
    message: String,
    next_send: Instant,
}

impl<C: Chassis> Monitor<C> {
    /// A monitor of the board behind `driver`, its generation's part `chassis`; `drive`: keys
    /// drive at `speed`.
    pub fn new(driver: HostDriver<C::Core>, chassis: C, drive: bool, speed: i32) -> Self {
        Monitor {
            driver,
            chassis,
            drive,
            speed,
            velocity: [0; 3],
            held: false,
            failsafe_seen: 0,
            last_frame: None,
            message: String::new(),
            next_send: Instant::now(),
        }
    }

    /// A driver error as one line, in the CLI's words.
    fn explain(&self, e: Error<SerialError>) -> String {
        stopping::explain(&self.driver, e)
    }

    /// Takes in what the port holds, without blocking: `Ok(true)` when a frame of any kind
    /// came ([`Chassis::took`]), `Ok(false)` when nothing waits. The driver judges its
    /// failsafe here.
    fn poll(&mut self) -> Result<bool, String> {
        match self.driver.poll() {
            Ok(Some(event)) => {
                self.chassis.took(&event);
                Ok(true)
            }
            Ok(None) => Ok(false),
            Err(e) => Err(self.explain(e)),
        }
    }

    /// Whether a frame came in the last half second.
    pub fn link_alive(&self) -> bool {
        self.last_frame
            .is_some_and(|t| t.elapsed() < Duration::from_millis(500))
    }

    /// Takes in what the port holds for `ms`, judges the failsafe, re-sends the velocity, lets
    /// the generation follow up (a turn's pending angle). Never ends on a board error: it is
    /// shown.
    pub fn tick(&mut self, ms: u64) {
        let until = Instant::now() + Duration::from_millis(ms);
        while Instant::now() < until && ending::ended().is_none() {
            match self.poll() {
                Ok(true) => self.last_frame = Some(Instant::now()),
                Ok(false) => std::thread::sleep(Duration::from_millis(1)),
                Err(e) => self.message = e,
            }
        }
        let stops = self.driver.core().failsafe_stops();
        if stops != self.failsafe_seen {
            self.failsafe_seen = stops;
            if self.drive {
                // The driver stopped the chassis: never drive it again on our own.
                self.velocity = [0; 3];
                self.held = true;
                self.message = "the board went quiet: the failsafe stopped the chassis; once the link is back, press a key to drive".into();
            }
        }
        if self.drive && Instant::now() >= self.next_send {
            self.next_send = Instant::now() + Duration::from_millis(50);
            if self.velocity != [0; 3] && !self.held {
                if let Err(e) = self.chassis.drive(&mut self.driver, self.velocity) {
                    self.message = self.explain(e);
                }
            }
        }
        if let Some(message) = self.chassis.follow_up(&mut self.driver) {
            self.message = message;
        }
    }

    /// Does what `key` asks; `false` once it asks to quit.
    pub fn key(&mut self, key: Key) -> bool {
        let s = self.speed;
        let target = match key {
            Key::Quit => return false,
            _ if !self.drive => return true,
            Key::Forward => [0, s, 0],
            Key::Backward => [0, -s, 0],
            Key::Left => [-s, 0, 0],
            Key::Right => [s, 0, 0],
            Key::RotateLeft | Key::RotateRight => match self.chassis.rotate_rate() {
                Ok(rate) if key == Key::RotateLeft => [0, 0, rate],
                Ok(rate) => [0, 0, -rate],
                Err(why) => {
                    self.message = why.into();
                    return true;
                }
            },
            Key::Stop => {
                self.velocity = [0; 3];
                self.message = match self.driver.stop() {
                    Ok(()) => "stopped".into(),
                    Err(e) => self.explain(e),
                };
                return true;
            }
            Key::Faster | Key::Slower => {
                self.speed = if key == Key::Faster {
                    (s + 50).min(2_000)
                } else {
                    (s - 50).max(50)
                };
                // The new speed applies at once, in the direction being driven (a rotation
                // keeps its fixed rate).
                let [x, y, z] = self.velocity;
                self.velocity = [x.signum() * self.speed, y.signum() * self.speed, z];
                self.next_send = Instant::now();
                return true;
            }
            Key::Turn => {
                let alive = self.link_alive();
                match self.chassis.turn(&mut self.driver, alive) {
                    Ok(message) => {
                        self.held = false;
                        self.message = message;
                    }
                    Err(message) => self.message = message,
                }
                return true;
            }
        };
        if !self.link_alive() {
            self.message = "no link: not driving (the board is not heard)".into();
            return true;
        }
        self.held = false;
        self.velocity = target;
        self.next_send = Instant::now();
        self.message.clear();
        true
    }

    /// What the screen shows now.
    pub fn view(&self) -> C::View {
        let alive = self.link_alive();
        self.chassis.view(
            self.driver.core(),
            Status {
                port: self.driver.uart().name().to_string(),
                link_alive: alive,
                stale_ms: if alive {
                    None
                } else {
                    self.last_frame
                        .map(|t| u64::try_from(t.elapsed().as_millis()).unwrap_or(u64::MAX))
                },
                driving: self.drive,
                held: self.held,
                speed: self.speed,
                velocity: self.velocity,
                message: self.message.clone(),
            },
        )
    }

    /// The stop on the way out (cancelling a turn), never cut short, if this monitor drives
    /// the chassis (`None`: it only watches): `Ok` with what it did when the chassis is known
    /// to have stopped, `Err` with what is known otherwise ([`stopping::stop`]).
    pub fn stop_on_exit(&mut self) -> Option<Result<String, String>> {
        if !self.drive {
            return None;
        }
        self.velocity = [0; 3];
        let stopped = stopping::stop(&mut self.driver);
        let words = stopped.words::<C::Core>();
        Some(if stopped.confirmed() {
            Ok(words)
        } else {
            Err(words)
        })
    }
}

/// `chassis monitor [--drive]` over the board `open` opens (once the terminal is known to be
/// one), `chassis` its generation's part: draws until a quit key or an ending ([`crate::ending`]: a signal, the terminal gone),
/// then stops the chassis before giving the terminal back. The terminal is read and drawn on
/// threads of their own ([`terminal`]): nothing it does keeps this loop from the driver.
pub fn run_monitor<C: Chassis>(
    open: impl FnOnce() -> Result<HostDriver<C::Core>, String>,
    chassis: C,
    drive: bool,
    speed: i32,
) -> Result<(), String>
where
    C::View: Send + 'static,
{
    use std::io::IsTerminal;
    if !std::io::stdin().is_terminal() || !std::io::stdout().is_terminal() {
        return Err(
            "monitor draws on a terminal and reads its keys: run it in one (stdin and stdout a terminal, not a pipe or a file); `chassis record` captures without one".into(),
        );
    }
    let mut monitor = Monitor::new(open()?, chassis, drive, speed);
    crate::ending::before_motion()?;
    let screen = terminal::Screen::start(
        ratatui::try_init().map_err(|e| format!("terminal: {e}"))?,
        C::render,
    );
    let keys = terminal::Keys::start();
    let result = monitor_loop(&mut monitor, &keys, &screen);
    // Stop before giving the terminal back, whatever happened.
    let stopped = monitor.stop_on_exit();
    screen.give_back();
    if let Some(end) = ending::ended() {
        return Err(format!(
            "{}{}",
            end.words(),
            match stopped {
                None => String::new(),
                Some(Ok(words) | Err(words)) => format!(": {words}"),
            }
        ));
    }
    result?;
    match stopped {
        Some(Err(words)) => Err(words),
        _ => Ok(()),
    }
}

fn monitor_loop<C: Chassis>(
    monitor: &mut Monitor<C>,
    keys: &terminal::Keys,
    screen: &terminal::Screen<C::View>,
) -> Result<(), String>
where
    C::View: Send + 'static,
{
    let mut next_draw = Instant::now();
    while ending::ended().is_none() {
        monitor.tick(20);
        while let Some(event) = keys.next()? {
            if let Some(key) = Key::of(&event) {
                if !monitor.key(key) {
                    return Ok(());
                }
            }
        }
        if let Some(e) = screen.failed() {
            return Err(e);
        }
        if Instant::now() >= next_draw {
            next_draw = Instant::now() + Duration::from_millis(100);
            screen.show(monitor.view());
        }
    }
    Ok(())
}
