"""A teleoperation node shaped as a ROS 2 node holds the chassis, runnable without ROS.

`ChassisNode` is what an `rclpy.node.Node` subclass would hold: a `cmd_vel` callback that sets
the velocity, a timer that publishes the telemetry, a watchdog that stops the chassis when
cmd_vel goes quiet for 0.5 s (as ROS 2 teleop nodes do; the driver's own failsafe stops it when
the *board* goes quiet), and `destroy_node()` that stops it. The comments say where rclpy's
calls go. Here a small executor spins it and feeds it synthetic cmd_vel messages:

    python ros2_teleop_node.py                      # a simulated 2020 board
    python ros2_teleop_node.py --firmware v1.0.0    # a simulated v1.0.0 board
    python ros2_teleop_node.py --port /dev/ttyUSB0  # a real board (it moves!)

Axes as ROS (REP 103) has them: x forward, y left, z up, angular z counter-clockwise. The board's
y is forward and its x sideways; which way its +x points is not documented: SIDEWAYS says.
"""

from __future__ import annotations

import argparse
import contextlib
import time
from typing import Callable

import chassis

CMD_VEL_TIMEOUT_S = 0.5
# The board's +x taken as the chassis's right, so ROS's +y (left) is -x: flip it if the chassis
# strafes the wrong way.
SIDEWAYS = -1
# 2020 velocities are raw units (the 2020 spec states no unit, its A8, nor which way +z turns).
# This node takes 1 raw unit as 1 mm/s and 1 mrad/s counter-clockwise, as v1.0.0's wire units
# are: measure your chassis and change these (a negative factor flips a direction).
RAW_PER_M_S = 1000.0
RAW_PER_RAD_S = 1000.0

Publish = Callable[[str, str], None]


class ChassisNode:
    def __init__(self, bot: chassis.Chassis | chassis.ChassisV1, publish: Publish) -> None:
        # rclpy: super().__init__("chassis"); then the port and rates from declare_parameter().
        self.bot = bot
        self.publish = publish
        self.last_cmd_vel = time.monotonic()
        self.stopped_by_watchdog = False
        # rclpy: self.create_subscription(Twist, "cmd_vel", self.on_cmd_vel_msg, 10)
        #        with on_cmd_vel_msg(msg) calling self.on_cmd_vel(msg.linear.x, msg.linear.y,
        #        msg.angular.z).
        # rclpy: self.imu_pub = self.create_publisher(Imu, "imu/data_raw", 10), and one per
        #        topic below ("wheel_encoders", "battery_state", "odom_velocity").
        # rclpy: self.create_timer(0.5, self.on_telemetry_timer)
        # rclpy: self.create_timer(0.1, self.on_watchdog_timer)

    def on_cmd_vel(self, linear_x: float, linear_y: float, angular_z: float) -> None:
        """A Twist: m/s forward and left, rad/s counter-clockwise."""
        self.last_cmd_vel = time.monotonic()
        self.stopped_by_watchdog = False
        sideways = SIDEWAYS * linear_y
        if isinstance(self.bot, chassis.ChassisV1):
            self.bot.set_velocity(vx=sideways, vy=linear_x, wz=angular_z)
        else:
            self.bot.set_velocity(
                x=round(sideways * RAW_PER_M_S),
                y=round(linear_x * RAW_PER_M_S),
                z=round(angular_z * RAW_PER_RAD_S),
            )

    def on_watchdog_timer(self) -> None:
        quiet = time.monotonic() - self.last_cmd_vel
        if quiet > CMD_VEL_TIMEOUT_S and not self.stopped_by_watchdog:
            self.bot.stop()
            self.stopped_by_watchdog = True
            self.publish("~/status", f"no cmd_vel for {quiet:.2f} s: stopped")

    def on_telemetry_timer(self) -> None:
        # Take in every frame that arrived (a real node could publish each); publish the latest.
        while self.bot.poll() is not None:
            pass
        if isinstance(self.bot, chassis.ChassisV1):
            t = self.bot.telemetry
            if t is not None:
                vx, vy, wz = t.velocity  # mm/s, mm/s, mrad/s
                self.publish(
                    "odom_velocity",
                    f"forward {vy / 1000:+.3f} m/s, left {SIDEWAYS * vx / 1000:+.3f} m/s, "
                    f"turn {wz / 1000:+.3f} rad/s, yaw {t.yaw_degrees:+.1f}°",
                )
                self.publish("battery_state", f"{t.battery_mv / 1000:.2f} V")
            return
        imu, encoders, battery = self.bot.imu, self.bot.encoders, self.bot.battery
        if imu is not None:
            self.publish("imu/data_raw", f"accel {imu.accel}, gyro {imu.gyro} (raw)")
        if encoders is not None:
            self.publish("wheel_encoders", f"{encoders.ticks} (raw)")
        if battery is not None:
            self.publish("battery_state", f"{battery.centivolts / 100:.2f} V, {battery.percent} %")

    def destroy_node(self) -> None:
        # rclpy: then super().destroy_node().
        self.bot.close()  # stops the chassis first


class Executor:
    """A stand-in for rclpy's executor: runs timer callbacks on time, in one thread."""

    def __init__(self) -> None:
        self.timers: list[tuple[float, Callable[[], None]]] = []

    def create_timer(self, period_s: float, callback: Callable[[], None]) -> None:
        self.timers.append((period_s, callback))

    def spin_for(self, seconds: float) -> None:
        start = time.monotonic()
        due = [start] * len(self.timers)
        while time.monotonic() - start < seconds:
            for i, (period_s, callback) in enumerate(self.timers):
                if time.monotonic() >= due[i]:
                    callback()
                    due[i] += period_s
            time.sleep(max(0.0, min(due) - time.monotonic()))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--port", help="the board's serial port (default: a simulated board)")
    parser.add_argument("--firmware", choices=["2020", "v1.0.0"], help="default: detected")
    args = parser.parse_args()

    start = time.monotonic()

    def publish(topic: str, message: str) -> None:
        # rclpy: self.<topic>_pub.publish(msg) with the message filled in.
        print(f"[{time.monotonic() - start:5.2f}] {topic}: {message}")

    # A teleop script: forward, then a turn, then cmd_vel stops coming (a dropped joystick).
    def teleop() -> None:
        t = time.monotonic() - start
        if t < 1.5:
            node.on_cmd_vel(0.2, 0.0, 0.0)
        elif t < 2.5:
            node.on_cmd_vel(0.0, 0.0, 0.5)

    with contextlib.ExitStack() as stack:
        port = args.port
        if port is None:
            port = stack.enter_context(chassis.sim.pty(args.firmware or "2020")).path
        node = ChassisNode(chassis.open(port, firmware=args.firmware), publish)
        try:
            executor = Executor()
            executor.create_timer(0.1, teleop)  # the joystick's cmd_vel, 10 Hz
            executor.create_timer(0.1, node.on_watchdog_timer)
            executor.create_timer(0.5, node.on_telemetry_timer)
            executor.spin_for(4.0)
        finally:
            node.destroy_node()
    print("node destroyed: chassis stopped and closed")


if __name__ == "__main__":
    main()
