"""A chassis inherited by a child process (`os.fork`, `multiprocessing` with the fork start
method, a daemon) is inert there: the child sends nothing, whether it exits without touching the
chassis or tries to use it (a clear `ChassisError`), and the parent drives on untouched. Each
test checks what the simulated board received."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

import chassis
from conftest import FORWARDS, STOPS, motion, wait_until

FORKED = """
    import multiprocessing, os, sys, time, chassis
    firmware, how, what = sys.argv[2], sys.argv[3], sys.argv[4]
    speed = 300 if firmware == "2020" else 0.3
    bot = chassis.open(sys.argv[1], firmware=firmware)
    bot.set_velocity(0, speed, 0)
    print("driving", flush=True)

    def child():
        if what == "uses":
            for call in (lambda: bot.set_velocity(0, 2 * speed, 0), bot.stop, lambda: bot.moving):
                try:
                    call()
                    print("child: no error", flush=True)
                except chassis.ChassisError as e:
                    print("child:", e, flush=True)

    if how == "os.fork":
        pid = os.fork()
        if pid == 0:
            child()
            sys.exit(0)  # the child's interpreter ends: exit handlers, collection
        code = os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])
    else:
        process = multiprocessing.get_context("fork").Process(target=child)
        process.start()
        process.join()
        code = process.exitcode
    print("child exit", code, flush=True)
    print("parent moving:", bot.moving, flush=True)
    for _ in range(5):
        bot.set_velocity(0, speed, 0)
        time.sleep(0.02)
    bot.close()
"""


@pytest.mark.parametrize("what", ["exits", "uses"])
@pytest.mark.parametrize("how", ["os.fork", "multiprocessing"])
def test_a_chassis_inherited_by_a_child_process_is_inert_there(
    target: chassis.sim.Pty, firmware: str, how: str, what: str
) -> None:
    forward = FORWARDS[firmware]
    p = subprocess.run(
        [sys.executable, "-W", "ignore::DeprecationWarning", "-c", textwrap.dedent(FORKED), target.path, firmware, how, what],
        capture_output=True,
        timeout=30,
    )
    out, err = p.stdout.decode(), p.stderr.decode()
    assert p.returncode == 0, err
    assert "panic" not in err and "Traceback" not in err, err
    lines = out.splitlines()
    if what == "uses":
        said = [line for line in lines if line.startswith("child:")]
        assert len(said) == 3, out
        for line in said:
            assert "a child made by fork" in line and "does nothing here" in line, line
    assert lines[0] == "driving" and lines[-2:] == ["child exit 0", "parent moving: True"], out
    # One stop, the parent's close(), last; nothing from the child (2x the speed never sent).
    stop = STOPS[firmware]
    wait_until("the parent's stop", lambda: stop in target.received)
    sent = motion(target.received, firmware)
    assert sent.count(stop) == 1 and sent[-1] == stop, [f.hex(" ") for f in sent]
    assert all(f == forward or f == stop for f in sent), [f.hex(" ") for f in sent]
