//! `chassis monitor`: a live view of the board's telemetry; with `--drive`, keys drive it.
//!
//! The screen is drawn from a [`View`] (a plain value taken from the driver each frame), so a
//! test renders it with ratatui's test backend. Keys: arrows or WASD drive at the set speed,
//! space stops, `t` turns 90° once (the pending angle is read until it is done), `+`/`-` change
//! the speed at once, `q`, Esc or Ctrl-C quit (stopping first); SIGINT, SIGTERM and SIGHUP
//! stop the chassis too. The driver's failsafe stays active: a board that goes quiet is
//! stopped, and stays stopped until the link is back and a key is pressed again; the figures
//! of a board gone quiet are marked stale.

use crate::device::{explain, open};
use crate::port::Board;
use crate::signals;
use chassis_protocol::driver::{CoreError, Error, Event as DriverEvent};
use chassis_protocol::{Battery, Downlink, Encoders, Imu, Lock, Stream, Velocity};
use ratatui::Frame;
use ratatui::crossterm::event::{self, Event, KeyCode, KeyEventKind, KeyModifiers};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Gauge, Paragraph, Row, Sparkline, Table, Wrap};
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// Gyro Z readings kept for the sparkline.
const HISTORY: usize = 120;

/// What one stream looks like.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamView {
    /// Frames per second, in thousandths.
    pub rate_millihertz: u32,
    /// Frames received.
    pub frames: u32,
    /// Frames missed by the count bytes.
    pub missed: u32,
}

/// Everything the screen shows.
#[derive(Clone, Debug, Default)]
pub struct View {
    /// The port.
    pub port: String,
    /// Whether a frame came lately.
    pub link_alive: bool,
    /// With the link down: how long ago the last frame came, in ms (the figures are that old).
    pub stale_ms: Option<u64>,
    /// The parser's certainty of where frames start.
    pub lock: Option<Lock>,
    /// Latest IMU frame.
    pub imu: Option<Imu>,
    /// Latest encoders frame.
    pub encoders: Option<Encoders>,
    /// Latest battery frame.
    pub battery: Option<Battery>,
    /// IMU, encoders, battery.
    pub streams: [StreamView; 3],
    /// Bytes the parser threw away.
    pub discarded: u32,
    /// Times the failsafe stopped the chassis.
    pub failsafe_stops: u32,
    /// |Gyro Z| history (how fast the chassis turns).
    pub gyro_z: Vec<u64>,
    /// Driving from the keyboard.
    pub driving: bool,
    /// The failsafe stopped the chassis: nothing moves until a key is pressed.
    pub held: bool,
    /// The speed keys drive at.
    pub speed: i32,
    /// The velocity being sent: x, y, z.
    pub velocity: [i32; 3],
    /// A turn is outstanding.
    pub turning: bool,
    /// The last message (errors, refusals).
    pub message: String,
}

