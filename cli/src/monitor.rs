//! `chassis monitor`: a live view of the board's telemetry; with `--drive`, keys drive it.
//!
//! The screen is drawn from a [`View`] (a plain value taken from the driver each frame), so a
//! test renders it with ratatui's test backend. Keys: arrows or WASD drive at the set speed,
//! space stops, `t` turns 90° once, `+`/`-` change the speed, `q` or Esc quits (stopping first).
//! The driver's failsafe stays active: a board that goes quiet is stopped.

use crate::device::{explain, open};
use chassis_protocol::driver::host::HostDriver;
use chassis_protocol::driver::{CoreError, Error};
use chassis_protocol::{Battery, Encoders, Imu, Lock, Stream, Velocity};
use ratatui::Frame;
use ratatui::crossterm::event::{self, Event, KeyCode, KeyEventKind};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Gauge, Paragraph, Row, Sparkline, Table};
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
    /// The speed keys drive at.
    pub speed: i32,
    /// The velocity being sent: x, y, z.
    pub velocity: [i32; 3],
    /// A turn is outstanding.
    pub turning: bool,
    /// The last message (errors, refusals).
    pub message: String,
}

impl View {
    fn from_driver(
        driver: &HostDriver,
        port: &str,
        link_alive: bool,
        history: &VecDeque<i16>,
        drive: &DriveState,
        message: &str,
    ) -> Self {
        let core = driver.core();
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
            port: port.to_string(),
            link_alive,
            lock: Some(core.lock()),
            imu: core.imu().map(|s| s.value),
            encoders: core.encoders().map(|s| s.value),
            battery: core.battery().map(|s| s.value),
            streams,
            discarded: core.parser_stats().discarded,
            failsafe_stops: core.failsafe_stops(),
            gyro_z: history
                .iter()
                .map(|g| u64::from(g.unsigned_abs()))
                .collect(),
            driving: drive.enabled,
            speed: drive.speed,
            velocity: [drive.velocity.x, drive.velocity.y, drive.velocity.z],
            turning: core.turning(),
            message: message.to_string(),
        }
    }
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
            Span::raw(format!(
                "  parser {lock}, {} bytes discarded  failsafe stops {}",
                view.discarded, view.failsafe_stops
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
                format!("{:.1} Hz", f64::from(s.rate_millihertz) / 1000.0),
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
    let drive = if view.driving {
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
        Paragraph::new(drive).block(Block::bordered().title(" drive ")),
        drive_area,
    );
    let help = if view.driving {
        "arrows/WASD drive  space stop  t turn 90° once  +/- speed  q quit"
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

/// The keyboard's driving state.
#[derive(Clone, Copy, Debug)]
struct DriveState {
    enabled: bool,
    speed: i32,
    velocity: Velocity,
}

/// `chassis monitor [--drive]`.
pub fn run(port: &str, drive: bool, speed: i32) -> Result<(), String> {
    let mut driver = open(port)?;
    let mut terminal = ratatui::try_init().map_err(|e| format!("terminal: {e}"))?;
    let result = monitor_loop(&mut terminal, &mut driver, port, drive, speed);
    // Stop before giving the terminal back, whatever happened.
    let stopped = if drive {
        driver.stop().map_err(explain)
    } else {
        Ok(())
    };
    ratatui::restore();
    result?;
    stopped
}

fn monitor_loop(
    terminal: &mut ratatui::DefaultTerminal,
    driver: &mut HostDriver,
    port: &str,
    drive: bool,
    speed: i32,
) -> Result<(), String> {
    let mut last_frame: Option<Instant> = None;
    let mut history: VecDeque<i16> = VecDeque::with_capacity(HISTORY);
    let mut state = DriveState {
        enabled: drive,
        speed,
        velocity: Velocity::new(0, 0, 0),
    };
    let mut message = String::new();
    let mut next_send = Instant::now();
    let mut next_draw = Instant::now();
    loop {
        // Everything the port holds, and time judged (failsafe included).
        let until = Instant::now() + Duration::from_millis(20);
        while Instant::now() < until {
            match driver.poll() {
                Ok(Some(chassis_protocol::driver::Event::Telemetry(
                    chassis_protocol::Downlink::Imu(imu),
                ))) => {
                    last_frame = Some(Instant::now());
                    if history.len() == HISTORY {
                        history.pop_front();
                    }
                    history.push_back(imu.gyro[2]);
                }
                Ok(Some(_)) => last_frame = Some(Instant::now()),
                Ok(None) => std::thread::sleep(Duration::from_millis(1)),
                Err(e) => message = explain(e),
            }
        }
        if state.enabled && Instant::now() >= next_send {
            next_send = Instant::now() + Duration::from_millis(50);
            if state.velocity != Velocity::new(0, 0, 0) {
                if let Err(e) = driver.set_velocity(state.velocity) {
                    message = explain(e);
                }
            }
        }
        while event::poll(Duration::ZERO).map_err(|e| format!("terminal: {e}"))? {
            let Event::Key(key) = event::read().map_err(|e| format!("terminal: {e}"))? else {
                continue;
            };
            if key.kind != KeyEventKind::Press {
                continue;
            }
            let s = state.speed;
            let target = match key.code {
                KeyCode::Char('q') | KeyCode::Esc => return Ok(()),
                _ if !state.enabled => None,
                KeyCode::Up | KeyCode::Char('w') => Some(Velocity::new(0, s, 0)),
                KeyCode::Down | KeyCode::Char('s') => Some(Velocity::new(0, -s, 0)),
                KeyCode::Left | KeyCode::Char('a') => Some(Velocity::new(-s, 0, 0)),
                KeyCode::Right | KeyCode::Char('d') => Some(Velocity::new(s, 0, 0)),
                KeyCode::Char(' ') => {
                    state.velocity = Velocity::new(0, 0, 0);
                    match driver.stop() {
                        Ok(()) => message = "stopped".into(),
                        Err(e) => message = explain(e),
                    }
                    None
                }
                KeyCode::Char('t') => {
                    match driver.turn_by(900) {
                        Ok(()) => message = "turning 90° (sent once)".into(),
                        Err(Error::Core(CoreError::TurnInProgress)) => {
                            message = "a turn is still going: not sent again".into();
                        }
                        Err(e) => message = explain(e),
                    }
                    None
                }
                KeyCode::Char('+') => {
                    state.speed = (state.speed + 50).min(2_000);
                    None
                }
                KeyCode::Char('-') => {
                    state.speed = (state.speed - 50).max(50);
                    None
                }
                _ => None,
            };
            if let Some(v) = target {
                state.velocity = v;
                next_send = Instant::now();
                message.clear();
            }
        }
        if Instant::now() >= next_draw {
            next_draw = Instant::now() + Duration::from_millis(100);
            // The link is up while frames keep coming: one in the last half second.
            let alive = last_frame.is_some_and(|t| t.elapsed() < Duration::from_millis(500));
            let view = View::from_driver(driver, port, alive, &history, &state, &message);
            terminal
                .draw(|f| render(f, &view))
                .map_err(|e| format!("terminal: {e}"))?;
        }
    }
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
}
