//! The odometry: the pose and twist from the 2020 board's encoder frames or from the v1.0.0
//! board's measured body velocity, integrated along the exact arc.

use crate::arc::wrap;
use crate::{Geometry, Noise, Pose2, Twist2, covariance};

/// How the 2020 board's encoder values are read (decision A5 in docs/protocol-2020.md: the vendor
/// says neither): a running total per wheel (wrapping i16) or the ticks counted since the last frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Counts {
    /// Each value is the wheel's running total, wrapping at 16 bits: a frame's motion is the
    /// wrapping difference from the previous frame (right while a wheel moves less than
    /// 32 767 ticks between frames). What the simulated board sends.
    RunningTotal,
    /// Each value is the ticks counted since the board's previous frame: a lost frame's motion
    /// is lost.
    PerFrame,
}

/// After a gap longer than this between two frames (ms), the later one only sets the reference
/// again: 1 s, twice the longest telemetry pause while settings are made (decision A13), 25
/// encoder frames at 25 Hz.
pub const DEFAULT_MAX_GAP_MS: u64 = 1_000;

/// The last v1.0.0 frame: when, its twist, its heading (quaternion yaw, raw).
#[derive(Clone, Copy, Debug, PartialEq)]
struct BodySample {
    at_ms: u64,
    twist: Twist2,
    yaw: Option<f32>,
}

/// The pose and twist of the chassis, from one firmware generation's frames: the 2020
/// encoder frames ([`Odometry::encoders`]) or the v1.0.0 telemetry ([`Odometry::body`]), not
/// both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Odometry {
    geometry: Geometry,
    counts: Counts,
    noise: Noise,
    max_gap_ms: u64,
    pose: Pose2,
    twist: Twist2,
    /// The last encoder frame and when it came.
    last_ticks: Option<([i16; 4], u64)>,
    /// The last v1.0.0 frame.
    last_body: Option<BodySample>,
    /// The quaternion's yaw where the odometry frame's heading is 0 (fixed by the first frame
    /// with a quaternion).
    yaw_origin: Option<f32>,
    /// Distance travelled (m) and turned (rad), summed absolutely, since the start.
    travelled_m: f32,
    turned_rad: f32,
    /// Whether the heading is a quaternion's (v1.0.0) rather than integrated.
    heading_measured: bool,
}

impl Odometry {
    /// At the origin, still, waiting for its first frame; gaps up to [`DEFAULT_MAX_GAP_MS`].
    #[must_use]
    pub const fn new(geometry: Geometry, counts: Counts, noise: Noise) -> Self {
        Odometry {
            geometry,
            counts,
            noise,
            max_gap_ms: DEFAULT_MAX_GAP_MS,
            pose: Pose2 {
                x: 0.0,
                y: 0.0,
                yaw: 0.0,
            },
            twist: Twist2 {
                vx: 0.0,
                vy: 0.0,
                wz: 0.0,
            },
            last_ticks: None,
            last_body: None,
            yaw_origin: None,
            travelled_m: 0.0,
            turned_rad: 0.0,
            heading_measured: false,
        }
    }

    /// The same with another longest gap between frames (ms): after a longer one, a frame
    /// only sets the reference again.
    #[must_use]
    pub const fn with_max_gap_ms(mut self, max_gap_ms: u64) -> Self {
        self.max_gap_ms = max_gap_ms;
        self
    }

