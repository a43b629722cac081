//! `chassis monitor` on a board running the 2020 firmware: its screen ([`View`], [`render`]) and
//! its [`Chassis`] (the gyro Z history, the reads of a turn's pending angle). The driver, the
//! keys, the failsafe's hold, the link, the screen's title and keys lines and the terminal are
//! shared ([`crate::monitor`]).

use super::{explain, open};
use crate::monitor::{Chassis, Status, drive_panel, rate_text, run_monitor, screen_frame};
use crate::port::Board;
use chassis_protocol::driver::host::SerialError;
use chassis_protocol::driver::{CoreError, DriverCore, Error, Event as DriverEvent};
use chassis_protocol::{Battery, Downlink, Encoders, Imu, Lock, Stream, Velocity};
use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::Line;
use ratatui::widgets::{Block, Gauge, Paragraph, Row, Sparkline, Table};
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// Gyro Z readings kept for the sparkline.
const HISTORY: usize = 120;

/// How often the pending angle is read while a turn is outstanding.
const TURN_READ: Duration = Duration::from_millis(250);

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

/// Everything the 2020 board's screen shows.
#[derive(Clone, Debug, Default)]
pub struct View {
    /// The monitor's part: port, link, hold, what is sent, the message.
    pub status: Status,
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
    /// A turn is outstanding.
    pub turning: bool,
}

/// Draws the 2020 board's whole screen.
pub fn render(frame: &mut Frame<'_>, view: &View) {
    let status = &view.status;
    let lock = match view.lock {
        Some(Lock::Locked) => "locked",
        Some(Lock::Tentative) => "tentative",
        Some(Lock::Hunting) | None => "hunting",
    };
    let body = screen_frame(
        frame,
        status,
        format!(
            "  failsafe stops {}  parser {lock}, {} bytes discarded",
            view.failsafe_stops, view.discarded
        ),
        "arrows/WASD drive  space stop  t turn 90° once  +/- speed  q or Ctrl-C quit",
    );
    let [left, right] =
        Layout::horizontal([Constraint::Percentage(55), Constraint::Percentage(45)]).areas(body);
    render_motion(frame, left, view);
    let [battery_area, streams_area, drive_area] = Layout::vertical([
        Constraint::Length(3),
        Constraint::Length(6),
        Constraint::Min(4),
    ])
    .areas(right);
    render_battery(frame, battery_area, view.battery);
    render_streams(frame, streams_area, view);
    drive_panel(
        frame,
        drive_area,
        status,
        format!(
            "driving at {}: x {} y {} z {}{}",
            status.speed,
            status.velocity[0],
            status.velocity[1],
            status.velocity[2],
            if view.turning { "  (turning)" } else { "" }
        ),
    );
}

/// The left column: the IMU, the |gyro Z| history, the encoders.
fn render_motion(frame: &mut Frame<'_>, area: Rect, view: &View) {
    let [imu_area, gyro_area, enc_area] = Layout::vertical([
        Constraint::Length(4),
        Constraint::Min(3),
        Constraint::Length(3),
    ])
    .areas(area);
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
}

/// The battery gauge.
fn render_battery(frame: &mut Frame<'_>, area: Rect, battery: Option<Battery>) {
    let (ratio, label) = match battery {
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
        area,
    );
}

/// The three streams: rate, frames, frames missed.
fn render_streams(frame: &mut Frame<'_>, area: Rect, view: &View) {
    let rows = ["IMU", "encoders", "battery"]
        .iter()
        .zip(view.streams.iter())
        .map(|(name, s)| {
            Row::new(vec![
                (*name).to_string(),
                rate_text(s.rate_millihertz, view.status.stale_ms),
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
        area,
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

/// The 2020 board under the monitor: the gyro Z history, the next read of a turn's pending
/// angle.
pub struct Board2020 {
    history: VecDeque<i16>,
    next_turn_read: Instant,
}

impl Board2020 {
    /// No history yet.
    pub fn new() -> Self {
        Board2020 {
            history: VecDeque::with_capacity(HISTORY),
            next_turn_read: Instant::now(),
        }
    }
}

impl Chassis for Board2020 {
    type Core = DriverCore;
    type View = View;

    fn took(&mut self, event: &DriverEvent) {
        if let DriverEvent::Telemetry(Downlink::Imu(imu)) = event {
            if self.history.len() == HISTORY {
                self.history.pop_front();
            }
            self.history.push_back(imu.gyro[2]);
        }
    }

    fn drive(&self, driver: &mut Board, [x, y, z]: [i32; 3]) -> Result<(), Error<SerialError>> {
        driver.set_velocity(Velocity::new(x, y, z))
    }

    fn rotate_rate(&self) -> Result<i32, &'static str> {
        Err("no rotate keys on the 2020 firmware: t turns 90°")
    }

    fn turn(&mut self, driver: &mut Board, alive: bool) -> Result<String, String> {
        if !alive {
            return Err("no link: not turning".into());
        }
        match driver.turn_by(900) {
            Ok(()) => {
                self.next_turn_read = Instant::now() + TURN_READ;
                Ok("turning 90° (sent once)".into())
            }
            Err(Error::Core(CoreError::TurnInProgress)) => {
                Err("a turn is still going: not sent again".into())
            }
            Err(e) => Err(explain(driver, e)),
        }
    }

    fn follow_up(&mut self, driver: &mut Board) -> Option<String> {
        if driver.core().turning() && Instant::now() >= self.next_turn_read {
            self.next_turn_read = Instant::now() + TURN_READ;
            // A read lost is tried again at the next one.
            if driver.turn_remaining().is_ok() && !driver.core().turning() {
                return Some("turn done".into());
            }
        }
        None
    }

    fn view(&self, core: &DriverCore, status: Status) -> View {
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
            status,
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
            turning: core.turning(),
        }
    }

    fn render(frame: &mut Frame<'_>, view: &View) {
        render(frame, view);
    }
}

/// `chassis monitor [--drive]` on a 2020 board.
pub fn run(port: &str, drive: bool, speed: i32) -> Result<(), String> {
    run_monitor(|| open(port), Board2020::new(), drive, speed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monitor::testing::*;

    #[test]
    fn the_screen_shows_every_stream_the_link_and_the_keys() {
        let view = View {
            status: driving("turning 90° (sent once)"),
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
            turning: true,
        };
        assert_screen(
            &screen_text(render, &view),
            &[
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
            ],
            &[],
        );
    }
}
