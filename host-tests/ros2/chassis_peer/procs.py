"""The processes under test: the simulated board (`chassis sim --pty --pose FILE`) and the node
(`chassis-ros2 --port PTY`), and the simulator's pose file.

The binaries are found through `CHASSIS_BIN` and `CHASSIS_ROS2_BIN` (what `cargo xtask ros2`
sets), else in `$CARGO_TARGET_DIR/release` or the workspace's `target/release`.
"""

import os
import signal
import subprocess
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

ROOT = Path(__file__).resolve().parents[3]
"""The workspace root."""

GENERATIONS = ("2020", "v1.0.0")
"""The two firmware generations, as `--firmware` names them."""


def binary(env: str, name: str) -> Optional[Path]:
    """The binary `name`: `$env` if set, else in the release build directory; None if absent."""
    given = os.environ.get(env)
    if given:
        path = Path(given)
        return path if path.is_file() else None
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    path = target / "release" / name
    return path if path.is_file() else None


def chassis_bin() -> Optional[Path]:
    """The CLI, `chassis`."""
    return binary("CHASSIS_BIN", "chassis")


def node_bin() -> Optional[Path]:
    """The node, `chassis-ros2`."""
    return binary("CHASSIS_ROS2_BIN", "chassis-ros2")


PARAMS_2020 = """\
chassis:
  ros__parameters:
    odom_frame: odom
    base_frame: base_link
    imu_frame: imu_link
    publish_tf: true
    cmd_vel_timeout: {timeout}
    drive: mecanum
    half_wheelbase: 0.10
    half_track: 0.12
    ticks_per_meter: 1000.0
    encoder_counts: running_total
    speed_scale: 1000.0
    turn_scale: 220.0
"""
"""The node's parameters for the simulated 2020 board (its fixed geometry and raw scale)."""

PARAMS_V1 = """\
chassis:
  ros__parameters:
    odom_frame: odom
    base_frame: base_link
    imu_frame: imu_link
    publish_tf: true
    cmd_vel_timeout: {timeout}
    drive: mecanum
    half_wheelbase: 0.10
    half_track: 0.12
    ticks_per_meter: 1000.0
    encoder_counts: running_total
"""
"""The node's parameters for the simulated v1.0.0 board (mm/s and mrad/s: no scale)."""


def params(firmware: str, directory: Path, timeout: float = 0.5) -> Path:
    """Writes the node's parameters file for the simulator of `firmware` into `directory`."""
    text = (PARAMS_2020 if firmware == "2020" else PARAMS_V1).format(timeout=timeout)
    path = directory / f"params-{firmware}.yaml"
    path.write_text(text)
    return path


class _Lines:
    """A pipe's lines, kept by a thread as they come."""

    def __init__(self, pipe) -> None:
        self.lines: list[str] = []
        self.closed = False
        self._cond = threading.Condition()
        self._thread = threading.Thread(target=self._read, args=(pipe,), daemon=True)
        self._thread.start()

    def _read(self, pipe) -> None:
        for raw in iter(pipe.readline, b""):
            with self._cond:
                self.lines.append(raw.decode(errors="replace").rstrip("\n"))
                self._cond.notify_all()
        pipe.close()
        with self._cond:
            self.closed = True
            self._cond.notify_all()

    def wait(self, prefix: str, timeout: float) -> Optional[str]:
        """The first line starting with `prefix`, waiting up to `timeout` s or the pipe's end."""
        end = time.monotonic() + timeout
        with self._cond:
            while True:
                for line in self.lines:
                    if line.startswith(prefix):
                        return line
                left = end - time.monotonic()
                if left <= 0 or self.closed:
                    return None
                self._cond.wait(left)

    def text(self) -> str:
        """Everything read so far."""
        with self._cond:
            return "\n".join(self.lines)

    def join(self, timeout: float) -> None:
        """Waits up to `timeout` s for the pipe's end."""
        self._thread.join(timeout)


@dataclass
class Pose:
    """One line of the simulator's pose file: board time and the true pose (REP-103)."""

    t_ms: int
    x: float
    y: float
    yaw: float