    /// Its geometry.
    #[must_use]
    pub const fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// A 2020 encoder frame's four values, heard at `at_ms` (monotonic ms): the pose moves by
    /// the wheels' travel since the previous frame, integrated along the exact arc. The first
    /// frame (and the first after `reset`, or after a gap longer than `max_gap_ms`) only sets
    /// the reference. Returns the twist estimated over that interval.
    ///
    /// A frame heard earlier than the previous one also only sets the reference; one heard at
    /// the same ms moves the pose and returns `None` (no interval to divide by). Motion that
    /// is not finite (a geometry that fails [`Geometry::validate`]) is ignored: `None`, the
    /// pose unchanged.
    pub fn encoders(&mut self, ticks: [i16; 4], at_ms: u64) -> Option<Twist2> {
        let (before, then_ms) = self.last_ticks.replace((ticks, at_ms))?;
        if at_ms < then_ms || at_ms - then_ms > self.max_gap_ms {
            return None;
        }
        let mut travel = [0.0f32; 4];
        for ((t, now), was) in travel.iter_mut().zip(ticks).zip(before) {
            let delta = match self.counts {
                Counts::RunningTotal => now.wrapping_sub(was),
                Counts::PerFrame => now,
            };
            *t = f32::from(delta) / self.geometry.ticks_per_m;
        }
        // Wheel travels in m give the body's displacement (m) and turn (rad).
        let moved = self.geometry.body_twist(travel);
        if !(moved.vx.is_finite() && moved.vy.is_finite() && moved.wz.is_finite()) {
            return None;
        }
        self.advance(moved.vx, moved.vy, moved.wz);
        if at_ms == then_ms {
            return None;
        }
        let dt_s = (at_ms - then_ms) as f32 / 1_000.0;
        self.twist = Twist2 {
            vx: moved.vx / dt_s,
            vy: moved.vy / dt_s,
            wz: moved.wz / dt_s,
        };
        Some(self.twist)
    }

    /// A 2020 encoder frame ([`Odometry::encoders`] of its values).
    pub fn encoder_frame(
        &mut self,
        frame: &chassis_protocol::Encoders,
        at_ms: u64,
    ) -> Option<Twist2> {
        self.encoders(frame.ticks, at_ms)
    }

    /// A v1.0.0 telemetry frame: its measured body velocity (REP-103 axes: [`v1_twist`]
    /// converts the frame's) and, where the frame has one, the yaw from its quaternion
    /// ([`v1_yaw`]), which then sets the heading instead of integrating wz.
    ///
    /// The pose moves over the interval since the previous frame along the arc, at the mean of
    /// the two frames' velocities (the trapezoid rule), turning by the change of the
    /// quaternion's yaw where both frames have one, else by the mean wz. The heading is then the
    /// quaternion's yaw less its yaw at the first frame that had one (less the heading the
    /// odometry had then: 0 at its start, so the odometry frame starts heading along x, as with
    /// encoders). The first frame, one after `reset`, after a gap longer than
    /// `max_gap_ms` or earlier than the previous one only sets the reference (and the twist).
    /// Values that are not finite are ignored.
    ///
    /// [`v1_twist`]: crate::v1_twist
    /// [`v1_yaw`]: crate::v1_yaw
    pub fn body(&mut self, body: Twist2, yaw: Option<f32>, at_ms: u64) {
        if !(body.vx.is_finite() && body.vy.is_finite() && body.wz.is_finite()) {
            return;
        }
        let yaw = yaw.filter(|y| y.is_finite());
        let previous = self.last_body.replace(BodySample {
            at_ms,
            twist: body,
            yaw,
        });
        self.twist = body;
        // Moved since the previous frame, unless this one only sets the reference.
        if let Some(before) =
            previous.filter(|b| at_ms >= b.at_ms && at_ms - b.at_ms <= self.max_gap_ms)
        {
            let dt_s = (at_ms - before.at_ms) as f32 / 1_000.0;
            let turn = match (before.yaw, yaw) {
                (Some(a), Some(b)) => wrap(b - a),
                _ => (before.twist.wz + body.wz) / 2.0 * dt_s,
            };
            self.advance(
                (before.twist.vx + body.vx) / 2.0 * dt_s,
                (before.twist.vy + body.vy) / 2.0 * dt_s,
                turn,
            );
        }
        if let Some(y) = yaw {
            // The first quaternion fixes where heading 0 is: the heading the odometry has
            // then (0 at its start), so that the heading never jumps.
            let origin = *self.yaw_origin.get_or_insert(wrap(y - self.pose.yaw));
            self.pose.yaw = wrap(y - origin);
            self.heading_measured = true;
        }
    }

