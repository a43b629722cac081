"""Inputs with limits and checks: a number out of its range, however large, is a `ValueError` that
names it, with nothing sent; a write whose read-back never confirms it is the same error on both
generations; a v1.0.0 restore refuses a key that is none of its fields; `open()` refuses limits
it cannot work with; the simulated board's clock moves a bounded step and hears Ctrl-C."""

from __future__ import annotations

import re
import subprocess
import sys
import textwrap
import threading
import time
from typing import Callable

import pytest

import chassis
from conftest import frames_2020, frames_v1, wait_until

HUGE = 2**64
HUGER = 10**400  # too large even for a float

# (what is called, the name the message must give)
FRAMES: list[tuple[Callable[[], object], str]] = [
    (lambda: chassis.Velocity(HUGE), "x"),
    (lambda: chassis.Velocity(y=-HUGER), "y"),
    (lambda: chassis.Turn(HUGE), "deci_degrees"),
    (lambda: chassis.Turn(70_000), "deci_degrees"),
    (lambda: chassis.Turn(900, y=HUGE), "y"),
    (lambda: chassis.Write("max-speed", HUGE), "max-speed"),
    (lambda: chassis.Write("max-speed", -1), "max-speed"),
    (lambda: chassis.Action(HUGE), "number"),
    (lambda: chassis.Imu([0, HUGE, 0], [0, 0, 0], 0), "accel[1]"),
    (lambda: chassis.Imu([0, 0, 0], [0, 0, 0], 256), "seq"),
    (lambda: chassis.Encoders([0, 0, 0, -HUGE], 0), "ticks[3]"),
    (lambda: chassis.Battery(70_000, 0, 0), "centivolts"),
    (lambda: chassis.Reply("max-speed", HUGE), "value"),
    (lambda: chassis.BodyVelocity(vx_mm_s=HUGE), "vx_mm_s"),
    (lambda: chassis.BodyVelocity(ctl=256), "ctl"),
    (lambda: chassis.Telemetry(quaternion=[1000, 0, 0, HUGER]), "quaternion[3]"),
    (lambda: chassis.ReadbackReply("system", [0] * 9 + [256]), "payload[9]"),
    (lambda: chassis.SystemMode(HUGE), "bits"),
    (lambda: chassis.DownlinkParser().quiet(HUGE), "ms"),
    (lambda: chassis.UplinkParser().quiet(-1), "ms"),
    (lambda: chassis.decode_capture(b"", quiet_ms=HUGER), "quiet_ms"),
    (lambda: chassis.sim.Board(seed=-1), "seed"),
    (lambda: chassis.sim.pty(seed=HUGE), "seed"),
    (lambda: chassis.sim.Board().advance(-1), "now_ms"),
]


@pytest.mark.parametrize("call, name", FRAMES, ids=[n for _, n in FRAMES])
def test_a_number_out_of_range_in_a_frame_is_a_value_error_naming_it(call: Callable[[], object], name: str) -> None:
    with pytest.raises(ValueError, match=rf"^{re.escape(name)} = \S+.* is out of range"):
        call()


def test_a_number_out_of_range_given_to_a_chassis_is_a_value_error_naming_it_with_nothing_sent(
    board: chassis.sim.Pty, v1_board: chassis.sim.Pty
) -> None:
    with chassis.open(board.path, firmware="2020") as bot:
        before = len(board.received)
        for call, name in [
            (lambda: bot.set_velocity(HUGE, 0, 0), "x"),
            (lambda: bot.set_velocity(0, 0, -HUGER), "z"),
            (lambda: bot.turn(HUGER), "degrees"),
            (lambda: bot.write("max-speed", HUGER), "max-speed"),
        ]:
            with pytest.raises(ValueError, match=rf"^{name} = "):
                call()
        # A timeout too large even for a float waits for ever, as math.inf does.
        assert bot.wait_frame(HUGER) is not None
        assert board.received[before:] == b""
    with chassis.open(v1_board.path, firmware="v1.0.0") as v1:
        before = len(v1_board.received)
        for call, name in [
            (lambda: v1.set_velocity(HUGER, 0, 0), "vx"),
            (lambda: v1.set_velocity(wz=-HUGER), "wz"),
            (lambda: v1.write("wheel-diameter", HUGER), "wheel-diameter"),
            (lambda: v1.wait_frame(-HUGER), "timeout"),
        ]:
            with pytest.raises(ValueError, match=rf"^{name} = "):
                call()
        assert v1_board.received[before:] == b""


