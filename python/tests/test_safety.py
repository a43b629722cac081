"""The chassis is stopped when the program is interrupted, fails or lets go, and when the board
goes silent; a turn is sent exactly once. Each test checks what the simulated board received,
through the real OS serial stack."""

from __future__ import annotations

import gc
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import pytest

import chassis
from conftest import FORCED_STOP, FORWARD, STOP, TURN_90, V1_FORWARD, frames_2020, wait_until


def child(code: str, path: str) -> subprocess.Popen[bytes]:
    """A Python program driving the board at `path`."""
    return subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(code), path],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )


DRIVE_LOOP = """
    import sys, time, chassis
    with chassis.open(sys.argv[1]) as bot:
        print("driving", flush=True)
        while True:
            bot.set_velocity(0, 300, 0)
            time.sleep(0.05)
"""

DRIVE_LOOP_NO_WITH = """
    import sys, time, chassis
    bot = chassis.open(sys.argv[1])
    print("driving", flush=True)
    while True:
        bot.set_velocity(0, 300, 0)
        time.sleep(0.05)
"""


@pytest.mark.parametrize("code", [DRIVE_LOOP, DRIVE_LOOP_NO_WITH], ids=["with", "no-with"])
def test_keyboard_interrupt_in_a_drive_loop_stops_the_chassis(board: chassis.sim.Pty, code: str) -> None:
    p = child(code, board.path)
    assert p.stdout is not None and p.stdout.readline() == b"driving\n"
    wait_until("driving", lambda: FORWARD in board.received)
    time.sleep(0.2)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=10)
    assert b"KeyboardInterrupt" in err
    sent = frames_2020(board.received)
    assert sent[-1] == STOP, [f.hex(" ") for f in sent[-3:]]
    assert FORWARD not in b"".join(sent[sent.index(STOP, len(sent) - 2):])


def test_an_exception_in_the_with_block_stops_the_chassis(board: chassis.sim.Pty) -> None:
    with pytest.raises(ZeroDivisionError):
        with chassis.open(board.path) as bot:
            bot.set_velocity(0, 300, 0)
            wait_until("driving", lambda: FORWARD in board.received)
            1 / 0
    assert frames_2020(board.received)[-1] == STOP


def test_a_chassis_collected_without_close_stops(board: chassis.sim.Pty) -> None:
    bot = chassis.open(board.path)
    bot.set_velocity(0, 300, 0)
    wait_until("driving", lambda: FORWARD in board.received)
    del bot
    gc.collect()
    wait_until("stopped", lambda: frames_2020(board.received)[-1] == STOP)


def test_a_silent_board_is_stopped_by_the_failsafe_while_the_program_sleeps(board: chassis.sim.Pty) -> None:
    with chassis.open(board.path) as bot:
        bot.set_velocity(0, 300, 0)
        wait_until("driving", lambda: FORWARD in board.received)
        board.silent = True
        went_silent = time.monotonic()
        # The program does nothing: no poll, no velocity. The pump thread judges the link.
        took = wait_until("the failsafe's STOP", lambda: frames_2020(board.received)[-1] == STOP, 3.0)
        assert bot.failsafe_stops == 1
        assert not bot.moving
        assert took < 0.2 + 0.3, f"stopped {time.monotonic() - went_silent:.3f} s after the board went silent"
        board.silent = False


def test_a_turn_in_a_periodic_loop_is_sent_once(board: chassis.sim.Pty) -> None:
    with chassis.open(board.path) as bot:
        bot.turn(90)
        refused = 0
        for _ in range(20):
            try:
                bot.turn(90)
            except chassis.TurnInProgressError as e:
                refused += 1
                assert "adds turns up" in str(e)
            time.sleep(0.02)
        assert refused == 20
        assert bot.wait_turn(timeout=5)
        bot.turn(-90)
        assert bot.wait_turn(timeout=5)
    sent = frames_2020(board.received)
    assert sent.count(TURN_90) == 1
    assert sent.count(bytes.fromhex("FF FE 01 00 00 00 00 03 84 11")) == 1, "the -90° turn, once"


def test_stop_from_another_thread_while_one_waits_cancels_the_turn(board: chassis.sim.Pty) -> None:
    with chassis.open(board.path) as bot:
        bot.turn(360)
        result: list[bool] = []
        waiter = threading.Thread(target=lambda: result.append(bot.wait_turn(timeout=10)))
        waiter.start()
        time.sleep(0.5)
        start = time.monotonic()
        bot.stop()  # the GIL and the driver are free while the other thread waits
        waiter.join(timeout=5)
        assert result == [True], "the wait ends: the turn was cancelled"
        assert time.monotonic() - start < 2.0
        assert bot.read("pending-angle") == 0.0
    sent = frames_2020(board.received)
    # The cancel: the opposite of what was pending, angle mode with Z reversed (dir bits 0x11).
    assert any(f[:4] == b"\xff\xfe\x01\x00" and f[9] == 0x11 for f in sent)


