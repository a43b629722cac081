"""Shared fixtures: each firmware generation in turn, a simulated board of either firmware on a
pseudo-terminal (the real OS serial stack), and the frames the board must receive, written by
hand from the spec's tables."""

from __future__ import annotations

import signal
import time
from typing import Callable, Iterator

import pytest

import chassis

# A test run started in the background of a non-interactive shell (`cmd &` in a CI script)
# inherits SIGINT ignored, and so would every program the tests start: Python then never raises
# KeyboardInterrupt in them, and the tests of what Ctrl-C does could not be run. A handler here
# (not "ignore") is reset to the default in each program started, as a terminal would give it.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

# 2020 firmware, table 1A: velocity mode, X = Y = Z = 0, no direction bits.
STOP = bytes.fromhex("FF FE 01 00 00 00 00 00 00 00")
# 1A: Y = 300 (0x012C).
FORWARD = bytes.fromhex("FF FE 01 00 00 01 2C 00 00 00")
# 1A, angle mode (dir bit 4): +90.0° (900 = 0x0384).
TURN_90 = bytes.fromhex("FF FE 01 00 00 00 00 03 84 10")
# v1.0.0: 0x25 forced stop (ctl 0, all zeros; BCC 7B ^ 25 = 5E).
FORCED_STOP = bytes.fromhex("7B 25 00 00 00 00 00 00 00 00 00 00 5E 7D")
# v1.0.0: 0x25, vy = 300 mm/s (01 2C), ctl 2, type 4; BCC 7B^25^02^04^01^2C = 75.
V1_FORWARD = bytes.fromhex("7B 25 02 04 00 00 01 2C 00 00 00 00 75 7D")


# Per firmware: the frame that drives forward (the speed of `SPEEDS`), and that speed in the
# units its `set_velocity` takes (2020: raw; v1.0.0: m/s).
FORWARDS = {"2020": FORWARD, "v1.0.0": V1_FORWARD}
SPEEDS = {"2020": 300, "v1.0.0": 0.3}

# A program that drives forward in a loop on the board at `sys.argv[1]`, of firmware
# `sys.argv[2]`, and says "driving" once the chassis is open.
DRIVE = """
    import sys, time
    import chassis
    firmware = sys.argv[2]
    speed = 300 if firmware == "2020" else 0.3
    with chassis.open(sys.argv[1], firmware=firmware) as bot:
        print("driving", flush=True)
        while True:
            bot.set_velocity(0, speed, 0)
            time.sleep(0.02)
"""


@pytest.fixture(params=["2020", "v1.0.0"])
def firmware(request: pytest.FixtureRequest) -> str:
    """Each firmware generation in turn: a test that takes `firmware` runs once for each."""
    generation: str = request.param
    return generation


@pytest.fixture
def board() -> Iterator[chassis.sim.Pty]:
    with chassis.sim.pty() as b:
        yield b


@pytest.fixture
def v1_board() -> Iterator[chassis.sim.Pty]:
    with chassis.sim.pty(firmware="v1.0.0") as b:
        yield b


@pytest.fixture
def target(firmware: str, board: chassis.sim.Pty, v1_board: chassis.sim.Pty) -> chassis.sim.Pty:
    """The board of the test's `firmware` (both are served, as `board` and `v1_board`)."""
    return board if firmware == "2020" else v1_board


def frames_2020(data: bytes) -> list[bytes]:
    """The board's received bytes as 10- or 12-byte commands (by the mode byte, from the spec)."""
    out, at = [], 0
    while at < len(data):
        assert data[at : at + 2] == b"\xff\xfe", f"no frame at {at}: {data[at:at + 12].hex(' ')}"
        length = 12 if data[at + 2] in (0x02, 0x03) else 10
        out.append(data[at : at + length])
        at += length
    return out


def frames_v1(data: bytes) -> list[bytes]:
    """The board's received bytes as v1.0.0 commands (14 bytes each, `7B … 7D`, from the spec)."""
    out = [data[at : at + 14] for at in range(0, len(data), 14)]
    for at, f in enumerate(out):
        assert len(f) == 14 and f[0] == 0x7B and f[13] == 0x7D, f"no frame at {14 * at}: {f.hex(' ')}"
    return out


# The frame that stops the chassis, per firmware.
STOPS = {"2020": STOP, "v1.0.0": FORCED_STOP}


def motion(data: bytes, firmware: str) -> list[bytes]:
    """The motion frames among the board's received bytes: 2020 modes 01 (velocity, turn), 02
    and 03 (motors); v1.0.0 codes 0x25 (body velocity, the forced stop) and 0x26 (motors)."""
    if firmware == "2020":
        return [f for f in frames_2020(data) if f[2] in (0x01, 0x02, 0x03)]
    return [f for f in frames_v1(data) if f[1] in (0x25, 0x26)]


def wait_until(what: str, condition: Callable[[], bool], seconds: float = 5.0) -> float:
    """Waits for `condition`; the time it took."""
    start = time.monotonic()
    while not condition():
        assert time.monotonic() - start < seconds, f"never: {what}"
        time.sleep(0.005)
    return time.monotonic() - start