LIMITS = [
    ("read_tries", 0, r"read_tries = 0 is out of range \(2..=10\)"),
    ("read_tries", 1, r"read_tries = 1 is out of range \(2..=10\)"),
    ("read_tries", 300, r"read_tries = 300 is out of range"),
    ("failsafe_ms", 0, r"failsafe_ms = 0 is out of range \(50..=5000\)"),
    ("failsafe_ms", HUGE, r"failsafe_ms = 18446744073709551616 is out of range \(50..=5000\)"),
    ("idle_ms", 0, r"idle_ms = 0 is out of range \(1..=500\)"),
    ("board_latency_ms", -1, r"board_latency_ms = -1 is out of range \(0..=2000\)"),
]


@pytest.mark.parametrize("option, value, words", LIMITS, ids=[f"{o}={v}" for o, v, _ in LIMITS])
def test_open_refuses_limits_it_cannot_work_with(board: chassis.sim.Pty, option: str, value: int, words: str) -> None:
    with pytest.raises(ValueError, match=words):
        chassis.open(board.path, firmware="2020", **{option: value})  # type: ignore[call-overload]
    assert board.received == b"", "refused before the port was opened"


def test_a_write_not_confirmed_is_an_unconfirmed_error_on_both_generations(
    board: chassis.sim.Pty, v1_board: chassis.sim.Pty
) -> None:
    # The board stops answering once the write's frame is out: its read-back gets nothing.
    with chassis.open(board.path, firmware="2020") as bot:
        board.silent = True
        with pytest.raises(chassis.UnconfirmedError, match=r"^max-speed: 800 was written \(the frame went out\), but not confirmed: "):
            bot.write("max-speed", 800)
        board.silent = False
    assert bytes.fromhex("FF FE 80 80 01 00 00 03 20 00") in frames_2020(board.received)
    with chassis.open(v1_board.path, firmware="v1.0.0") as v1:
        before = len(frames_v1(v1_board.received))

        def cut_after_the_write() -> None:
            # v1.0.0 reads the frame back first, then writes it (0x24: the geometry).
            wait_until("the write", lambda: any(f[1] == 0x24 for f in frames_v1(v1_board.received)[before:]))
            v1_board.silent = True

        cutter = threading.Thread(target=cut_after_the_write)
        cutter.start()
        with pytest.raises(chassis.UnconfirmedError, match=r"^wheel-diameter: 65 was written \(the frame went out\), but not confirmed: "):
            v1.write("wheel-diameter", 65)
        cutter.join()
        v1_board.silent = False


def test_a_v1_restore_refuses_a_key_that_is_none_of_its_fields_with_nothing_written(
    board: chassis.sim.Pty, v1_board: chassis.sim.Pty
) -> None:
    with chassis.open(v1_board.path, firmware="v1.0.0") as v1:
        saved = v1.settings()
        before = len(v1_board.received)
        typo_inside = {**saved, "geometry": {**saved["geometry"], "wheel_diamter_mm": 65}}
        typo_outside = {**saved, "pdi": saved["pid"]}
        with pytest.raises(ValueError, match=r'geometry: "wheel_diamter_mm" is not one of its fields .*nothing was written'):
            v1.restore(typo_inside)
        with pytest.raises(ValueError, match=r'no key "pdi" in them .*nothing was written'):
            v1.restore(typo_outside)
        # The earlier names of two fields are still read.
        old_names = dict(saved)
        system = dict(saved["system"])
        system["motor_directions"] = system.pop("motor_direction_bits")
        v1.restore({**old_names, "system": system})
        written = [f[1] for f in frames_v1(v1_board.received[before:]) if f[1] in (0x23, 0x24, 0x40)]
        assert written == [0x23, 0x24, 0x40], "only the good restore wrote"
    # The 2020 restore refused such a key already.
    with chassis.open(board.path, firmware="2020") as bot:
        with pytest.raises(ValueError, match="unknown field"):
            bot.restore({**bot.settings(), "max_sped": 800})


def test_the_simulated_board_moves_a_bounded_step_and_hears_ctrl_c() -> None:
    b = chassis.sim.Board()
    start = time.monotonic()
    with pytest.raises(ValueError, match="more than an hour"):
        b.advance(2**63)
    assert time.monotonic() - start < 1.0 and b.now_ms == 0
    # An hour at once (a twentieth of a second or more), Ctrl-C (here SIGALRM raising
    # KeyboardInterrupt) after 5 ms: it goes through at once, the board left where it got to.
    p = subprocess.run(
        [
            sys.executable,
            "-c",
            textwrap.dedent(
                """
                import signal, chassis
                def interrupt(signum, frame):
                    raise KeyboardInterrupt
                signal.signal(signal.SIGALRM, interrupt)
                b = chassis.sim.Board()
                signal.setitimer(signal.ITIMER_REAL, 0.005)
                try:
                    b.advance(3_600_000)
                    print("finished", b.now_ms)
                except KeyboardInterrupt:
                    print("interrupted", b.now_ms)
                """
            ),
        ],
        capture_output=True,
        timeout=60,
    )
    said, at = p.stdout.decode().split()
    assert said == "interrupted" and int(at) < 3_600_000, p.stdout
