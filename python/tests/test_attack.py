"""The standing attack suite: a program driving a chassis in a loop, ended every way a robot's
Raspberry Pi meets, on both firmware generations, checked by what the simulated board received.

* **Signals**: SIGINT (Ctrl-C), SIGTERM (`systemctl stop`, `docker stop`, `kill`) and SIGHUP (a
  closed session), each at ten moments from the program's start to 2 s after it (before
  `import chassis`, during `open()`, while driving).
* **Another thread's `stop()` or `close()`** during each blocking call (`read`, `settings`,
  `write`, `restore`, `wait_turn`, `wait_frame`; on v1.0.0 the same but `wait_turn`), the
  board silent so that the call waits.
* **A fork** (the child exits, the child uses the chassis, `multiprocessing`): `test_fork.py`.

After each: the board's last motion frame is a stop (or nothing moved at all), nothing moved it
after, the process ended within its bound (a signal: the stop within 1 s of it, the process gone
within 5 s, bounds for a loaded 2-core machine; unloaded they take 1-2 ms and 2-20 ms; the
stop waits at most 1 s for a turn's cancel), and what the program said tells what happened. The cases of a test run side by side; `pytest -s` prints each one's
figures.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, Callable

import pytest

import chassis
from conftest import DRIVE, FORWARDS, SPEEDS, STOPS, motion, wait_until

# Bounds for a loaded 2-core machine: unloaded, the stop takes 1-2 ms and the exit 2-20 ms.
STOP_WITHIN_S = 1.0
EXIT_WITHIN_S = 5.0
# From the program's start to 2 s after it, closer together early on: before `import chassis`,
# during it, during `open()`, the first frames, then driving.
MOMENTS = [0.0, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 1.0, 1.5, 2.0]

@dataclass
class Ending:
    """What one case did."""

    moment: float
    moved_before: bool  # the board had a motion frame other than a stop before the signal
    stop_after_s: float | None  # from the signal to the stop frame, if one came after it
    exit_after_s: float
    returncode: int
    stderr: str
    last: bytes | None  # the last motion frame


def end_by_signal(firmware: str, sig: signal.Signals, moment: float) -> Ending:
    stop = STOPS[firmware]
    with chassis.sim.pty(firmware=firmware) as board:
        p = subprocess.Popen(
            [sys.executable, "-c", textwrap.dedent(DRIVE), board.path, firmware],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
        )
        start = time.monotonic()
        time.sleep(max(0.0, start + moment - time.monotonic()))
        before = board.received
        sent = time.monotonic()
        p.send_signal(sig)
        stop_after = None
        exited = None
        # Until it is gone and, if it moved, its stop has reached the board (the simulated
        # board may lag behind on a loaded machine).
        while time.monotonic() - sent < EXIT_WITHIN_S + 5:
            if stop_after is None and stop in board.received[len(before):]:
                stop_after = time.monotonic() - sent
            if exited is None and p.poll() is not None:
                exited = time.monotonic() - sent
            moved = any(f != stop for f in motion(board.received, firmware))
            if exited is not None and (stop_after is not None or not moved):
                break
            time.sleep(0.002)
        try:
            _, err = p.communicate(timeout=5)
        except subprocess.TimeoutExpired:
            p.kill()
            _, err = p.communicate()
        exit_after = exited if exited is not None else time.monotonic() - sent
        sent_frames = motion(board.received, firmware)
        moved = any(f != stop for f in motion(before, firmware))
        return Ending(
            moment=moment,
            moved_before=moved,
            stop_after_s=stop_after,
            exit_after_s=exit_after,
            returncode=p.returncode,
            stderr=err.decode(errors="replace"),
            last=sent_frames[-1] if sent_frames else None,
        )


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP], ids=["SIGINT", "SIGTERM", "SIGHUP"])
def test_a_driving_program_ended_by_a_signal_at_any_moment_leaves_the_chassis_stopped(
    firmware: str, sig: signal.Signals
) -> None:
    # Four programs at a time: more would load a 2-core machine with the suite itself.
    with ThreadPoolExecutor(max_workers=4) as pool:
        endings = list(pool.map(lambda m: end_by_signal(firmware, sig, m), MOMENTS))
    stop = STOPS[firmware]
    failures = []
    for e in endings:
        stop_ms = "-" if e.stop_after_s is None else f"{e.stop_after_s * 1000:.0f} ms"
        print(
            f"{firmware:7} {sig.name:8} at {e.moment:4.2f} s: moved {'yes' if e.moved_before else 'no ':3}  "
            f"last motion {'stop' if e.last == stop else ('none' if e.last is None else e.last.hex(' '))}  "
            f"stop after {stop_ms:>7}  exit {e.returncode:4} after {e.exit_after_s * 1000:5.0f} ms  "
            f"said: {e.stderr.strip().splitlines()[-1] if e.stderr.strip() else '(nothing)'}"
        )
        why = []
        # Nothing moved it after: its last motion frame is the stop, or it never moved.
        if e.last is not None and e.last != stop:
            why.append("the last motion frame is not a stop")
        if e.moved_before and (e.stop_after_s is None or e.stop_after_s > STOP_WITHIN_S):
            why.append(f"moving at the signal, stopped after {e.stop_after_s}")
        if e.exit_after_s > EXIT_WITHIN_S:
            why.append(f"ended {e.exit_after_s:.2f} s after the signal")
        # Python itself interrupted while it starts (importing `site`, before the program
        # runs) ends with status 1 and a fatal error naming KeyboardInterrupt.
        startup = sig == signal.SIGINT and e.returncode == 1 and "KeyboardInterrupt" in e.stderr
        if e.returncode != -sig and not (startup and not e.moved_before):
            why.append(f"exit status {e.returncode}, not {sig.name}'s")
        if e.moved_before:
            said = "KeyboardInterrupt" if sig == signal.SIGINT else f"chassis: {sig.name}: the chassis on"
            if said not in e.stderr:
                why.append(f"said {e.stderr!r}")
        if why:
            failures.append((e.moment, why))
    assert not failures, failures
    # The moments reach the driving loop: the later ones moved before their signal.
    assert sum(e.moved_before for e in endings) >= 4, "the program never drove"


# ----- another thread's stop() or close() during each blocking call -----


# Per firmware: what the blocking calls read, and write (a settings field, its value).
READ = {"2020": "max-speed", "v1.0.0": "geometry"}
WRITE = {"2020": ("max-speed", 900), "v1.0.0": ("wheel-diameter", 65)}


def blocking_calls(bot: chassis.Chassis | chassis.ChassisV1) -> dict[str, Callable[[], object]]:
    """Each call of `bot` that waits for the board, by name (`wait_turn`: 2020 only)."""
    saved: Any = bot.settings()
    read, (field, value) = READ[bot.firmware], WRITE[bot.firmware]
    calls: dict[str, Callable[[], object]] = {
        "read": lambda: bot.read(read),
        "settings": bot.settings,
        "write": lambda: bot.write(field, value),
        "restore": lambda: bot.restore(saved),
        "wait_frame": lambda: bot.wait_frame(10),
    }
    if isinstance(bot, chassis.Chassis):
        calls["wait_turn"] = lambda: bot.wait_turn(10)
    return calls


CALLS = [("2020", c) for c in ["read", "settings", "write", "restore", "wait_turn", "wait_frame"]] + [
    ("v1.0.0", c) for c in ["read", "settings", "write", "restore", "wait_frame"]
]


@dataclass
class Interrupted:
    """What one case did."""

    stop_after_s: float  # from the call of stop()/close() to the stop frame on the wire
    returned_after_s: float  # from the call of stop()/close() to its return
    said: str  # what stop()/close() said
    ended: str  # how the blocked call ended


def interrupt_a_blocked_call(firmware: str, call: str, how: str) -> Interrupted:
    stop = STOPS[firmware]
    with chassis.sim.pty(firmware=firmware) as board:
        # The failsafe set long: only the stop asked for can stop the chassis here.
        bot = chassis.open(board.path, firmware=firmware, failsafe_ms=5000)
        try:
            calls = blocking_calls(bot)
            bot.set_velocity(0, SPEEDS[firmware], 0)  # type: ignore[arg-type]
            if isinstance(bot, chassis.Chassis) and call == "wait_turn":
                bot.turn(360)
            forward = FORWARDS[firmware]
            wait_until("driving", lambda: forward in board.received or call == "wait_turn")
            ended: list[str] = []

            def blocked() -> None:
                try:
                    ended.append(f"returned {calls[call]()!r}")
                except BaseException as e:  # noqa: BLE001 - recorded for the test
                    ended.append(f"{type(e).__name__}: {e}")

            board.silent = True
            if call == "wait_frame":
                time.sleep(0.05)  # the frames on their way are in
                while bot.poll() is not None:
                    pass
            t = threading.Thread(target=blocked, daemon=True)
            t.start()
            time.sleep(0.15)  # the call's request is out and waits
            assert t.is_alive(), f"{call} did not wait: {ended}"
            before = len(board.received)
            seen: list[float] = []

            def watch() -> None:
                while stop not in board.received[before:]:
                    if time.monotonic() - start > 5.0:
                        return
                    time.sleep(0.0005)
                seen.append(time.monotonic() - start)

            start = time.monotonic()
            watcher = threading.Thread(target=watch)
            watcher.start()
            said = "returned"
            try:
                getattr(bot, how)()
            except chassis.ChassisError as e:
                # 2020, a turn outstanding on a silent board: the stop went out, its cancel
                # could not be confirmed, and stop() says so.
                said = f"{type(e).__name__}: {e}"
            returned = time.monotonic() - start
            watcher.join()
            assert seen, "no stop reached the board"
            took = seen[0]
            if how == "stop":
                try:
                    bot.close()  # ends the blocked call at its next turn
                except chassis.ChassisError:
                    pass  # wait_turn: the cancel again unconfirmed, as said above
            t.join(3.0)
            assert not t.is_alive(), f"{call} still waits after close()"
            sent = motion(board.received, firmware)
            assert sent[-1] == stop, [f.hex(" ") for f in sent[-3:]]
            return Interrupted(took, returned, said, ended[0] if ended else "(nothing)")
        finally:
            try:
                bot.close()
            except chassis.ChassisError:
                pass  # said above


@pytest.mark.parametrize("how", ["stop", "close"])
def test_another_threads_stop_during_each_blocking_call_goes_out_at_once(how: str) -> None:
    with ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(lambda c: (c, interrupt_a_blocked_call(c[0], c[1], how)), CALLS))
    failures = []
    for (firmware, call), r in results:
        print(
            f"{firmware:7} {how}() during {call:10}: the stop on the wire after {r.stop_after_s * 1000:4.0f} ms, "
            f"{how}() returned after {r.returned_after_s * 1000:5.0f} ms ({r.said[:60]}); the call: {r.ended[:100]}"
        )
        if r.stop_after_s > STOP_WITHIN_S:
            failures.append((firmware, call, r))
        # The blocked call ends with the chassis closed (wait_turn: the turn was cancelled,
        # or the wait ended by the close).
        if "is closed" not in r.ended and not (call == "wait_turn" and r.ended.startswith("returned")):
            failures.append((firmware, call, r))
        if r.said != "returned" and not (call == "wait_turn" and "the stop was sent" in r.said):
            failures.append((firmware, call, r))
    assert not failures, failures
