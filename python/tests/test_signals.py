"""A program stopped as a service (SIGTERM: `systemctl stop`, `docker stop`, `kill`) or by a closed
session (SIGHUP) stops the chassis first, whatever its main thread is doing, and then ends as the
signal asks, or runs the program's own handler. Each test runs the program in a process of its
own and checks what the simulated board received."""

from __future__ import annotations

import math
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import chassis
from conftest import DRIVE, FORWARD, FORWARDS, STOPS, V1_FORWARD, motion, wait_until

# A stop within this of the signal: the guard's thread stops at once (about a millisecond);
# the rest is room for a loaded machine.
STOP_WITHIN_S = 0.5


def run(code: str, *args: str, **popen: object) -> subprocess.Popen[bytes]:
    """A Python program with `args`, its output piped."""
    return subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(code), *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        **popen,  # type: ignore[call-overload]
    )


def signal_and_time_the_stop(p: subprocess.Popen[bytes], sig: int, board: chassis.sim.Pty, stop: bytes) -> float:
    """Sends `sig` to `p`: how long until `stop` reached `board` after it (inf: not in 3 s)."""
    before = len(board.received)
    start = time.monotonic()
    p.send_signal(sig)
    while stop not in board.received[before:]:
        if time.monotonic() - start > 3.0:
            return math.inf
        time.sleep(0.001)
    return time.monotonic() - start


def expect_line(p: subprocess.Popen[bytes], line: bytes) -> None:
    assert p.stdout is not None
    got = p.stdout.readline()
    assert got == line, (got, p.stderr.read() if p.stderr and p.poll() is not None else b"")


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP], ids=["SIGTERM", "SIGHUP"])
def test_sigterm_and_sighup_stop_the_chassis_then_end_the_process_with_their_status(
    target: chassis.sim.Pty, firmware: str, sig: signal.Signals
) -> None:
    forward, stop = FORWARDS[firmware], STOPS[firmware]
    p = run(DRIVE, target.path, firmware)
    expect_line(p, b"driving\n")
    wait_until("driving", lambda: forward in target.received)
    took = signal_and_time_the_stop(p, sig, target, stop)
    _, err = p.communicate(timeout=10)
    assert took < STOP_WITHIN_S, f"the stop {took:.3f} s after {sig.name}"
    assert p.returncode == -sig, (p.returncode, err.decode())
    assert f"chassis: {sig.name}: the chassis on {target.path} was stopped".encode() in err, err.decode()
    sent = motion(target.received, firmware)
    assert sent[-1] == stop, [f.hex(" ") for f in sent[-3:]]


BLOCKED = """
    import sys, time, chassis
    bot = chassis.open(sys.argv[1], firmware="2020", failsafe_ms=5000)
    bot.set_velocity(0, 300, 0)
    print("driving", flush=True)
    if sys.argv[2] == "sleep":
        time.sleep(60)
    else:
        while True:
            try:
                bot.read("max-speed")  # the board silent: each read waits 2.5 s
            except chassis.ChassisError:
                pass
"""


@pytest.mark.parametrize("blocked_in", ["sleep", "read"])
def test_the_stop_does_not_wait_for_the_main_thread(board: chassis.sim.Pty, blocked_in: str) -> None:
    # The main thread asleep for a minute, or in a read of a board gone silent (the failsafe
    # set long, so that only the signal can stop the chassis).
    p = run(BLOCKED, board.path, blocked_in)
    expect_line(p, b"driving\n")
    wait_until("driving", lambda: FORWARD in board.received)
    if blocked_in == "read":
        board.silent = True
        time.sleep(0.3)
    took = signal_and_time_the_stop(p, signal.SIGTERM, board, STOPS["2020"])
    _, err = p.communicate(timeout=10)
    assert took < STOP_WITHIN_S, f"the stop {took:.3f} s after SIGTERM"
    assert p.returncode == -signal.SIGTERM, err.decode()
    assert motion(board.received, "2020")[-1] == STOPS["2020"]


OWN_HANDLER = """
    import signal, sys, time, chassis
    def handler(signum, frame):
        print("handler", flush=True)
        raise SystemExit(0)
    if sys.argv[3] == "before":
        signal.signal(signal.SIGTERM, handler)
    first = chassis.open(sys.argv[1], firmware="2020")
    if sys.argv[3] == "after":
        # Replaces the package's handler; the next open() puts the stop in front of it again.
        signal.signal(signal.SIGTERM, handler)
    second = chassis.open(sys.argv[2], firmware="v1.0.0")
    first.set_velocity(0, 300, 0)
    second.set_velocity(0, 0.3, 0)
    try:
        print("driving", flush=True)
        time.sleep(60)  # the handler's exception ends the sleep at once
    except SystemExit:
        # The program's own way to end: it takes its time, then closes.
        print("moving:", first.moving, second.moving, flush=True)
        time.sleep(1.0)
        first.close()
        second.close()
"""


