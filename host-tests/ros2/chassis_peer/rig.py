"""A simulated board, the node on its pseudo-terminal and the peer, started together and torn
down together; geometry helpers over the simulator's pose."""

import contextlib
import math
import tempfile
import threading
import time
from pathlib import Path
from typing import Iterator, Optional

from . import dds, procs


class Rig:
    """The three parts of one run."""

    def __init__(self, sim: procs.Sim, node: procs.Node, peer: dds.Peer, params: Path):
        self.sim = sim
        self.node = node
        self.peer = peer
        self.params = params

    def settle(self, seconds: float) -> None:
        """Publishes zero velocity at 20 Hz for `seconds` (the chassis comes to rest)."""
        self.peer.drive(0.0, 0.0, 0.0, seconds)


@contextlib.contextmanager
def rig(
    firmware: str,
    extra: tuple = (),
    timeout: float = 0.5,
    stamped: bool = False,
    via_cli: bool = False,
) -> Iterator[Rig]:
    """Starts the simulator of `firmware`, the node on it (with `extra` arguments and
    `cmd_vel_timeout` = `timeout` in its parameters file; through `chassis ros2` with
    `via_cli`) and a peer matched with it; stops all three at the end."""
    with tempfile.TemporaryDirectory(prefix="chassis-ros2-") as tmp:
        directory = Path(tmp)
        params = procs.params(firmware, directory, timeout)
        sim = procs.Sim(firmware, directory)
        node: Optional[procs.Node] = None
        peer: Optional[dds.Peer] = None
        try:
            node = procs.Node(sim, params, extra, via_cli=via_cli)
            peer = dds.Peer(stamped=stamped)
            if not peer.wait_matched(10.0, ["/odom"]):
                raise RuntimeError(
                    "the peer and the node did not match on /cmd_vel and /odom within 10 s; "
                    f"node's stderr:\n{node.stderr()}"
                )
            yield Rig(sim, node, peer, params)
        finally:
            if peer is not None:
                peer.close()
            if node is not None:
                node.kill()
            sim.stop()


class Repeater:
    """Publishes one `/cmd_vel` at 20 Hz on a thread until `stop()`; `last_sent` is when the
    last one went (monotonic seconds)."""

    def __init__(self, peer: dds.Peer, vx: float = 0.0, vy: float = 0.0, wz: float = 0.0):
        self._peer = peer
        self._command = (vx, vy, wz)
        self._stop = threading.Event()
        self.last_sent = 0.0
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            self._peer.send(*self._command)
            self.last_sent = time.monotonic()
            self._stop.wait(0.05)

    def stop(self) -> float:
        """Stops publishing; returns when the last `/cmd_vel` went."""
        self._stop.set()
        self._thread.join()
        return self.last_sent


def wrap(angle: float) -> float:
    """`angle` brought into [-π, π)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def body_delta(before: procs.Pose, after: procs.Pose) -> tuple[float, float, float]:
    """The motion from `before` to `after` in `before`'s body frame: forward, left (m), turn
    (rad, CCW)."""
    dx, dy = after.x - before.x, after.y - before.y
    c, s = math.cos(before.yaw), math.sin(before.yaw)
    return c * dx + s * dy, -s * dx + c * dy, wrap(after.yaw - before.yaw)
