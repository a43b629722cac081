"""Drive a square (forward, sideways, back, sideways back), turn, stop; log the telemetry.

Works with either firmware: on a 2020 board it logs the IMU's gyro, the encoders (raw: the
2020 spec does not say whether they are running totals or counts per period) and the battery;
on a v1.0.0 board the measured velocity, the yaw and the battery. Without --port it serves a
simulated board itself, so it runs on any laptop:

    python drive_and_log.py                       # a simulated 2020 board
    python drive_and_log.py --firmware v1.0.0     # a simulated v1.0.0 board
    python drive_and_log.py --port /dev/ttyUSB0   # a real board (firmware detected)

The chassis stops when the `with` block ends, whatever ends it (Ctrl-C included).
"""

from __future__ import annotations

import argparse
import contextlib
import time

import chassis

# Each leg: name, seconds, the 2020 velocity (x sideways, y forward, z rotation: raw units),
# the v1.0.0 velocity (vx sideways, vy forward: m/s; wz: rad/s).
LEGS: list[tuple[str, float, tuple[int, int, int], tuple[float, float, float]]] = [
    ("forward", 1.0, (0, 300, 0), (0.0, 0.2, 0.0)),
    ("sideways", 1.0, (300, 0, 0), (0.2, 0.0, 0.0)),
    ("back", 1.0, (0, -300, 0), (0.0, -0.2, 0.0)),
    ("sideways back", 1.0, (-300, 0, 0), (-0.2, 0.0, 0.0)),
    ("turn", 1.0, (0, 0, 300), (0.0, 0.0, 0.5)),
    ("stop", 0.5, (0, 0, 0), (0.0, 0.0, 0.0)),
]
PERIOD_S = 0.05  # the control loop: 20 Hz
LOG_EVERY_S = 0.5


def log_2020(bot: chassis.Chassis, t: float, leg: str, frames: int) -> None:
    imu, encoders, battery = bot.imu, bot.encoders, bot.battery
    print(
        f"{t:5.2f} s  {leg:<13}  {frames:3d} frames  gyro {imu.gyro if imu else '-'}  "
        f"encoders {encoders.ticks if encoders else '-'}  "
        f"battery {battery.centivolts / 100 if battery else '-'} V"
    )


def log_v1(bot: chassis.ChassisV1, t: float, leg: str, frames: int) -> None:
    tm = bot.telemetry
    if tm is None:
        print(f"{t:5.2f} s  {leg:<13}  no telemetry yet")
        return
    vx, vy, wz = (v / 1000 for v in tm.velocity)
    print(
        f"{t:5.2f} s  {leg:<13}  {frames:2d} frames  vx {vx:+.3f} m/s  vy {vy:+.3f} m/s  "
        f"wz {wz:+.3f} rad/s  yaw {tm.yaw_degrees:+6.1f}°  battery {tm.battery_mv / 1000} V"
    )


def drive(bot: chassis.Chassis | chassis.ChassisV1) -> None:
    start = time.monotonic()
    next_log = start + LOG_EVERY_S
    frames = 0  # frames received since the last log line
    for leg, seconds, raw, si in LEGS:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if isinstance(bot, chassis.Chassis):
                bot.set_velocity(*raw)
            else:
                bot.set_velocity(*si)
            # Every frame that arrived; the driver also keeps the latest of each stream.
            while bot.poll() is not None:
                frames += 1
            now = time.monotonic()
            if now >= next_log:
                if isinstance(bot, chassis.Chassis):
                    log_2020(bot, now - start, leg, frames)
                else:
                    log_v1(bot, now - start, leg, frames)
                frames = 0
                next_log += LOG_EVERY_S
            time.sleep(PERIOD_S)
    print("streams:", bot.streams)
    print("counters:", bot.counters, " failsafe stops:", bot.failsafe_stops)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--port", help="the board's serial port (default: a simulated board)")
    parser.add_argument(
        "--firmware",
        choices=["2020", "v1.0.0"],
        help="the board's firmware (default: detected; the simulated board runs 2020)",
    )
    args = parser.parse_args()
    with contextlib.ExitStack() as stack:
        port = args.port
        if port is None:
            port = stack.enter_context(chassis.sim.pty(args.firmware or "2020")).path
        with chassis.open(port, firmware=args.firmware) as bot:
            print(f"{bot!r} on {bot.port}")
            drive(bot)
    print("stopped and closed")


if __name__ == "__main__":
    main()