/// Draws the whole screen.
pub fn render(frame: &mut Frame<'_>, view: &View) {
    let [title, body, keys] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(10),
        Constraint::Length(3),
    ])
    .areas(frame.area());
    let link = if view.link_alive {
        Span::styled(" LINK UP ", Style::new().fg(Color::Black).bg(Color::Green))
    } else {
        Span::styled(" NO LINK ", Style::new().fg(Color::White).bg(Color::Red))
    };
    let lock = match view.lock {
        Some(Lock::Locked) => "locked",
        Some(Lock::Tentative) => "tentative",
        Some(Lock::Hunting) | None => "hunting",
    };
    frame.render_widget(
        Paragraph::new(Line::from(vec![
            Span::styled(
                " chassis monitor ",
                Style::new().add_modifier(Modifier::BOLD),
            ),
            Span::raw(format!("{}  ", view.port)),
            link,
            Span::raw(match view.stale_ms {
                Some(ms) => format!("  STALE {:.1} s", ms as f64 / 1000.0),
                None => String::new(),
            }),
            Span::raw(format!(
                "  failsafe stops {}  parser {lock}, {} bytes discarded",
                view.failsafe_stops, view.discarded
            )),
        ])),
        title,
    );
    let [left, right] =
        Layout::horizontal([Constraint::Percentage(55), Constraint::Percentage(45)]).areas(body);
    let [imu_area, gyro_area, enc_area] = Layout::vertical([
        Constraint::Length(4),
        Constraint::Min(3),
        Constraint::Length(3),
    ])
    .areas(left);
    render_imu(frame, imu_area, view);
    // The newest readings that fit, scaled to what was seen (never finer than the sensor's
    // noise at rest).
    let fit = usize::from(gyro_area.width.saturating_sub(2));
    let recent = view
        .gyro_z
        .get(view.gyro_z.len().saturating_sub(fit)..)
        .unwrap_or(&[]);
    let peak = recent.iter().copied().max().unwrap_or(0).max(50);
    frame.render_widget(
        Sparkline::default()
            .block(Block::bordered().title(format!(
                " |gyro Z|, last {:.1} s (peak {peak}) ",
                recent.len() as f64 / 100.0
            )))
            .data(recent.iter().copied())
            .max(peak)
            .style(Style::new().fg(Color::Cyan)),
        gyro_area,
    );
    let enc = view.encoders.map_or_else(
        || "—".to_string(),
        |e| {
            format!(
                "M1 {:>6}  M2 {:>6}  M3 {:>6}  M4 {:>6}   count {}",
                e.ticks[0], e.ticks[1], e.ticks[2], e.ticks[3], e.seq
            )
        },
    );
    frame.render_widget(
        Paragraph::new(enc).block(Block::bordered().title(" encoders ")),
        enc_area,
    );

    let [battery_area, streams_area, drive_area] = Layout::vertical([
        Constraint::Length(3),
        Constraint::Length(6),
        Constraint::Min(4),
    ])
    .areas(right);
    let (ratio, label) = match view.battery {
        Some(b) => (
            f64::from(b.percent.min(100)) / 100.0,
            format!(
                "{}.{:02} V  {} %",
                b.centivolts / 100,
                b.centivolts % 100,
                b.percent
            ),
        ),
        None => (0.0, "—".to_string()),
    };
    frame.render_widget(
        Gauge::default()
            .block(Block::bordered().title(" battery "))
            .gauge_style(Style::new().fg(if ratio > 0.2 {
                Color::Green
            } else {
                Color::Red
            }))
            .ratio(ratio)
            .label(label),
        battery_area,
    );
    let rows = ["IMU", "encoders", "battery"]
        .iter()
        .zip(view.streams.iter())
        .map(|(name, s)| {
            Row::new(vec![
                (*name).to_string(),
                if view.stale_ms.is_some() {
                    "stale".to_string()
                } else {
                    format!("{:.1} Hz", f64::from(s.rate_millihertz) / 1000.0)
                },
                s.frames.to_string(),
                s.missed.to_string(),
            ])
        });
    frame.render_widget(
        Table::new(
            rows,
            [
                Constraint::Length(9),
                Constraint::Length(9),
                Constraint::Length(8),
                Constraint::Length(7),
            ],
        )
        .header(
            Row::new(vec!["stream", "rate", "frames", "missed"])
                .style(Style::new().add_modifier(Modifier::BOLD)),
        )
        .block(Block::bordered().title(" streams ")),
        streams_area,
    );
    let drive = if view.driving && view.held {
        vec![
            Line::from("stopped by the failsafe: press a key to drive again (once LINK UP)"),
            Line::from(view.message.clone()),
        ]
    } else if view.driving {
        vec![
            Line::from(format!(
                "driving at {}: x {} y {} z {}{}",
                view.speed,
                view.velocity[0],
                view.velocity[1],
                view.velocity[2],
                if view.turning { "  (turning)" } else { "" }
            )),
            Line::from(view.message.clone()),
        ]
    } else {
        vec![
            Line::from("read only (start with --drive to drive)"),
            Line::from(view.message.clone()),
        ]
    };
    frame.render_widget(
        Paragraph::new(drive)
            .wrap(Wrap { trim: true })
            .block(Block::bordered().title(" drive ")),
        drive_area,
    );
    let help = if view.driving {
        "arrows/WASD drive  space stop  t turn 90° once  +/- speed  q or Ctrl-C quit"
    } else {
        "q quit"
    };
    frame.render_widget(
        Paragraph::new(help).block(Block::new().borders(Borders::TOP)),
        keys,
    );
}