    /// A v1.0.0 telemetry frame ([`Odometry::body`] of [`v1_twist`](crate::v1_twist) and
    /// [`v1_yaw`](crate::v1_yaw)).
    pub fn v1_telemetry(&mut self, frame: &chassis_protocol::v1::Telemetry, at_ms: u64) {
        self.body(crate::v1_twist(frame), crate::v1_yaw(frame), at_ms);
    }

    /// Moves along the arc: `forward`, `left` (m) and `turn` (rad) in the body's axes.
    fn advance(&mut self, forward: f32, left: f32, turn: f32) {
        self.pose = self.pose.along_arc(forward, left, turn);
        self.travelled_m += libm::hypotf(forward, left);
        self.turned_rad += turn.abs();
    }

    /// Where the chassis is in the odometry frame.
    #[must_use]
    pub fn pose(&self) -> Pose2 {
        self.pose
    }

    /// The twist over the last interval (2020), or the last measured one (v1.0.0).
    #[must_use]
    pub fn twist(&self) -> Twist2 {
        self.twist
    }

    /// Row-major 6×6 over (x, y, z, roll, pitch, yaw), as nav_msgs/Odometry wants.
    ///
    /// Diagonal: x and y `pose_xy × (1 + d)`, d the distance travelled (m); yaw
    /// `pose_yaw × (1 + d + θ)`, θ the angle turned (rad), or `pose_yaw` while a quaternion
    /// gives the heading; z, roll, pitch `immobile`. Each at least 10⁻⁹ and at most
    /// `immobile`.
    #[must_use]
    pub fn pose_covariance(&self) -> [f64; 36] {
        covariance::pose(
            &self.noise,
            self.travelled_m,
            self.turned_rad,
            self.heading_measured,
        )
    }

    /// Row-major 6×6 over (vx, vy, vz, roll, pitch, yaw rates): `twist_linear` on vx and vy
    /// (`immobile` on vy for a differential chassis), `twist_angular` on wz, `immobile` on the
    /// rest.
    #[must_use]
    pub fn twist_covariance(&self) -> [f64; 36] {
        covariance::twist(&self.noise, self.geometry.moves_sideways())
    }

