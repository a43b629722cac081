"""The node (`chassis-ros2`) driven from outside by the peer, against the simulated board of each
firmware generation (`chassis sim --pty --pose FILE`), in the suite's private network namespace.
The simulator's pose file is the truth: where the simulated chassis really is."""

import math
import signal
import time

import pytest

from chassis_peer import cdr, dds, msgs, procs, report
from chassis_peer.rig import Repeater, body_delta, rig, wrap

GENERATIONS = procs.GENERATIONS

if procs.chassis_bin() is None or procs.node_bin() is None:
    pytest.skip(
        "the binaries under test are not built (chassis: "
        f"{procs.chassis_bin()}, chassis-ros2: {procs.node_bin()}): `cargo xtask ros2` builds "
        "them, or set CHASSIS_BIN and CHASSIS_ROS2_BIN",
        allow_module_level=True,
    )

SPEED = 0.25
"""m/s for the motion checks."""
TURN = 0.8
"""rad/s for the motion checks."""

HEADING_BOUND = 0.02
"""rad: how far `/odom`'s heading may end from the simulator's after the square or the circle
(both generations measure the heading: 2020 from the wheels' counts, v1.0.0 from the board's
yaw)."""

V1_TELEMETRY_S = 0.045
"""The simulated v1.0.0 board's telemetry period (its `SimConfig::telemetry_period_ms`)."""


def position_bound(firmware: str, speed: float, starts_and_stops: int) -> float:
    """m: how far `/odom`'s position may end from the simulator's after a path driven at
    `speed` whose translation starts or stops `starts_and_stops` times.

    2020: the wheels' encoder counts are positions (1 mm a tick), integrated along the arc
    between frames: 20 mm. v1.0.0: the board reports its velocity every 45 ms and the node
    integrates it (trapezoid), so where a step of velocity falls inside a period is unknown:
    each start or stop may be off by up to speed × period / 2 (11 mm at 0.5 m/s); 10 mm more
    for the rest."""
    if firmware == "2020":
        return 0.020
    return 0.010 + starts_and_stops * speed * V1_TELEMETRY_S / 2


STOP_SLACK = 0.25
"""s: how long after the cause (timeout expiry, signal) the chassis may still move."""


@pytest.mark.parametrize("firmware", GENERATIONS)
@pytest.mark.parametrize(
    "name, command, expect",
    [
        ("forward", (SPEED, 0.0, 0.0), (SPEED, 0.0, 0.0)),
        ("backward", (-SPEED, 0.0, 0.0), (-SPEED, 0.0, 0.0)),
        ("left (mecanum)", (0.0, SPEED, 0.0), (0.0, SPEED, 0.0)),
        ("rotate CCW", (0.0, 0.0, TURN), (0.0, 0.0, TURN)),
        ("rotate CW", (0.0, 0.0, -TURN), (0.0, 0.0, -TURN)),
    ],
)
def test_chassis_moves_as_commanded(firmware, name, command, expect):
    """One second of `/cmd_vel` moves the simulated chassis the commanded way: forward is +x of
    the body, left +y (the simulated boards are mecanum), CCW +yaw (REP-103), each by the
    commanded speed × 1 s within 25 %, the other axes by under 10 % of it."""
    with rig(firmware) as r:
        r.settle(0.3)
        before = r.sim.pose()
        r.peer.drive(*command, seconds=1.0)
        r.settle(0.5)
        after = r.sim.pose()
        moved = body_delta(before, after)
        seen = f"{name} on {firmware}: from {before} to {after}, body delta {moved}"
        size = max(abs(e) for e in expect)
        for axis, want, got in zip(("forward", "left", "yaw"), expect, moved):
            if want:
                assert math.copysign(1, got) == math.copysign(1, want), f"{axis} wrong way; {seen}"
                assert abs(got - want) <= 0.25 * abs(want), f"{axis} by {got}, want {want}; {seen}"
            else:
                assert abs(got) <= 0.1 * size, f"{axis} moved {got}; {seen}"


SQUARE_SPEED = 0.5
"""m/s along the square's sides and the circle."""


def _square(r) -> tuple[float, int]:
    side, turn = 1.0, 1.0
    for _ in range(4):
        r.peer.drive(SQUARE_SPEED, 0.0, 0.0, side / SQUARE_SPEED)
        r.peer.drive(0.0, 0.0, turn, (math.pi / 2) / turn)
    return 4 * side, 8


def _circle(r) -> tuple[float, int]:
    turn = 1.0
    r.peer.drive(SQUARE_SPEED, 0.0, turn, 2 * math.pi / turn)
    return 2 * math.pi * SQUARE_SPEED / turn, 2


def _longest_gap(samples: list) -> float:
    """The longest time between consecutive header stamps, s (a node that stalled shows it)."""
    stamps = [s.value.header.stamp.sec + s.value.header.stamp.nanosec * 1e-9 for s in samples]
    return max((b - a for a, b in zip(stamps, stamps[1:])), default=0.0)