fn render_imu(frame: &mut Frame<'_>, area: Rect, view: &View) {
    let lines = match view.imu {
        Some(imu) => vec![
            Line::from(format!(
                "accel  x {:>6}  y {:>6}  z {:>6}",
                imu.accel[0], imu.accel[1], imu.accel[2]
            )),
            Line::from(format!(
                "gyro   x {:>6}  y {:>6}  z {:>6}   count {}",
                imu.gyro[0], imu.gyro[1], imu.gyro[2], imu.seq
            )),
        ],
        None => vec![Line::from("waiting for the IMU…")],
    };
    frame.render_widget(
        Paragraph::new(lines).block(Block::bordered().title(" IMU ")),
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
    /// Stop (space).
    Stop,
    /// Turn 90° once (`t`).
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
            KeyCode::Char(' ') => Key::Stop,
            KeyCode::Char('t') => Key::Turn,
            KeyCode::Char('+' | '=') => Key::Faster,
            KeyCode::Char('-' | '_') => Key::Slower,
            _ => return None,
        })
    }
}

/// How often the pending angle is read while a turn is outstanding.
const TURN_READ: Duration = Duration::from_millis(250);

/// The monitor's logic, apart from the terminal: what the keys did, the failsafe's hold, the
/// link. [`run`] feeds it the terminal's keys; a test feeds it keys of its own.
pub struct Monitor {
    driver: Board,
    drive: bool,
    speed: i32,
    velocity: Velocity,
    /// The failsafe stopped the chassis: nothing moves until the link is back and a key is
    /// pressed.
    held: bool,
    failsafe_seen: u32,
    last_frame: Option<Instant>,
    history: VecDeque<i16>,
    message: String,
    next_send: Instant,
    next_turn_read: Instant,
}

impl Monitor {
    /// A monitor over `driver`; `drive`: keys drive at `speed`.
    pub fn new(driver: Board, drive: bool, speed: i32) -> Self {
        Monitor {
            driver,
            drive,
            speed,
            velocity: Velocity::new(0, 0, 0),
            held: false,
            failsafe_seen: 0,
            last_frame: None,
            history: VecDeque::with_capacity(HISTORY),
            message: String::new(),
            next_send: Instant::now(),
            next_turn_read: Instant::now(),
        }
    }

    /// Whether a frame came in the last half second.
    pub fn link_alive(&self) -> bool {
        self.last_frame
            .is_some_and(|t| t.elapsed() < Duration::from_millis(500))
    }

    /// Takes in what the port holds for `ms`, judges the failsafe, re-sends the velocity, reads
    /// the pending angle of a turn. Never ends on a board error: it is shown.
    pub fn tick(&mut self, ms: u64) {
        let until = Instant::now() + Duration::from_millis(ms);
        while Instant::now() < until {
            match self.driver.poll() {
                Ok(Some(DriverEvent::Telemetry(Downlink::Imu(imu)))) => {
                    self.last_frame = Some(Instant::now());
                    if self.history.len() == HISTORY {
                        self.history.pop_front();
                    }
                    self.history.push_back(imu.gyro[2]);
                }
                Ok(Some(_)) => self.last_frame = Some(Instant::now()),
                Ok(None) => std::thread::sleep(Duration::from_millis(1)),
                Err(e) => self.message = explain(&self.driver, e),
            }
        }
        let stops = self.driver.core().failsafe_stops();
        if stops != self.failsafe_seen {
            self.failsafe_seen = stops;
            if self.drive {
                // The driver stopped the chassis: never drive it again on our own.
                self.velocity = Velocity::new(0, 0, 0);
                self.held = true;
                self.message = "the board went quiet: the failsafe stopped the chassis; once the link is back, press a key to drive".into();
            }
        }
        if self.drive && Instant::now() >= self.next_send {
            self.next_send = Instant::now() + Duration::from_millis(50);
            if self.velocity != Velocity::new(0, 0, 0) && !self.held {
                if let Err(e) = self.driver.set_velocity(self.velocity) {
                    self.message = explain(&self.driver, e);
                }
            }
        }
        if self.driver.core().turning() && Instant::now() >= self.next_turn_read {
            self.next_turn_read = Instant::now() + TURN_READ;
            // A read lost is tried again at the next one.
            if self.driver.turn_remaining().is_ok() && !self.driver.core().turning() {
                self.message = "turn done".into();
            }
        }
    }

