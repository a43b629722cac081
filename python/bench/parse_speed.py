"""Benchmark (not a test): the package's parsers against pure-Python ones, and the CPU cost of a
115 200 bps link through `Chassis.poll()`.

(a) Parse speed: 1 MB of a 2020 board's stream through `chassis.DownlinkParser().feed()`, beside
    pure-Python parsers of the same frames written here as people write them next to pyserial
    (header, length by kind, count; no resynchronisation rules), one with bytes.find and struct,
    one a byte at a time; then 1 MB of v1.0.0 telemetry through `chassis.V1DownlinkParser`
    beside the same two in pure Python for v1 (header, length by code, BCC, end byte). All fed
    the same chunks in the same run, taking turns, best of 5; MB/s and the ratios.
(b) CPU cost: a simulated 2020 board served in another process (its real rates: 1 782 bytes/s,
    126 frames/s), opened with `chassis.open`, polled for 10 s as a program would (poll until
    None, then sleep 5 ms); the CPU time of this process (every thread: the driver's pump too)
    as a % of one core. Beside it, the same loop with no chassis, and the chassis open with the
    program idle, to show where the time goes. Three rounds, each figure and its median.

    python parse_speed.py           # the full run: about 2 minutes
    python parse_speed.py --quick   # a smaller, shorter run, to try it
"""

from __future__ import annotations

import argparse
import multiprocessing
import statistics
import struct
import time
from multiprocessing.connection import Connection
from typing import Callable, Protocol, Sequence

import chassis

MB = 1_000_000
CHUNK = 4096  # bytes per feed() call, both parsers alike


# ----- streams -----


def stream_2020(size: int) -> bytes:
    """What a 2020 board sends: IMU 100 Hz, encoders 25 Hz, battery 1 Hz, each with its rolling
    count. Made by the package's simulated board (the downlink frame classes have no
    constructor), one second at a time."""
    board = chassis.sim.Board("2020")
    chunks, total, now_ms = [], 0, 0
    while total < size:
        now_ms += 1000
        board.advance(now_ms)
        chunks.append(board.transmit())
        total += len(chunks[-1])
    return b"".join(chunks)