class Sim:
    """`chassis sim --pty [--firmware F] --pose FILE`, its pseudo-terminal's path read from the
    first line of its standard output."""

    def __init__(self, firmware: str, directory: Path) -> None:
        exe = chassis_bin()
        if exe is None:
            raise FileNotFoundError("the chassis CLI is not built")
        self.pose_file = directory / f"pose-{firmware}.txt"
        self.firmware = firmware
        args = [str(exe), "--firmware", firmware, "sim", "--pty", "--pose", str(self.pose_file)]
        self.args = args
        self.proc = subprocess.Popen(
            args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL
        )
        self.out = _Lines(self.proc.stdout)
        self.err = _Lines(self.proc.stderr)
        line = self.out.wait("/", 10.0)
        if line is None:
            self.stop()
            raise RuntimeError(
                f"`{' '.join(args)}` printed no pseudo-terminal path; stderr:\n{self.err.text()}"
            )
        self.pty = line.strip()

    def poses(self) -> list[Pose]:
        """Every complete line of the pose file so far."""
        try:
            text = self.pose_file.read_text()
        except FileNotFoundError:
            return []
        out = []
        for line in text.splitlines(keepends=True):
            if not line.endswith("\n"):
                break
            fields = line.split()
            if len(fields) != 4:
                raise ValueError(f"pose file line {line!r} is not `t_ms x_m y_m yaw_rad`")
            out.append(Pose(int(fields[0]), float(fields[1]), float(fields[2]), float(fields[3])))
        return out

    def pose(self) -> Pose:
        """The last complete pose line, waiting up to 2 s for the first."""
        end = time.monotonic() + 2.0
        while True:
            poses = self.poses()
            if poses:
                return poses[-1]
            if time.monotonic() > end:
                raise RuntimeError(f"the simulator wrote no pose to {self.pose_file}")
            time.sleep(0.01)

    def stop(self) -> None:
        """Stops the simulator (SIGINT, then SIGKILL after 3 s)."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(3.0)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


class Node:
    """`chassis-ros2 --port PTY --firmware F --params FILE [extra…]` (or the same through
    `chassis ros2` with `via_cli`), started and awaited until it prints `ready:`."""

    def __init__(
        self,
        sim: Sim,
        params_file: Path,
        extra: tuple = (),
        ready_timeout: float = 20.0,
        via_cli: bool = False,
    ):
        exe = node_bin()
        if exe is None:
            raise FileNotFoundError("the node chassis-ros2 is not built")
        env = dict(os.environ)
        head = [str(exe)]
        if via_cli:
            # `chassis ros2 ARGS…`: the CLI runs the node found beside it or on PATH.
            cli = chassis_bin()
            if cli is None:
                raise FileNotFoundError("the chassis CLI is not built")
            head = [str(cli), "ros2"]
            env["PATH"] = f"{exe.parent}{os.pathsep}{env.get('PATH', '')}"
        args = [
            *head,
            "--port",
            sim.pty,
            "--firmware",
            sim.firmware,
            "--params",
            str(params_file),
            *extra,
        ]
        self.args = args
        self.proc = subprocess.Popen(
            args,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            stdin=subprocess.DEVNULL,
            env=env,
        )
        self.out = _Lines(self.proc.stdout)
        self.err = _Lines(self.proc.stderr)
        if self.err.wait("ready:", ready_timeout) is None:
            code = self.proc.poll()
            self.kill()
            raise RuntimeError(
                f"`{' '.join(args)}` did not print `ready:` within {ready_timeout} s "
                f"(exit {code}); stderr:\n{self.err.text()}"
            )

    def signal(self, sig: int, timeout: float = 10.0) -> int:
        """Sends `sig` and returns the exit status (a negative number: killed by that signal)."""
        self.proc.send_signal(sig)
        return self.wait(timeout)

    def wait(self, timeout: float) -> int:
        """The exit status, waiting up to `timeout` s (a negative number: killed by a signal)."""
        try:
            code = self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            raise RuntimeError(f"the node did not exit within {timeout} s")
        self.err.join(2.0)
        return code

    def kill(self) -> None:
        """Ends the node at once if it still runs."""
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        self.err.join(2.0)

    def stderr(self) -> str:
        """What the node printed on standard error so far."""
        return self.err.text()