    /// Back to the origin, still, waiting for a first frame (which only sets the reference).
    pub fn reset(&mut self) {
        *self =
            Odometry::new(self.geometry, self.counts, self.noise).with_max_gap_ms(self.max_gap_ms);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Drive;
    use core::f32::consts::PI;

    const GEOMETRY: Geometry = Geometry::SIMULATOR;

    fn odometry(counts: Counts) -> Odometry {
        Odometry::new(GEOMETRY, counts, Noise::DEFAULT)
    }

    fn twist(vx: f32, vy: f32, wz: f32) -> Twist2 {
        Twist2 { vx, vy, wz }
    }

    fn near(pose: Pose2, x: f32, y: f32, yaw: f32, tolerance: f32) {
        assert!(
            (pose.x - x).abs() < tolerance
                && (pose.y - y).abs() < tolerance
                && (pose.yaw - yaw).abs() < tolerance,
            "{pose:?}, expected ({x}, {y}, {yaw}) within {tolerance}"
        );
    }

    #[test]
    fn the_first_frame_only_sets_the_reference() {
        for counts in [Counts::RunningTotal, Counts::PerFrame] {
            let mut o = odometry(counts);
            assert_eq!(o.encoders([500, -20, 7, 32_000], 1_000), None);
            assert_eq!(o.pose(), Pose2::default());
            assert_eq!(o.twist(), Twist2::default());
        }
    }

    #[test]
    fn a_straight_metre_at_25_hz() {
        let mut o = odometry(Counts::RunningTotal);
        assert_eq!(o.encoders([0; 4], 0), None);
        for i in 1..=25i16 {
            // 40 ticks (4 cm) every 40 ms: 1 m/s.
            let t = o.encoders([40 * i; 4], 40 * i as u64).expect("a twist");
            assert!(
                (t.vx - 1.0).abs() < 1e-5 && t.vy == 0.0 && t.wz == 0.0,
                "{t:?}"
            );
        }
        near(o.pose(), 1.0, 0.0, 0.0, 1e-5);
    }

    #[test]
    fn running_totals_wrap_at_16_bits() {
        let mut o = odometry(Counts::RunningTotal);
        o.encoders([-32_700, 32_700, 32_700, -32_700], 0);
        // Left wheels 100 ticks back past −32 768 (to 32 736), right ones 100 forward past
        // 32 767 (to −32 736), in 100 ms: 0.1 m each way, a turn in place counter-clockwise
        // by 4 × 0.1 / (4 × 0.22) = 0.4545 rad, 4.545 rad/s. Misread without the wrap, each
        // wheel would have gone 65.4 m the other way.
        let t = o
            .encoders([32_736, -32_736, -32_736, 32_736], 100)
            .expect("a twist");
        assert!(t.vx.abs() < 1e-5 && t.vy.abs() < 1e-5, "{t:?}");
        assert!((t.wz - 0.4 / 0.088).abs() < 1e-3, "{t:?}");
        near(o.pose(), 0.0, 0.0, 0.1 / 0.22, 1e-5);
        // The same wrap on every wheel: 0.1 m forward.
        let mut o = odometry(Counts::RunningTotal);
        o.encoders([32_700; 4], 0);
        o.encoders([-32_736; 4], 100);
        near(o.pose(), 0.1, 0.0, 0.0, 1e-6);
    }

    #[test]
    fn per_frame_counts_add_up() {
        let mut o = odometry(Counts::PerFrame);
        // The first frame's 999 ticks cover an unknown interval: ignored.
        o.encoders([999; 4], 0);
        for i in 1..=10u64 {
            let t = o.encoders([40; 4], 40 * i).expect("a twist");
            assert!((t.vx - 1.0).abs() < 1e-5);
        }
        near(o.pose(), 0.4, 0.0, 0.0, 1e-6);
    }

    #[test]
    fn a_gap_or_time_going_back_only_sets_the_reference() {
        let mut o = odometry(Counts::RunningTotal);
        o.encoders([0; 4], 0);
        o.encoders([40; 4], 40);
        // 1 001 ms later: longer than the 1 000 ms allowed.
        assert_eq!(o.encoders([1_040; 4], 1_041), None);
        near(o.pose(), 0.04, 0.0, 0.0, 1e-6);
        // From there on, it counts again.
        assert!(o.encoders([1_080; 4], 1_081).is_some());
        near(o.pose(), 0.08, 0.0, 0.0, 1e-6);
        // Earlier than the previous frame.
        assert_eq!(o.encoders([2_000; 4], 500), None);
        near(o.pose(), 0.08, 0.0, 0.0, 1e-6);
        // A shorter longest gap.
        let mut strict = odometry(Counts::RunningTotal).with_max_gap_ms(50);
        strict.encoders([0; 4], 0);
        assert_eq!(strict.encoders([60; 4], 60), None);
        assert_eq!(strict.pose(), Pose2::default());
    }

    #[test]
    fn a_frame_at_the_same_ms_moves_but_gives_no_twist() {
        let mut o = odometry(Counts::RunningTotal);
        o.encoders([0; 4], 0);
        o.encoders([40; 4], 40);
        assert_eq!(o.encoders([80; 4], 40), None);
        near(o.pose(), 0.08, 0.0, 0.0, 1e-6);
        assert!((o.twist().vx - 1.0).abs() < 1e-5, "the last twist is kept");
    }

    #[test]
    fn a_turn_in_place_counter_clockwise() {
        let mut o = odometry(Counts::RunningTotal);
        o.encoders([0; 4], 0);
        // 0.22 m on the lever 0.22 m: 1 rad, in 1 s; left wheels back.
        let t = o.encoders([-220, 220, 220, -220], 1_000).expect("a twist");
        assert!((t.wz - 1.0).abs() < 1e-5 && t.vx.abs() < 1e-6 && t.vy.abs() < 1e-6);
        near(o.pose(), 0.0, 0.0, 1.0, 1e-5);
    }

    #[test]
    fn a_full_circle_returns_to_the_start() {
        // 1e5 ticks/m (0.01 mm a tick), 0.5 m/s and a turn in 12.6 s (315 frames at 25 Hz),
        // running totals from near the wrap. Each frame's ticks are the wheels' exact
        // travel rounded: the heading is off by at most 4 × 0.5 tick / (4 k × 1e5) = 2.3e-5
        // rad, not accumulating (totals, not sums); the position by at most that times each
        // frame's 2 cm, 315 times: 0.15 mm; f32 rounding over 315 steps adds ~1e-4. Bound:
        // 1 mm, 0.5 mrad.
        let geometry = Geometry {
            ticks_per_m: 1e5,
            ..GEOMETRY
        };
        let mut o = Odometry::new(geometry, Counts::RunningTotal, Noise::DEFAULT);
        let (vx, wz, k) = (0.5f64, 2.0 * core::f64::consts::PI / 12.6, 0.22f64);
        // MOTO1..4 of a forward speed and a counter-clockwise turn, by hand.
        let wheels = [vx - k * wz, vx + k * wz, vx + k * wz, vx - k * wz];
        let ticks_at = |ms: u64| {
            let t = ms as f64 / 1_000.0;
            wheels.map(|w| (32_000.0 + w * t * 1e5).round() as i64 as i16)
        };
        o.encoders(ticks_at(0), 0);
        for i in 1..=315u64 {
            o.encoders(ticks_at(40 * i), 40 * i);
            if i == 158 {
                // Halfway (6.32 s, a little past half a turn): near (0, 2r).
                let r = (vx / wz) as f32;
                assert!((o.pose().y - 2.0 * r).abs() < 0.01, "{:?}", o.pose());
            }
        }
        let end = o.pose();
        assert!(end.x.hypot(end.y) < 1e-3, "{end:?}");
        assert!(end.yaw.abs() < 5e-4, "{end:?}");
    }

    #[test]
    fn geometry_that_cannot_be_used_leaves_the_pose() {
        let broken = Geometry {
            ticks_per_m: 0.0,
            ..GEOMETRY
        };
        let mut o = Odometry::new(broken, Counts::RunningTotal, Noise::DEFAULT);
        o.encoders([0; 4], 0);
        assert_eq!(o.encoders([40; 4], 40), None);
        assert_eq!(o.pose(), Pose2::default());
    }

    #[test]
    fn reset_goes_back_to_the_origin_and_waits() {
        let mut o = odometry(Counts::RunningTotal).with_max_gap_ms(5_000);
        o.encoders([0; 4], 0);
        o.encoders([400; 4], 400);
        o.reset();
        assert_eq!(o.pose(), Pose2::default());
        assert_eq!(o.twist(), Twist2::default());
        assert_eq!(
            o.encoders([800; 4], 800),
            None,
            "the first frame after a reset"
        );
        // The longest gap is kept.
        assert!(o.encoders([840; 4], 4_000).is_some());
        // And the covariance starts again.
        let expected = f64::from(Noise::DEFAULT.pose_xy) * (1.0 + 0.04);
        assert!((o.pose_covariance()[0] - expected).abs() < 1e-9);
    }

    #[test]
    fn covariance_never_zero_on_an_estimated_axis() {
        let mut o = odometry(Counts::RunningTotal);
        for m in [o.pose_covariance(), o.twist_covariance()] {
            for i in [0, 7, 35] {
                assert!(m[i] > 0.0, "{i}: {}", m[i]);
            }
            for i in [14, 21, 28] {
                assert_eq!(m[i], 1e3, "immobile {i}");
            }
        }
        o.encoders([0; 4], 0);
        o.encoders([1_000; 4], 1_000);
        // 1 m: x, y × 2, yaw × 2.
        let p = f64::from(Noise::DEFAULT.pose_xy);
        assert!((o.pose_covariance()[0] - 2.0 * p).abs() < 1e-9);
        assert!((o.pose_covariance()[35] - 2.0 * p).abs() < 1e-9);
        let differential = Odometry::new(
            Geometry {
                drive: Drive::Differential,
                ..GEOMETRY
            },
            Counts::RunningTotal,
            Noise::DEFAULT,
        );
        assert_eq!(differential.twist_covariance()[7], 1e3);
        assert!(
            differential.pose_covariance()[7] < 1.0,
            "y is estimated in the odom frame"
        );
    }

    #[test]
    fn measured_velocity_at_25_hz_goes_a_straight_metre() {
        let mut o = odometry(Counts::RunningTotal);
        for i in 0..=25u64 {
            o.body(twist(1.0, 0.0, 0.0), None, 40 * i);
        }
        near(o.pose(), 1.0, 0.0, 0.0, 1e-5);
        assert_eq!(o.twist(), twist(1.0, 0.0, 0.0));
    }

    #[test]
    fn measured_velocity_uses_the_mean_of_two_frames() {
        let mut o = odometry(Counts::RunningTotal);
        o.body(twist(0.0, 0.0, 0.0), None, 0);
        // From still to 1 m/s over 100 ms: 5 cm.
        o.body(twist(1.0, 0.0, 0.0), None, 100);
        near(o.pose(), 0.05, 0.0, 0.0, 1e-6);
        // Sideways too, and wz integrated when there is no quaternion: 0.5 rad/s for 1 s.
        let mut o = odometry(Counts::RunningTotal);
        o.body(twist(0.0, 0.0, 0.5), None, 0);
        o.body(twist(0.0, 0.0, 0.5), None, 1_000);
        near(o.pose(), 0.0, 0.0, 0.5, 1e-6);
    }

    #[test]
    fn the_quaternion_sets_the_heading_from_where_it_started() {
        let mut o = odometry(Counts::RunningTotal);
        // The board powered up heading elsewhere: 1.0 rad at our first frame.
        o.body(twist(0.0, 0.0, 0.0), Some(1.0), 0);
        assert_eq!(o.pose().yaw, 0.0);
        // wz says nothing (0); the quaternion says a quarter turn more.
        o.body(twist(0.0, 0.0, 0.0), Some(1.0 + PI / 2.0), 500);
        near(o.pose(), 0.0, 0.0, PI / 2.0, 1e-6);
        // Moving forward while the quaternion turns by 0.2 rad over 40 ms: along the arc.
        let mut o = odometry(Counts::RunningTotal);
        o.body(twist(1.0, 0.0, 0.0), Some(0.0), 0);
        o.body(twist(1.0, 0.0, 0.0), Some(0.2), 40);
        // 0.04 m on an arc turning 0.2 rad: (0.04 sin 0.2 / 0.2, 0.04 (1 − cos 0.2) / 0.2).
        near(o.pose(), 0.039_733, 0.003_987, 0.2, 1e-5);
        // The yaw variance does not grow while measured.
        assert_eq!(o.pose_covariance()[35], f64::from(Noise::DEFAULT.pose_yaw));
    }

    #[test]
    fn a_first_quaternion_after_frames_without_one_does_not_make_the_heading_jump() {
        let mut o = odometry(Counts::RunningTotal);
        o.body(twist(0.0, 0.0, 0.5), None, 0);
        o.body(twist(0.0, 0.0, 0.5), None, 1_000);
        // 0.5 rad integrated; then the board's quaternion says 2.0 (its own zero elsewhere),
        // wz 0 from here: the heading stays (the mean wz turns it by 0.25 rad first).
        o.body(twist(0.0, 0.0, 0.0), Some(2.0), 1_000 + 1_000);
        near(o.pose(), 0.0, 0.0, 0.75, 1e-6);
        // From there the quaternion's changes count: 0.1 rad more.
        o.body(twist(0.0, 0.0, 0.0), Some(2.1), 2_040);
        near(o.pose(), 0.0, 0.0, 0.85, 1e-6);
    }

    #[test]
    fn measured_velocity_that_is_not_finite_is_ignored() {
        let mut o = odometry(Counts::RunningTotal);
        o.body(twist(1.0, 0.0, 0.0), None, 0);
        o.body(twist(f32::NAN, 0.0, 0.0), None, 40);
        o.body(twist(1.0, 0.0, 0.0), Some(f32::INFINITY), 80);
        // From 0 to 80 ms at 1 m/s: the NaN frame was never there.
        near(o.pose(), 0.08, 0.0, 0.0, 1e-6);
    }
}