def stream_v1(size: int) -> bytes:
    """v1.0.0 telemetry frames, encoded by `chassis.Telemetry`, their values changing."""
    frames = []
    for i in range((size + 31) // 32):
        frames.append(
            chassis.Telemetry(
                velocity=(i % 400 - 200, 0, i % 100),
                accel=(i % 7 - 3, i % 5 - 2, 1000),
                gyro=(i % 3 - 1, 0, i % 100),
                quaternion=(1000, 0, 0, i % 50),
                battery_mv=12_000 - i // 1000,
            ).encode()
        )
    return b"".join(frames)


# ----- pure-Python parsers -----

KINDS_2020 = {
    0xFA: (15, "imu", struct.Struct(">6hB")),
    0xFB: (11, "encoders", struct.Struct(">4hB")),
    0xFC: (7, "battery", struct.Struct(">HHB")),
}


class PyFind2020:
    """`FF`, a kind byte that gives the length, the fields and the count: no resync rules.
    Searches with bytes.find and unpacks with struct: pure Python at its fastest."""

    def __init__(self) -> None:
        self.buf = b""

    def feed(self, data: bytes) -> list[tuple[str, tuple[int, ...]]]:
        buf = self.buf + data
        end, i, frames = len(buf), 0, []
        while True:
            i = buf.find(b"\xff", i)
            if i < 0:
                i = end
                break
            if i + 1 >= end:
                break
            kind = KINDS_2020.get(buf[i + 1])
            if kind is None:
                i += 1
                continue
            length, name, layout = kind
            if i + length > end:
                break
            frames.append((name, layout.unpack_from(buf, i + 2)))
            i += length
        self.buf = buf[i:]
        return frames


class PyBytewise2020:
    """The same, a byte at a time, as a loop over `serial.read(1)` does: the common way."""

    def __init__(self) -> None:
        self.frame = bytearray()
        self.length = 0

    def feed(self, data: bytes) -> list[tuple[str, tuple[int, ...]]]:
        frames = []
        frame = self.frame
        for byte in data:
            if not frame:
                if byte == 0xFF:
                    frame.append(byte)
            elif len(frame) == 1:
                kind = KINDS_2020.get(byte)
                if kind is not None:
                    self.length = kind[0]
                    frame.append(byte)
                elif byte != 0xFF:
                    frame.clear()
            else:
                frame.append(byte)
                if len(frame) == self.length:
                    _, name, layout = KINDS_2020[frame[1]]
                    frames.append((name, layout.unpack_from(frame, 2)))
                    frame.clear()
        return frames


V1_TELEMETRY = struct.Struct(">14h")  # velocity 3, accel 3, gyro 3, quaternion 4, battery
V1_REPLY_CODES = {0x33, 0x34, 0x35, 0x36, 0x50}


class PyFindV1:
    """`7B`, a code that gives the length (32 telemetry, 14 a reply), BCC (XOR) and `7D`, with
    bytes.find and struct."""

    def __init__(self) -> None:
        self.buf = b""

    def feed(self, data: bytes) -> list[tuple[str, object]]:
        buf = self.buf + data
        end, i = len(buf), 0
        frames: list[tuple[str, object]] = []
        while True:
            i = buf.find(b"\x7b", i)
            if i < 0:
                i = end
                break
            if i + 1 >= end:
                break
            code = buf[i + 1]
            length = 32 if code == 0 else 14 if code in V1_REPLY_CODES else 0
            if length == 0:
                i += 1
                continue
            if i + length > end:
                break
            bcc = 0
            for byte in buf[i : i + length - 2]:
                bcc ^= byte
            if bcc != buf[i + length - 2] or buf[i + length - 1] != 0x7D:
                i += 1
                continue
            if code == 0:
                frames.append(("telemetry", V1_TELEMETRY.unpack_from(buf, i + 2)))
            else:
                frames.append(("reply", (code, buf[i + 2 : i + 12])))
            i += length
        self.buf = buf[i:]
        return frames


class PyBytewiseV1:
    """The same, a byte at a time."""

    def __init__(self) -> None:
        self.frame = bytearray()
        self.length = 0

    def feed(self, data: bytes) -> list[tuple[str, object]]:
        frames: list[tuple[str, object]] = []
        frame = self.frame
        for byte in data:
            if not frame:
                if byte == 0x7B:
                    frame.append(byte)
            elif len(frame) == 1:
                self.length = 32 if byte == 0 else 14 if byte in V1_REPLY_CODES else 0
                if self.length:
                    frame.append(byte)
                elif byte != 0x7B:
                    frame.clear()
            else:
                frame.append(byte)
                if len(frame) == self.length:
                    bcc = 0
                    for b in frame[:-2]:
                        bcc ^= b
                    if bcc == frame[-2] and frame[-1] == 0x7D:
                        if frame[1] == 0:
                            frames.append(("telemetry", V1_TELEMETRY.unpack_from(frame, 2)))
                        else:
                            frames.append(("reply", (frame[1], bytes(frame[2:12]))))
                    frame.clear()
        return frames


# ----- (a) -----


class Parser(Protocol):
    def feed(self, data: bytes) -> Sequence[object]: ...


def one_run(make: Callable[[], Parser], chunks: list[bytes]) -> tuple[float, int]:
    """A new parser over every chunk: the seconds it took and the frames it found."""
    parser = make()
    start = time.perf_counter()
    found = sum(len(parser.feed(chunk)) for chunk in chunks)
    return time.perf_counter() - start, found


def parse_speed(size: int, repeat: int) -> None:
    print(f"(a) parse speed: {size / MB:g} MB per stream, fed in {CHUNK}-byte chunks, best of {repeat}")
    print("    (ratio: how many times longer than the chassis parser)")
    print(f"    {'stream':<24}{'parser':<30}{'frames':>9}{'MB/s':>9}{'ratio':>8}")
    cases: list[tuple[str, bytes, list[tuple[str, Callable[[], Parser]]]]] = [
        (
            "2020 (IMU/enc/battery)",
            stream_2020(size),
            [
                ("chassis.DownlinkParser", chassis.DownlinkParser),
                ("pure Python: find + struct", PyFind2020),
                ("pure Python: byte by byte", PyBytewise2020),
            ],
        ),
        (
            "v1.0.0 (telemetry)",
            stream_v1(size),
            [
                ("chassis.V1DownlinkParser", chassis.V1DownlinkParser),
                ("pure Python: find + struct", PyFindV1),
                ("pure Python: byte by byte", PyBytewiseV1),
            ],
        ),
    ]
    for stream, data, parsers in cases:
        chunks = [data[i : i + CHUNK] for i in range(0, len(data), CHUNK)]
        # The parsers take turns, so that a change in the machine's load hits them alike.
        best = [float("inf")] * len(parsers)
        frames = [0] * len(parsers)
        for _ in range(repeat):
            for k, (_, make) in enumerate(parsers):
                seconds, frames[k] = one_run(make, chunks)
                best[k] = min(best[k], seconds)
        for k, (name, _) in enumerate(parsers):
            speed = len(data) / MB / best[k]
            ratio = f"{best[k] / best[0]:.1f}x" if k else ""
            print(f"    {stream:<24}{name:<30}{frames[k]:>9,}{speed:>9.1f}{ratio:>8}")
            stream = ""


# ----- (b) -----


def serve_board(conn: Connection) -> None:
    """The child process: a simulated 2020 board on a pseudo-terminal; answers "cpu" with its
    CPU time so far, ends at "stop"."""
    with chassis.sim.pty("2020") as board:
        conn.send(board.path)
        while conn.recv() == "cpu":
            conn.send(time.process_time())


def cpu_share(seconds: float, body: Callable[[float], int]) -> tuple[float, int]:
    """This process's CPU time while `body(end)` runs until `end`, as % of one core."""
    cpu, wall = time.process_time(), time.monotonic()
    frames = body(wall + seconds)
    return 100 * (time.process_time() - cpu) / (time.monotonic() - wall), frames


def poll_loop(bot: chassis.Chassis | None) -> Callable[[float], int]:
    def run(end: float) -> int:
        frames = 0
        while time.monotonic() < end:
            if bot is not None:
                while bot.poll() is not None:
                    frames += 1
            time.sleep(0.005)
        return frames

    return run


def idle(end: float) -> int:
    time.sleep(max(0.0, end - time.monotonic()))
    return 0


def link_cost(seconds: float, rounds: int) -> None:
    ctx = multiprocessing.get_context("spawn")
    conn, child_conn = ctx.Pipe()
    child = ctx.Process(target=serve_board, args=(child_conn,), daemon=True)
    child.start()
    path = conn.recv()

    def board_cpu() -> float:
        conn.send("cpu")
        cpu: float = conn.recv()
        return cpu

    print(
        f"(b) CPU cost of a 115 200 bps 2020 link, the simulated board in another process, "
        f"{seconds:g} s each, {rounds} rounds (this machine is shared: judge the median)"
    )
    names = [
        "the loop alone: sleep 5 ms, no chassis",
        "chassis open, the program asleep (the pump thread)",
        "chassis open, poll until None then sleep 5 ms",
        "  the chassis's share (the row above less the loop alone)",
        "  (the simulated board's process meanwhile)",
    ]
    shares: list[list[float]] = [[] for _ in names]
    frames = lost = 0
    for _ in range(rounds):
        alone, _ = cpu_share(seconds, poll_loop(None))
        with chassis.open(path, firmware="2020") as bot:
            assert isinstance(bot, chassis.Chassis)
            time.sleep(0.5)
            asleep, _ = cpu_share(seconds, idle)
            while bot.poll() is not None:
                pass
            before, not_polled = board_cpu(), bot.counters["not_polled"]
            polled, count = cpu_share(seconds, poll_loop(bot))
            board = 100 * (board_cpu() - before) / seconds
            frames += count
            lost += bot.counters["not_polled"] - not_polled
        for row, share in zip(shares, [alone, asleep, polled, polled - alone, board]):
            row.append(share)
    conn.send("stop")
    child.join()
    print(f"    {'what':<60}{'median':>8}   each round (CPU % of a core)")
    for what, row in zip(names, shares):
        each = ", ".join(f"{x:.2f}" for x in row)
        print(f"    {what:<60}{statistics.median(row):>7.2f}%   {each}")
    whole = statistics.median(shares[2])
    print(f"    frames polled: {frames:,}; dropped while polled (nobody took them): {lost}")
    print(
        f"    a whole link through poll(): {whole:.2f} % of a core, median "
        f"(goal under 1 %: {'met' if whole < 1.0 else 'NOT MET'})"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="100 kB, 2 runs, 2 s")
    args = parser.parse_args()
    parse_speed(MB // 10 if args.quick else MB, 2 if args.quick else 5)
    print()
    link_cost(2.0 if args.quick else 10.0, 1 if args.quick else 3)


if __name__ == "__main__":
    main()