@pytest.mark.parametrize("when", ["before", "after"])
def test_a_handler_of_the_program_runs_and_every_chassis_stops_at_once(
    board: chassis.sim.Pty, v1_board: chassis.sim.Pty, when: str
) -> None:
    p = run(OWN_HANDLER, board.path, v1_board.path, when)
    expect_line(p, b"driving\n")
    wait_until("driving", lambda: FORWARD in board.received and V1_FORWARD in v1_board.received)
    b2020, bv1 = len(board.received), len(v1_board.received)
    start = time.monotonic()
    p.send_signal(signal.SIGTERM)
    took = wait_until(
        "both stopped",
        lambda: STOPS["2020"] in board.received[b2020:] and STOPS["v1.0.0"] in v1_board.received[bv1:],
        3.0,
    )
    out, err = p.communicate(timeout=10)
    assert took < STOP_WITHIN_S, f"stopped {took:.3f} s after SIGTERM ({time.monotonic() - start:.3f} s)"
    # The program's handler ran after the stop (it finds both chassis stopped), at once (not
    # after the minute's sleep), and the program ended its own way.
    assert out == b"handler\nmoving: False False\n", (out, err.decode())
    assert p.returncode == 0, err.decode()
    assert motion(board.received, "2020")[-1] == STOPS["2020"]
    assert motion(v1_board.received, "v1.0.0")[-1] == STOPS["v1.0.0"]


def test_a_handler_another_library_installed_in_c_is_called_after_the_stop(board: chassis.sim.Pty) -> None:
    # faulthandler's handler for a user's signal is C (as rclpy's is): it writes the threads'
    # stacks and lets the program go on, which then ends its own way.
    p = run(
        """
        import faulthandler, signal, sys, time, chassis
        faulthandler.register(signal.SIGTERM)
        bot = chassis.open(sys.argv[1], firmware="2020")
        bot.set_velocity(0, 300, 0)
        print("driving", flush=True)
        time.sleep(1.5)
        print("moving:", bot.moving, flush=True)
        bot.close()
        """,
        board.path,
    )
    expect_line(p, b"driving\n")
    wait_until("driving", lambda: FORWARD in board.received)
    took = signal_and_time_the_stop(p, signal.SIGTERM, board, STOPS["2020"])
    out, err = p.communicate(timeout=10)
    assert took < STOP_WITHIN_S, f"the stop {took:.3f} s after SIGTERM"
    assert b"(most recent call first)" in err, err.decode()
    assert out == b"moving: False\n" and p.returncode == 0, (out, err.decode())


def test_sighup_inherited_as_ignored_stays_ignored(board: chassis.sim.Pty) -> None:
    # nohup: the program asked to outlive its terminal, and the chassis drives on.
    p = run(DRIVE, board.path, "2020", preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN))
    expect_line(p, b"driving\n")
    wait_until("driving", lambda: FORWARD in board.received)
    p.send_signal(signal.SIGHUP)
    time.sleep(0.3)
    after = len(board.received)
    wait_until("still driving", lambda: FORWARD in board.received[after:])
    assert p.poll() is None, "SIGHUP ignored: the program runs on"
    assert STOPS["2020"] not in board.received
    took = signal_and_time_the_stop(p, signal.SIGTERM, board, STOPS["2020"])
    p.communicate(timeout=10)
    assert took < STOP_WITHIN_S
    assert p.returncode == -signal.SIGTERM


def test_a_chassis_opened_on_another_thread_is_stopped_too(board: chassis.sim.Pty) -> None:
    # Python's signal.signal works on the main thread only; the guard is installed in C.
    p = run(
        """
        import sys, threading, time, chassis
        def drive():
            bot = chassis.open(sys.argv[1], firmware="2020")
            print("driving", flush=True)
            while True:
                bot.set_velocity(0, 300, 0)
                time.sleep(0.02)
        threading.Thread(target=drive, daemon=True).start()
        time.sleep(60)
        """,
        board.path,
    )
    expect_line(p, b"driving\n")
    wait_until("driving", lambda: FORWARD in board.received)
    took = signal_and_time_the_stop(p, signal.SIGTERM, board, STOPS["2020"])
    _, err = p.communicate(timeout=10)
    assert took < STOP_WITHIN_S
    assert p.returncode == -signal.SIGTERM, err.decode()
    assert motion(board.received, "2020")[-1] == STOPS["2020"]