def test_keyboard_interrupt_while_waiting_for_a_turn_cancels_it(board: chassis.sim.Pty) -> None:
    p = child(
        """
        import sys, chassis
        with chassis.open(sys.argv[1]) as bot:
            bot.turn(360)
            print("turning", flush=True)
            bot.wait_turn()
        """,
        board.path,
    )
    assert p.stdout is not None and p.stdout.readline() == b"turning\n"
    time.sleep(0.5)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=10)
    assert b"KeyboardInterrupt" in err
    sent = frames_2020(board.received)
    assert sent.count(bytes.fromhex("FF FE 01 00 00 00 00 0E 10 10")) == 1, "360° sent once"
    assert any(f[:4] == b"\xff\xfe\x01\x00" and f[9] == 0x11 for f in sent), "and cancelled"
    assert sent[-1] == STOP or sent[-1][9] == 0x11


def test_v1_forced_stop_on_exit_and_on_a_silent_board(v1_board: chassis.sim.Pty) -> None:
    with chassis.open(v1_board.path) as bot:
        assert isinstance(bot, chassis.ChassisV1)
        assert not hasattr(bot, "turn"), "no turn by an angle on v1.0.0"
        bot.set_velocity(0, 0.3, 0)
        wait_until("driving", lambda: V1_FORWARD in v1_board.received)
        v1_board.silent = True
        took = wait_until("the forced stop", lambda: v1_board.received.endswith(FORCED_STOP), 3.0)
        assert took < 0.3 + 0.3
        assert bot.failsafe_stops == 1
        v1_board.silent = False
        bot.set_velocity(0, 0.3, 0)
    assert v1_board.received.endswith(FORCED_STOP)


READER_THREAD = """
    import sys, threading, time, chassis
    bot = chassis.open(sys.argv[1], firmware=sys.argv[2])
    threading.Thread(target=lambda: [f for f in bot], daemon=True).start()
    bot.set_velocity(0, {speed}, 0)
    print("driving", flush=True)
    time.sleep(0.3)
    # The program ends with the reader thread still waiting for frames.
"""


def test_a_program_ending_with_a_thread_still_reading_stops_the_chassis_and_exits_cleanly(
    board: chassis.sim.Pty, v1_board: chassis.sim.Pty, firmware: str
) -> None:
    target, speed, forward, stop = (
        (board, 300, FORWARD, STOP) if firmware == "2020" else (v1_board, 0.3, V1_FORWARD, FORCED_STOP)
    )
    p = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(READER_THREAD.format(speed=speed)), target.path, firmware],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    out, err = p.communicate(timeout=20)
    assert out == b"driving\n"
    assert p.returncode == 0, err.decode()
    assert b"Error" not in err and b"FATAL" not in err, err.decode()
    assert forward in target.received
    assert target.received.endswith(stop), target.received[-28:].hex(" ")


def test_leaving_the_with_block_while_another_thread_reads_stops_the_chassis(board: chassis.sim.Pty) -> None:
    ended = threading.Event()
    seen: list[object] = []

    def reader(bot: chassis.Chassis) -> None:
        for frame in bot:
            seen.append(frame)
        ended.set()

    with chassis.open(board.path, firmware="2020") as bot:
        threading.Thread(target=reader, args=(bot,), daemon=True).start()
        bot.set_velocity(0, 300, 0)
        wait_until("driving", lambda: FORWARD in board.received)
        wait_until("frames read", lambda: len(seen) > 5)
    wait_until("stopped", lambda: frames_2020(board.received)[-1] == STOP)  # the board may lag
    assert ended.wait(2.0), "the reader's iteration ends when the chassis is closed"
    with pytest.raises(chassis.ChassisError, match="is closed"):
        bot.moving


def test_close_from_another_thread_while_one_waits_for_a_frame(v1_board: chassis.sim.Pty) -> None:
    bot = chassis.open(v1_board.path, firmware="v1.0.0")
    bot.set_velocity(0, 0.3, 0)
    wait_until("driving", lambda: V1_FORWARD in v1_board.received)
    errors: list[BaseException] = []

    def waiter() -> None:
        try:
            while bot.wait_frame(5.0) is not None:
                pass
        except chassis.ChassisError as e:
            errors.append(e)

    t = threading.Thread(target=waiter)
    t.start()
    time.sleep(0.1)
    bot.close()
    t.join(5.0)
    assert not t.is_alive()
    assert v1_board.received.endswith(FORCED_STOP)
    assert [str(e) for e in errors] == [f"the chassis on {v1_board.path} is closed"]
