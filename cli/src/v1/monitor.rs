//! `chassis monitor` on a board running the v1.0.0 firmware (`7B … BCC 7D`): its screen and
//! its [`Chassis`]. The keys, the failsafe's hold, the link and the terminal are the 2020
//! board's ([`crate::monitor::Monitor`]); what differs is what the board says and how it is driven:
//!
//! * one telemetry frame at about 22 Hz: the measured body velocity (mm/s and mrad/s, shown in
//!   m/s and rad/s), the yaw worked out from the quaternion, the gyro and accelerometer raw
//!   (their scale is unknown), the battery (mV, shown in V);
//! * the link counters of the `7B … 7D` parser: frames good, bad BCC, bytes discarded, and the
//!   failsafe's stops;
//! * the keys drive at `--speed` mm/s, `z` / `x` rotate at [`ROTATE_MRAD_S`], space sends the
//!   forced stop; there is no turn by an angle (`t` only says so).

use crate::monitor::{Chassis, Status, drive_panel, rate_text, screen_frame};
use crate::port::BoardV1;
use chassis_protocol::driver::Error;
use chassis_protocol::driver::host::SerialError;
use chassis_protocol::driver::v1::DriverCore;
use chassis_protocol::v1::{BodyVelocity, Telemetry};
use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::text::Line;
use ratatui::widgets::{Block, Paragraph};

/// The rate the rotate keys turn at: 0.5 rad/s.
pub const ROTATE_MRAD_S: i32 = 500;

/// What `t` says on v1.0.0: nothing is sent.
pub const NO_TURN: &str = "no turn by an angle on v1.0.0 (nothing sent): z / x rotate at 0.5 rad/s";

/// The yaw in degrees, in (-180, 180], of the quaternion w, x, y, z (× 1000, as the telemetry
/// carries it): atan2(2(wz + xy), 1 − 2(y² + z²)). The second term is written
/// w² + x² − y² − z², the same for a unit quaternion and right for one the rounding to
/// thousandths left a little off unit length. `None` for the zero quaternion (no rotation
/// known).
pub fn yaw_degrees(quaternion: [i16; 4]) -> Option<f64> {
    let [w, x, y, z] = quaternion.map(|q| f64::from(q) / 1000.0);
    let norm = w * w + x * x + y * y + z * z;
    if norm == 0.0 {
        return None;
    }
    let yaw = (2.0 * (w * z + x * y))
        .atan2(norm - 2.0 * (y * y + z * z))
        .to_degrees();
    // atan2 gives [-180, 180]: -180 is the same heading as 180.
    Some(if yaw <= -180.0 { yaw + 360.0 } else { yaw })
}

/// Thousandths (mm/s, mrad/s, mV) as units, three decimals.
fn units(milli: i32) -> String {
    format!("{:.3}", f64::from(milli) / 1000.0)
}

/// Everything the v1.0.0 board's screen shows.
#[derive(Clone, Debug, Default)]
pub struct View {
    /// The monitor's part: port, link, hold, what is sent, the message.
    pub status: Status,
    /// The latest telemetry frame.
    pub telemetry: Option<Telemetry>,
    /// Telemetry frames per second, in thousandths.
    pub rate_millihertz: u32,
    /// Frames taken whole, BCC right.
    pub frames: u32,
    /// Whole frames whose BCC did not match.
    pub bad_checksum: u32,
    /// Bytes the parser threw away.
    pub discarded: u32,
    /// Times the failsafe sent the forced stop.
    pub failsafe_stops: u32,
}

/// Draws the v1.0.0 board's whole screen.
pub fn render(frame: &mut Frame<'_>, view: &View) {
    let status = &view.status;
    let body = screen_frame(
        frame,
        status,
        "  firmware v1.0.0".into(),
        "arrows/WASD drive  z/x rotate 0.5 rad/s  space forced stop  +/- speed  q or Ctrl-C quit",
    );
    let [top, drive_area] =
        Layout::vertical([Constraint::Length(10), Constraint::Min(4)]).areas(body);
    let [left, right] =
        Layout::horizontal([Constraint::Percentage(55), Constraint::Percentage(45)]).areas(top);
    render_motion(frame, left, view);
    let [battery_area, link_area] =
        Layout::vertical([Constraint::Length(3), Constraint::Length(7)]).areas(right);
    render_battery(frame, battery_area, view);
    render_link(frame, link_area, view);
    let [vx, vy, wz] = status.velocity;
    drive_panel(
        frame,
        drive_area,
        status,
        format!(
            "driving at {} m/s: vx {} vy {} m/s, wz {} rad/s",
            units(status.speed),
            units(vx),
            units(vy),
            units(wz)
        ),
    );
}