@pytest.mark.parametrize("firmware", GENERATIONS)
@pytest.mark.parametrize("path", ["1 m square", "circle r 0.5 m"])
def test_odometry_ends_near_the_true_pose(firmware, path):
    """After a 1 m square (0.5 m/s sides, 1 rad/s turns in place) or a full circle (0.5 m/s,
    1 rad/s), then rest, `/odom`'s pose lies within `position_bound` and HEADING_BOUND of the
    simulator's own pose; `/tf` carries the same pose, odom → base_link."""
    with rig(firmware) as r:
        r.settle(0.3)
        start = r.sim.pose()
        length, starts_and_stops = _square(r) if path.endswith("square") else _circle(r)
        bound = position_bound(firmware, SQUARE_SPEED, starts_and_stops)
        stopped_at = time.monotonic()
        r.settle(0.6)
        truth = r.sim.pose()
        odom = r.peer.wait_for("/odom", 2.0, since=stopped_at + 0.4)
        assert odom is not None, f"no /odom after the run; node's stderr:\n{r.node.stderr()}"
        o = odom.value
        pose = o.pose.pose
        yaw = msgs.yaw_of(pose.orientation)
        pos_err = math.hypot(pose.position.x - truth.x, pose.position.y - truth.y)
        head_err = abs(wrap(yaw - truth.yaw))
        report.drift.append((firmware, path, pos_err, head_err, length, bound))
        seen = (
            f"{path} on {firmware}: simulator from {start} to {truth}; /odom at "
            f"({pose.position.x:.4f}, {pose.position.y:.4f}, yaw {yaw:.4f}); the longest gap "
            f"between /odom stamps {_longest_gap(r.peer.samples('/odom')) * 1000:.0f} ms"
        )
        assert (o.header.frame_id, o.child_frame_id) == ("odom", "base_link"), seen
        assert pos_err <= bound, f"position off by {pos_err:.4f} m (bound {bound} m); {seen}"
        assert head_err <= HEADING_BOUND, f"heading off by {head_err:.4f} rad; {seen}"
        tf = r.peer.wait_for("/tf", 2.0, since=stopped_at + 0.4)
        assert tf is not None, "no /tf after the run"
        (t,) = [t for t in tf.value.transforms if t.child_frame_id == "base_link"]
        assert t.header.frame_id == "odom", t
        tf_err = math.hypot(
            t.transform.translation.x - truth.x, t.transform.translation.y - truth.y
        )
        assert tf_err <= bound, f"/tf off by {tf_err:.4f} m; {t}"
        tf_yaw = msgs.yaw_of(t.transform.rotation)
        assert abs(wrap(tf_yaw - truth.yaw)) <= HEADING_BOUND, f"/tf yaw {tf_yaw}; {seen}"


def _key(pose: procs.Pose) -> tuple:
    return (pose.x, pose.y, pose.yaw)


def _moving(r, seen: str) -> tuple:
    """Asserts that the simulated chassis moves (its pose changes over 60 ms); its last pose."""
    before = r.sim.pose()
    time.sleep(0.06)
    now = r.sim.pose()
    assert _key(now) != _key(before), f"the chassis is not moving ({now}); {seen}"
    return _key(now)


def _stopped_after(r, cause: float, last: tuple, seen: str) -> float:
    """Watches the simulator's pose for 1.2 s after `cause` (monotonic seconds), `last` the pose
    read just before it, and returns how long after `cause` the pose was first seen at its final
    value (polled every 5 ms; the simulator writes a line every 10 ms; 0 if it never changed
    after `cause`). Asserts that the pose then stays unchanged for at least 0.7 s."""
    seen_at = cause
    changes = []
    while time.monotonic() < cause + 1.2:
        pose = r.sim.pose()
        if _key(pose) != last:
            last, seen_at = _key(pose), time.monotonic()
            changes.append(f"{seen_at - cause:+.3f} s {pose}")
        time.sleep(0.005)
    still = time.monotonic() - seen_at
    assert still >= 0.7, (
        f"still moving {still:.3f} s before the end of the watch; poses seen after the cause:\n"
        + "\n".join(changes[-12:])
        + f"\n{seen}"
    )
    return seen_at - cause


@pytest.mark.parametrize("firmware", GENERATIONS)
def test_cmd_vel_silence_stops_the_chassis(firmware):
    """With `--cmd-vel-timeout 0.3`, the chassis driven at 20 Hz keeps moving past 0.15 s of
    silence (the node waits for the timeout, not for the next command) and stops within the
    timeout + STOP_SLACK of the last `/cmd_vel`."""
    timeout = 0.3
    with rig(firmware, extra=("--cmd-vel-timeout", str(timeout))) as r:
        r.settle(0.3)
        driver = Repeater(r.peer, SPEED, 0.0, 0.0)
        time.sleep(1.0)
        seen = f"{firmware}, node stderr:\n{r.node.stderr()}"
        last = _moving(r, seen)
        last_sent = driver.stop()
        after = _stopped_after(r, last_sent, last, seen)
        report.stops.append((firmware, f"/cmd_vel silent ({timeout} s timeout)", after * 1000))
        assert after >= 0.15, f"stopped {after:.3f} s after the last /cmd_vel, before its timeout"
        assert after <= timeout + STOP_SLACK, f"stopped {after:.3f} s after the last /cmd_vel"