    /// Does what `key` asks; `false` once it asks to quit.
    pub fn key(&mut self, key: Key) -> bool {
        let s = self.speed;
        let target = match key {
            Key::Quit => return false,
            _ if !self.drive => return true,
            Key::Forward => Velocity::new(0, s, 0),
            Key::Backward => Velocity::new(0, -s, 0),
            Key::Left => Velocity::new(-s, 0, 0),
            Key::Right => Velocity::new(s, 0, 0),
            Key::Stop => {
                self.velocity = Velocity::new(0, 0, 0);
                self.message = match self.driver.stop() {
                    Ok(()) => "stopped".into(),
                    Err(e) => explain(&self.driver, e),
                };
                return true;
            }
            Key::Faster | Key::Slower => {
                self.speed = if key == Key::Faster {
                    (s + 50).min(2_000)
                } else {
                    (s - 50).max(50)
                };
                // The new speed applies at once, in the direction being driven.
                let v = self.velocity;
                self.velocity = Velocity::new(
                    v.x.signum() * self.speed,
                    v.y.signum() * self.speed,
                    v.z.signum() * self.speed,
                );
                self.next_send = Instant::now();
                return true;
            }
            Key::Turn => {
                if !self.link_alive() {
                    self.message = "no link: not turning".into();
                    return true;
                }
                self.message = match self.driver.turn_by(900) {
                    Ok(()) => {
                        self.held = false;
                        self.next_turn_read = Instant::now() + TURN_READ;
                        "turning 90° (sent once)".into()
                    }
                    Err(Error::Core(CoreError::TurnInProgress)) => {
                        "a turn is still going: not sent again".into()
                    }
                    Err(e) => explain(&self.driver, e),
                };
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
    pub fn view(&self) -> View {
        let core = self.driver.core();
        let alive = self.link_alive();
        let mut streams = [StreamView::default(); 3];
        for s in Stream::ALL {
            let info = core.stream(s);
            if let Some(v) = streams.get_mut(s.index()) {
                *v = StreamView {
                    rate_millihertz: info.rate_millihertz,
                    frames: info.frames,
                    missed: info.missed,
                };
            }
        }
        View {
            port: self.driver.uart().name().to_string(),
            link_alive: alive,
            stale_ms: if alive {
                None
            } else {
                self.last_frame
                    .map(|t| u64::try_from(t.elapsed().as_millis()).unwrap_or(u64::MAX))
            },
            lock: Some(core.lock()),
            imu: core.imu().map(|s| s.value),
            encoders: core.encoders().map(|s| s.value),
            battery: core.battery().map(|s| s.value),
            streams,
            discarded: core.parser_stats().discarded,
            failsafe_stops: core.failsafe_stops(),
            gyro_z: self
                .history
                .iter()
                .map(|g| u64::from(g.unsigned_abs()))
                .collect(),
            driving: self.drive,
            held: self.held,
            speed: self.speed,
            velocity: [self.velocity.x, self.velocity.y, self.velocity.z],
            turning: core.turning(),
            message: self.message.clone(),
        }
    }

    /// Stops the chassis (cancelling a turn) if this monitor drives it.
    pub fn stop(&mut self) -> Result<(), String> {
        if !self.drive {
            return Ok(());
        }
        self.velocity = Velocity::new(0, 0, 0);
        self.driver.stop().map_err(|e| explain(&self.driver, e))
    }
}

/// `chassis monitor [--drive]`.
pub fn run(port: &str, drive: bool, speed: i32) -> Result<(), String> {
    use std::io::IsTerminal;
    if !std::io::stdin().is_terminal() || !std::io::stdout().is_terminal() {
        return Err(
            "monitor draws on a terminal and reads its keys: run it in one (stdin and stdout a terminal, not a pipe or a file); `chassis record` captures without one".into(),
        );
    }
    signals::install()?;
    let mut monitor = Monitor::new(open(port)?, drive, speed);
    let mut terminal = ratatui::try_init().map_err(|e| format!("terminal: {e}"))?;
    let result = monitor_loop(&mut terminal, &mut monitor);
    // Stop before giving the terminal back, whatever happened.
    let stopped = monitor.stop();
    ratatui::restore();
    if let Some(signal) = signals::caught() {
        return Err(format!(
            "interrupted by {}{}",
            signals::name(signal),
            match (drive, stopped) {
                (false, _) => String::new(),
                (true, Ok(())) => ": the chassis was stopped".into(),
                (true, Err(e)) => format!(": the stop was sent but not confirmed: {e}"),
            }
        ));
    }
    result?;
    stopped
}

fn monitor_loop(
    terminal: &mut ratatui::DefaultTerminal,
    monitor: &mut Monitor,
) -> Result<(), String> {
    let mut next_draw = Instant::now();
    while signals::caught().is_none() {
        monitor.tick(20);
        while event::poll(Duration::ZERO).map_err(|e| format!("terminal: {e}"))? {
            let event = event::read().map_err(|e| format!("terminal: {e}"))?;
            if let Some(key) = Key::of(&event) {
                if !monitor.key(key) {
                    return Ok(());
                }
            }
        }
        if Instant::now() >= next_draw {
            next_draw = Instant::now() + Duration::from_millis(100);
            let view = monitor.view();
            terminal
                .draw(|f| render(f, &view))
                .map_err(|e| format!("terminal: {e}"))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::Terminal;
    use ratatui::backend::TestBackend;

    fn screen(view: &View) -> String {
        let mut terminal = Terminal::new(TestBackend::new(100, 24)).unwrap();
        terminal.draw(|f| render(f, view)).unwrap();
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

    #[test]
    fn the_screen_shows_every_stream_the_link_and_the_keys() {
        let view = View {
            port: "/dev/ttyUSB0".into(),
            link_alive: true,
            stale_ms: None,
            lock: Some(Lock::Locked),
            imu: Some(Imu {
                accel: [12, -7, 16_384],
                gyro: [-3, 2, 450],
                seq: 41,
            }),
            encoders: Some(Encoders {
                ticks: [120, -118, 121, -119],
                seq: 9,
            }),
            battery: Some(Battery {
                centivolts: 1_187,
                percent: 76,
                seq: 3,
            }),
            streams: [
                StreamView {
                    rate_millihertz: 100_000,
                    frames: 1_203,
                    missed: 2,
                },
                StreamView {
                    rate_millihertz: 25_000,
                    frames: 301,
                    missed: 0,
                },
                StreamView {
                    rate_millihertz: 990,
                    frames: 12,
                    missed: 0,
                },
            ],
            discarded: 17,
            failsafe_stops: 0,
            gyro_z: vec![3, 232, 450],
            driving: true,
            held: false,
            speed: 300,
            velocity: [0, 300, 0],
            turning: true,
            message: "turning 90° (sent once)".into(),
        };
        let text = screen(&view);
        for needle in [
            "chassis monitor",
            "/dev/ttyUSB0",
            "LINK UP",
            "parser locked, 17 bytes discarded",
            "failsafe stops 0",
            "accel  x     12  y     -7  z  16384",
            "gyro   x     -3  y      2  z    450   count 41",
            "M1    120  M2   -118  M3    121  M4   -119",
            "11.87 V  76 %",
            "100.0 Hz",
            "1203",
            "25.0 Hz",
            "1.0 Hz",
            "peak 450",
            "driving at 300: x 0 y 300 z 0  (turning)",
            "turning 90° (sent once)",
            "t turn 90° once",
            "q or Ctrl-C quit",
        ] {
            assert!(text.contains(needle), "{needle:?} on the screen:\n{text}");
        }
    }

    #[test]
    fn a_silent_board_shows_no_link_and_waits() {
        let text = screen(&View {
            port: "/dev/ttyACM0".into(),
            ..View::default()
        });
        assert!(text.contains("NO LINK"), "{text}");
        assert!(text.contains("waiting for the IMU"), "{text}");
        assert!(
            text.contains("read only (start with --drive to drive)"),
            "{text}"
        );
        assert!(text.contains("q quit"), "{text}");
    }

    #[test]
    fn a_board_gone_quiet_shows_stale_figures_and_the_hold() {
        let text = screen(&View {
            port: "/dev/ttyUSB0".into(),
            stale_ms: Some(3_200),
            streams: [StreamView {
                rate_millihertz: 100_000,
                frames: 50,
                missed: 0,
            }; 3],
            driving: true,
            held: true,
            failsafe_stops: 1,
            ..View::default()
        });
        for needle in [
            "NO LINK",
            "STALE 3.2 s",
            "stale",
            "stopped by the failsafe: press a key",
            "failsafe stops 1",
        ] {
            assert!(text.contains(needle), "{needle:?} on the screen:\n{text}");
        }
        assert!(
            !text.contains("100.0 Hz"),
            "no rate shown as if live:\n{text}"
        );
    }
}