/// The left column: the measured velocity and yaw, the IMU.
fn render_motion(frame: &mut Frame<'_>, area: Rect, view: &View) {
    let [measured_area, imu_area] =
        Layout::vertical([Constraint::Length(4), Constraint::Length(5)]).areas(area);
    let stale = if view.status.stale_ms.is_some() {
        " (stale)"
    } else {
        ""
    };
    let (measured, imu) = match view.telemetry {
        Some(t) => (measured_lines(&t), imu_lines(&t)),
        None => (
            vec![Line::from("waiting for the telemetry…")],
            vec![Line::from("—")],
        ),
    };
    frame.render_widget(
        Paragraph::new(measured).block(Block::bordered().title(format!(" measured{stale} "))),
        measured_area,
    );
    frame.render_widget(
        Paragraph::new(imu).block(
            Block::bordered().title(format!(" IMU (gyro, accel raw: scale unknown){stale} ")),
        ),
        imu_area,
    );
}

/// The measured body velocity and the yaw from the quaternion.
fn measured_lines(t: &Telemetry) -> Vec<Line<'static>> {
    let [vx, vy, wz] = t.velocity.map(i32::from);
    vec![
        Line::from(format!(
            "vx {:>7} m/s  vy {:>7} m/s  wz {:>7} rad/s",
            units(vx),
            units(vy),
            units(wz)
        )),
        Line::from(match yaw_degrees(t.quaternion) {
            Some(yaw) => format!("yaw {yaw:>7.1}°  (from the quaternion)"),
            None => "yaw —  (the quaternion is all zero)".into(),
        }),
    ]
}

/// The accelerometer and the gyro raw, the quaternion.
fn imu_lines(t: &Telemetry) -> Vec<Line<'static>> {
    let [ax, ay, az] = t.accel;
    let [gx, gy, gz] = t.gyro;
    let [qw, qx, qy, qz] = t.quaternion;
    vec![
        Line::from(format!("accel raw  x {ax:>6}  y {ay:>6}  z {az:>6}")),
        Line::from(format!("gyro raw   x {gx:>6}  y {gy:>6}  z {gz:>6}")),
        Line::from(format!(
            "quaternion ×1000  w {qw:>5}  x {qx:>5}  y {qy:>5}  z {qz:>5}"
        )),
    ]
}

/// The battery, in volts.
fn render_battery(frame: &mut Frame<'_>, area: Rect, view: &View) {
    let battery = view.telemetry.map(|t| i32::from(t.battery_mv));
    frame.render_widget(
        Paragraph::new(battery.map_or_else(
            || "—".to_string(),
            |mv| format!("{:.2} V  ({mv} mV)", f64::from(mv) / 1000.0),
        ))
        .style(Style::new().fg(match battery {
            Some(mv) if mv >= 10_500 => Color::Green,
            Some(_) => Color::Red,
            None => Color::Reset,
        }))
        .block(Block::bordered().title(" battery ")),
        area,
    );
}

/// The link's counters.
fn render_link(frame: &mut Frame<'_>, area: Rect, view: &View) {
    frame.render_widget(
        Paragraph::new(vec![
            Line::from(format!(
                "telemetry       {}",
                rate_text(view.rate_millihertz, view.status.stale_ms)
            )),
            Line::from(format!("frames good     {}", view.frames)),
            Line::from(format!("bad BCC         {}", view.bad_checksum)),
            Line::from(format!("bytes discarded {}", view.discarded)),
            Line::from(format!("failsafe stops  {}", view.failsafe_stops)),
        ])
        .block(Block::bordered().title(" link ")),
        area,
    );
}

/// A velocity component as the frame's 16 bits (the keys never go past ±2000).
fn i16_of(v: i32) -> i16 {
    i16::try_from(v).unwrap_or(if v < 0 { i16::MIN } else { i16::MAX })
}

/// The v1.0.0 board under the monitor: it keeps nothing beside the driver.
pub struct BoardV1Chassis;

impl Chassis for BoardV1Chassis {
    type Core = DriverCore;
    type View = View;