@pytest.mark.parametrize("firmware", GENERATIONS)
@pytest.mark.parametrize(
    "sig, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143), (signal.SIGHUP, 129)],
    ids=["SIGINT", "SIGTERM", "SIGHUP"],
)
def test_signal_stops_the_chassis(firmware, sig, status):
    """A signal to the node while `/cmd_vel` keeps coming stops the chassis within STOP_SLACK of
    the signal (the cmd_vel timeout is 5 s, so it is the signal that stops it) and the node
    exits with 128 + the signal's number."""
    _signal_stops(firmware, sig, status, via_cli=False)


@pytest.mark.parametrize("firmware", GENERATIONS)
def test_chassis_ros2_runs_the_node(firmware):
    """`chassis ros2 ARGS…` runs the same node: it drives the chassis, and SIGTERM to the
    `chassis` process stops it and ends it with the node's status, 143."""
    _signal_stops(firmware, signal.SIGTERM, 143, via_cli=True)


def _signal_stops(firmware: str, sig: int, status: int, via_cli: bool) -> None:
    with rig(firmware, timeout=5.0, via_cli=via_cli) as r:
        driver = Repeater(r.peer, SPEED, 0.0, 0.0)
        time.sleep(0.8)
        last = _moving(r, firmware)
        signalled = time.monotonic()
        r.node.proc.send_signal(sig)
        after = _stopped_after(r, signalled, last, f"{firmware}, node stderr:\n{r.node.stderr()}")
        code = r.node.wait(5.0)
        driver.stop()
        name = signal.Signals(sig).name + (" to `chassis ros2`" if via_cli else "")
        if not via_cli:
            report.stops.append((firmware, name, after * 1000))
        assert code == status, f"exit status {code}, want {status}; stderr:\n{r.node.stderr()}"
        assert after <= STOP_SLACK, f"stopped {after:.3f} s after {name}"


@pytest.mark.parametrize("firmware", GENERATIONS)
def test_every_message_equals_the_independent_encoder(firmware):
    """Every sample of each topic as the node put it on the wire (raw CDR) over about 1.5 s of
    driving equals `rosbags` serializing the same field values; decoded with the declared types
    and re-encoded by Cyclone DDS it gives the same bytes again (round trip). The frames and
    units ROS expects are checked on the way."""
    with rig(firmware) as r:
        driver = Repeater(r.peer, SPEED, 0.1, 0.3)
        since = time.monotonic()
        got = {t: r.peer.wait_for(t, 3.0, since=since + 0.5) for t in dds.PUBLISHED}
        driver.stop()
        missing = [t for t, s in got.items() if s is None]
        assert not missing, f"nothing on {missing}; node's stderr:\n{r.node.stderr()}"
        for topic in dds.PUBLISHED:
            samples = r.peer.samples(topic, since)
            for sample in samples:
                value = sample.value
                mismatch = cdr.wire_mismatch(sample.raw, cdr.rosbags_bytes(value))
                assert mismatch is None, f"{topic} on {firmware}: {mismatch}\n value {value}"
                mismatch = cdr.wire_mismatch(sample.raw, value.serialize())
                assert mismatch is None, f"{topic} on {firmware} (round trip): {mismatch}"
        odom = r.peer.latest("/odom").value
        assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_link")
        assert odom.twist.twist.linear.x > 0.0, f"driving forward, /odom says {odom.twist}"
        imu = got["/imu/data_raw"].value
        assert imu.header.frame_id == "imu_link", imu.header
        battery = got["/battery_state"].value
        assert 5.0 < battery.voltage < 30.0, f"battery {battery.voltage} V"
        assert battery.present
        diagnostics = got["/diagnostics"].value
        assert diagnostics.status, "an empty DiagnosticArray"


@pytest.mark.parametrize("firmware", GENERATIONS)
def test_stamped_and_no_tf(firmware):
    """With `--stamped --no-tf`, `TwistStamped` commands drive the chassis forward and nothing
    comes on `/tf` while `/odom` does."""
    with rig(firmware, extra=("--stamped", "--no-tf"), stamped=True) as r:
        before = r.sim.pose()
        since = time.monotonic()
        r.peer.drive(SPEED, 0.0, 0.0, seconds=1.0)
        r.settle(0.3)
        forward, _, _ = body_delta(before, r.sim.pose())
        assert forward > 0.5 * SPEED, f"moved {forward} m forward on TwistStamped"
        assert r.peer.samples("/odom", since), "no /odom"
        assert not r.peer.samples("/tf"), "/tf published with --no-tf"
