"""The node's figures, measured from outside (not a test: timings vary with the machine).

For each firmware generation, against its simulated board on a pseudo-terminal, in a private
network namespace:
- `/cmd_vel` received → first byte of its frame on the wire: the node's own `--stats` line
  (p50, p99, max) over COUNT commands published at RATE Hz, each with a different velocity;
- the node's CPU over those COUNT / RATE seconds: user + system time from `/proc/<pid>/stat`,
  as a share of one core, with the board's telemetry streaming and the commands going down;
and the node binary's size, stripped.

With `--segments`, instead: for each generation, the 1 m square of the tests driven with a rest
after each side and each turn, and `/odom`'s error against the simulator's pose after each.

    python bench.py [--count N] [--rate HZ] [--segments]
    (cargo xtask ros2-bench [--count N] [--rate HZ] [--segments])
"""

import argparse
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from chassis_peer import dds, msgs, netns, procs

STATS = re.compile(
    r"cmd_vel to wire: n=(\d+) p50=([\d.]+) ms p99=([\d.]+) ms max=([\d.]+) ms"
)


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of `pid` so far, seconds (`/proc/<pid>/stat` fields 14 and 15)."""
    text = Path(f"/proc/{pid}/stat").read_text()
    fields = text[text.rindex(")") + 2 :].split()
    # After "pid (comm) ", fields[0] is the state (field 3): utime is field 14, stime 15.
    ticks = int(fields[11]) + int(fields[12])
    return ticks / os.sysconf("SC_CLK_TCK")


def run(firmware: str, count: int, rate: float) -> dict:
    """One generation: the latency line and the CPU share."""
    with tempfile.TemporaryDirectory(prefix="chassis-ros2-bench-") as tmp:
        directory = Path(tmp)
        params = procs.params(firmware, directory, timeout=0.5)
        sim = procs.Sim(firmware, directory)
        node = None
        peer = None
        try:
            node = procs.Node(sim, params, ("--stats",))
            peer = dds.Peer()
            if not peer.wait_matched(10.0, ["/odom"]):
                raise RuntimeError(f"no match with the node; stderr:\n{node.stderr()}")
            time.sleep(0.5)  # matched: the node's reader knows the writer too
            cpu0, t0 = cpu_seconds(node.proc.pid), time.monotonic()
            for i in range(count):
                due = t0 + i / rate
                pause = due - time.monotonic()
                if pause > 0:
                    time.sleep(pause)
                # A different command each time: 0.100 .. 0.199 m/s, and back.
                peer.send(0.1 + (i % 100) / 1000.0, 0.0, 0.0)
            elapsed = time.monotonic() - t0
            cpu = cpu_seconds(node.proc.pid) - cpu0
            time.sleep(0.2)
            code = node.signal(signal.SIGINT)
            line = STATS.search(node.stderr())
            if line is None:
                raise RuntimeError(
                    f"no `cmd_vel to wire` line from --stats (exit {code}); stderr:\n"
                    f"{node.stderr()}"
                )
            n, p50, p99, mx = line.groups()
            return {
                "firmware": firmware,
                "n": int(n),
                "p50": float(p50),
                "p99": float(p99),
                "max": float(mx),
                "cpu": cpu / elapsed,
                "seconds": elapsed,
            }
        finally:
            if peer is not None:
                peer.close()
            if node is not None:
                node.kill()
            sim.stop()


def segments(firmware: str) -> None:
    """The square with rests: `/odom`'s error after each side and each turn, printed."""
    import math

    from chassis_peer.rig import rig

    print(f"{firmware}: /odom - simulator after each segment (x, y mm; yaw rad)")
    with rig(firmware) as r:
        r.settle(0.3)
        for i in range(4):
            for name, command, seconds in (
                (f"side {i + 1}", (0.5, 0.0, 0.0), 2.0),
                (f"turn {i + 1}", (0.0, 0.0, 1.0), math.pi / 2),
            ):
                r.peer.drive(*command, seconds=seconds)
                r.settle(0.4)
                truth = r.sim.pose()
                odom = r.peer.latest("/odom").value.pose.pose
                dyaw = msgs.yaw_of(odom.orientation) - truth.yaw
                print(
                    f"  {name}: {(odom.position.x - truth.x) * 1000:+6.1f} "
                    f"{(odom.position.y - truth.y) * 1000:+6.1f} "
                    f"{math.remainder(dyaw, 2 * math.pi):+.4f}"
                )


def stripped_size(binary: Path) -> tuple[int, int]:
    """The binary's size as built and stripped (`strip` on a copy)."""
    with tempfile.TemporaryDirectory() as tmp:
        copy = Path(tmp) / binary.name
        shutil.copyfile(binary, copy)
        subprocess.run(["strip", str(copy)], check=True)
        return binary.stat().st_size, copy.stat().st_size


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=1000, help="commands (default 1000)")
    parser.add_argument("--rate", type=float, default=100.0, help="commands a second (100)")
    parser.add_argument(
        "--segments", action="store_true", help="the square's odometry error segment by segment"
    )
    args = parser.parse_args()
    if args.count < 1 or args.rate <= 0:
        parser.error("--count and --rate must be positive")
    node_bin, chassis_bin = procs.node_bin(), procs.chassis_bin()
    if node_bin is None or chassis_bin is None:
        print(
            "bench: build chassis-ros2 and chassis first (cargo xtask ros2-bench)",
            file=sys.stderr,
        )
        return 2
    try:
        netns.enter()
    except netns.NamespaceError as e:
        print(f"bench: {e}", file=sys.stderr)
        return 2
    if args.segments:
        for firmware in procs.GENERATIONS:
            segments(firmware)
        return 0
    rows = [run(firmware, args.count, args.rate) for firmware in procs.GENERATIONS]
    built, stripped = stripped_size(node_bin)
    print(
        f"{args.count} /cmd_vel at {args.rate:g} Hz per generation, "
        "in a private network namespace"
    )
    print()
    print("| firmware | commands timed | p50 | p99 | max | node CPU (one core) |")
    print("|---|---:|---:|---:|---:|---:|")
    for r in rows:
        print(
            f"| {r['firmware']} | {r['n']} | {r['p50']:.3f} ms | {r['p99']:.3f} ms | "
            f"{r['max']:.3f} ms | {100 * r['cpu']:.1f} % over {r['seconds']:.1f} s |"
        )
    print()
    print(
        f"chassis-ros2: {stripped / 1e6:.2f} MB stripped "
        f"({built / 1e6:.1f} MB as built, with debug info)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