    fn drive(&self, driver: &mut BoardV1, velocity: [i32; 3]) -> Result<(), Error<SerialError>> {
        let [vx, vy, wz] = velocity.map(i16_of);
        driver.set_velocity(BodyVelocity::new(vx, vy, wz))
    }

    fn rotate_rate(&self) -> Result<i32, &'static str> {
        Ok(ROTATE_MRAD_S)
    }

    fn turn(&mut self, _driver: &mut BoardV1, _alive: bool) -> Result<String, String> {
        Err(NO_TURN.into())
    }

    fn follow_up(&mut self, _driver: &mut BoardV1) -> Option<String> {
        None
    }

    fn view(&self, core: &DriverCore, status: Status) -> View {
        let stats = core.parser_stats();
        View {
            status,
            telemetry: core.telemetry().map(|s| s.value),
            rate_millihertz: core.stream().rate_millihertz,
            frames: stats.frames,
            bad_checksum: stats.bad_checksum,
            discarded: stats.discarded,
            failsafe_stops: core.failsafe_stops(),
        }
    }

    fn render(frame: &mut Frame<'_>, view: &View) {
        render(frame, view);
    }
}

/// `chassis monitor [--drive]` on a v1.0.0 board: the keys drive at `speed` mm/s.
pub fn run(port: &str, drive: bool, speed: i32) -> Result<(), String> {
    crate::monitor::run_monitor(
        || crate::port::open_v1(port, None),
        BoardV1Chassis,
        drive,
        speed,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monitor::testing::*;

    fn close(got: Option<f64>, want: f64) {
        let got = got.expect("a yaw");
        assert!((got - want).abs() < 0.1, "yaw {got}, want {want}");
    }

    #[test]
    fn the_yaw_comes_from_the_quaternion() {
        // No rotation.
        close(yaw_degrees([1000, 0, 0, 0]), 0.0);
        // About z by θ: (cos θ/2, 0, 0, sin θ/2), × 1000 and rounded.
        close(yaw_degrees([707, 0, 0, 707]), 90.0);
        close(yaw_degrees([707, 0, 0, -707]), -90.0);
        close(yaw_degrees([966, 0, 0, 259]), 30.0);
        close(yaw_degrees([259, 0, 0, 966]), 150.0);
        // Half a turn is 180, whichever sign the quaternion has.
        close(yaw_degrees([0, 0, 0, 1000]), 180.0);
        close(yaw_degrees([0, 0, 0, -1000]), 180.0);
        // q and -q are the same rotation.
        close(yaw_degrees([-966, 0, 0, -259]), 30.0);
        // A quaternion a little off unit length gives the same heading.
        close(yaw_degrees([700, 0, 0, 700]), 90.0);
        // Tilted (roll 90° about x, then yaw 90°): the xy term counts.
        close(yaw_degrees([500, 500, 500, 500]), 90.0);
        assert_eq!(yaw_degrees([0; 4]), None);
    }

    #[test]
    fn the_screen_shows_the_telemetry_the_counters_and_the_keys() {
        let view = View {
            status: driving(NO_TURN),
            telemetry: Some(Telemetry {
                velocity: [-120, 300, 500],
                accel: [3, -4, 1000],
                gyro: [1, -2, 500],
                quaternion: [707, 0, 0, 707],
                battery_mv: 11_870,
            }),
            rate_millihertz: 22_200,
            frames: 1_203,
            bad_checksum: 4,
            discarded: 17,
            failsafe_stops: 1,
        };
        assert_screen(
            &screen_text(render, &view),
            &[
                "chassis monitor",
                "/dev/ttyUSB0",
                "LINK UP",
                "firmware v1.0.0",
                "vx  -0.120 m/s  vy   0.300 m/s  wz   0.500 rad/s",
                "yaw    90.0°",
                "accel raw  x      3  y     -4  z   1000",
                "gyro raw   x      1  y     -2  z    500",
                "w   707  x     0  y     0  z   707",
                "scale unknown",
                "11.87 V  (11870 mV)",
                "telemetry       22.2 Hz",
                "frames good     1203",
                "bad BCC         4",
                "bytes discarded 17",
                "failsafe stops  1",
                "driving at 0.300 m/s: vx 0.000 vy 0.300 m/s, wz 0.000 rad/s",
                "no turn by an angle on v1.0.0",
                "z/x rotate 0.5 rad/s",
                "space forced stop",
                "q or Ctrl-C quit",
            ],
            &["t turn"],
        );
    }
}
