"""No wait holds a stop back: a `stop()` or `close()` of another thread goes on the wire at once
while a call waits on a board that stopped answering, and the failsafe keeps its time whatever
other threads do. Each test checks what the simulated board received."""

from __future__ import annotations

import threading
import time
from typing import Callable

import pytest

import chassis
from conftest import FORWARDS, SPEEDS, STOPS, motion, wait_until

# A read on a silent board gives up after 2.4-2.5 s: a stop waiting behind it took that long.
# The stop goes out within a turn of the pump (a millisecond); the rest is room for a loaded
# machine.
STOP_WITHIN_S = 0.3

WAITS_2020: dict[str, Callable[[chassis.Chassis], object]] = {
    "read": lambda bot: bot.read("max-speed"),
    "settings": lambda bot: bot.settings(),
}
WAITS_V1: dict[str, Callable[[chassis.ChassisV1], object]] = {
    "read": lambda bot: bot.read("geometry"),
    "settings": lambda bot: bot.settings(),
}


def blocked_then(bot: chassis.Chassis | chassis.ChassisV1, call: Callable[[], object], board: chassis.sim.Pty) -> tuple[threading.Thread, list[BaseException]]:
    """`call` on a thread of its own, the board silent: it waits."""
    errors: list[BaseException] = []

    def waiting() -> None:
        try:
            call()
        except BaseException as e:  # noqa: BLE001 - recorded for the test
            errors.append(e)

    board.silent = True
    t = threading.Thread(target=waiting, daemon=True)
    t.start()
    time.sleep(0.1)  # the request is out and waits for its reply
    assert t.is_alive()
    return t, errors


@pytest.mark.parametrize("how", ["stop", "close"])
@pytest.mark.parametrize("call", ["read", "settings"])
def test_a_stop_of_another_thread_goes_out_at_once_while_a_call_waits(
    target: chassis.sim.Pty, firmware: str, call: str, how: str
) -> None:
    forward, speed, stop = FORWARDS[firmware], SPEEDS[firmware], STOPS[firmware]
    # The failsafe set long: only the stop asked for can stop the chassis here.
    bot = chassis.open(target.path, firmware=firmware, failsafe_ms=5000)
    bot.set_velocity(0, speed, 0)  # type: ignore[arg-type]
    wait_until("driving", lambda: forward in target.received)
    waits = WAITS_2020 if firmware == "2020" else WAITS_V1
    t, errors = blocked_then(bot, lambda: waits[call](bot), target)  # type: ignore[arg-type]
    before = len(target.received)
    start = time.monotonic()
    getattr(bot, how)()
    took = wait_until("the stop", lambda: stop in target.received[before:], 3.0)
    assert took < STOP_WITHIN_S, f"the stop reached the board {took:.3f} s after {how}()"
    if how == "stop":
        assert time.monotonic() - start < STOP_WITHIN_S, "stop() returns at once"
        assert t.is_alive(), "the other thread's call goes on"
        assert bot.failsafe_stops == 0, "the stop asked for, not the failsafe's"
        bot.close()
    # Closed: the waiting call ends at its next turn, with what happened.
    t.join(1.0)
    assert not t.is_alive()
    assert [str(e) for e in errors] == [f"the chassis on {target.path} is closed"]
    sent = motion(target.received, firmware)
    assert sent[-1] == stop
    target.silent = False


def test_the_failsafe_keeps_its_time_while_another_thread_reads(target: chassis.sim.Pty, firmware: str) -> None:
    # A thread reads in a loop (answered, then unanswered once the board goes silent); the
    # failsafe still stops the chassis its own time after the board was last heard (2020:
    # 200 ms; v1.0.0: 300 ms). It took 0.6 s (2020) and, on v1.0.0, never while readbacks kept
    # being asked for, or 0.9 s.
    forward, speed, stop = FORWARDS[firmware], SPEEDS[firmware], STOPS[firmware]
    failsafe = 0.2 if firmware == "2020" else 0.3
    bot = chassis.open(target.path, firmware=firmware)
    done = threading.Event()

    def reading() -> None:
        while not done.is_set():
            try:
                bot.read("max-speed" if firmware == "2020" else "geometry")
            except chassis.ChassisError:
                pass

    reader = threading.Thread(target=reading, daemon=True)
    reader.start()
    bot.set_velocity(0, speed, 0)  # type: ignore[arg-type]
    wait_until("driving", lambda: forward in target.received)
    time.sleep(0.3)  # reads answered meanwhile
    before = len(target.received)
    target.silent = True
    took = wait_until("the failsafe's stop", lambda: stop in target.received[before:], 3.0)
    assert bot.failsafe_stops == 1
    # Silence counts from the last frame heard (up to a telemetry period before the cut); the
    # rest is room for a loaded machine.
    assert took < failsafe + 0.25, f"the failsafe stopped {took:.3f} s after the board went silent"
    done.set()
    target.silent = False
    reader.join(5.0)
    bot.close()
    assert motion(target.received, firmware)[-1] == stop
