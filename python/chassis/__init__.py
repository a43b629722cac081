"""Drive the OminiBot HV chassis motor-controller board from Python.

The same trusted core as the Rust crate ``chassis-protocol`` (this package is that crate,
compiled): a driver with a failsafe and a one-shot turn guard, the frames and streaming parsers
of both firmware generations (2020: ``FF FE`` frames; v1.0.0: ``7B … BCC 7D``), and simulated
boards to try it all without hardware.

>>> import chassis
>>> with chassis.sim.pty() as board, chassis.open(board.path, firmware="2020") as bot:
...     bot.read("motor-voltage")
1200

Leaving a ``with`` block, an exception, ``KeyboardInterrupt``, ``close()``, the object being
collected or the interpreter exiting stops the chassis; so do SIGTERM and SIGHUP, before the
program's own handler runs or the process ends by the signal (see ``open``). A chassis inherited
by a child process (a fork) is inert there.
"""

from __future__ import annotations

import atexit
import weakref
from typing import TYPE_CHECKING, Literal, Optional, Union, overload

from . import sim
from .chassis_native import (
    Action,
    Battery,
    BodyVelocity,
    Chassis,
    ChassisError,
    ChassisV1,
    DownlinkParser,
    Encoders,
    FrameError,
    Imu,
    Motors,
    Read,
    ReadbackReply,
    Reply,
    SystemMode,
    Telemetry,
    TimeoutError,
    TransportError,
    Turn,
    TurnInProgressError,
    UnconfirmedError,
    UplinkParser,
    V1DownlinkParser,
    V1UplinkParser,
    Velocity,
    Write,
    WrongReplyError,
    Decoded,
    __version__,
    decode_capture,
)
from .chassis_native import _interpreter_exiting
from .chassis_native import open as _open

__all__ = [
    "Action",
    "Battery",
    "BodyVelocity",
    "Chassis",
    "ChassisError",
    "ChassisV1",
    "DownlinkParser",
    "Encoders",
    "FrameError",
    "Imu",
    "Motors",
    "Read",
    "ReadbackReply",
    "Reply",
    "SystemMode",
    "Telemetry",
    "TimeoutError",
    "TransportError",
    "Turn",
    "TurnInProgressError",
    "UnconfirmedError",
    "UplinkParser",
    "V1DownlinkParser",
    "V1UplinkParser",
    "Velocity",
    "Write",
    "WrongReplyError",
    "Decoded",
    "__version__",
    "decode_capture",
    "open",
    "sim",
]

if TYPE_CHECKING:
    from typing import TypedDict

    from typing_extensions import Unpack

    class _OpenOptions(TypedDict, total=False):
        """The limits `open()` takes besides the firmware, each `None` for the host default."""

        failsafe_ms: Optional[int]
        board_latency_ms: Optional[int]
        idle_ms: Optional[int]
        read_tries: Optional[int]

# Every chassis still open when the interpreter exits is stopped and closed.
_open_chassis: "weakref.WeakSet[Union[Chassis, ChassisV1]]" = weakref.WeakSet()


@overload
def open(port: str, *, firmware: Literal["2020"], **options: Unpack[_OpenOptions]) -> Chassis: ...


@overload
def open(
    port: str, *, firmware: Literal["v1.0.0", "v1"], **options: Unpack[_OpenOptions]
) -> ChassisV1: ...


@overload
def open(
    port: str, *, firmware: Optional[str] = None, **options: Unpack[_OpenOptions]
) -> Union[Chassis, ChassisV1]: ...


def open(
    port: str,
    *,
    firmware: Optional[str] = None,
    failsafe_ms: Optional[int] = None,
    board_latency_ms: Optional[int] = None,
    idle_ms: Optional[int] = None,
    read_tries: Optional[int] = None,
) -> Union[Chassis, ChassisV1]:
    """Open the board on serial port ``port`` and return its driver.

    Without ``firmware`` ("2020" or "v1.0.0"), the firmware is found from what the board
    sends (it listens first; only on a quiet line does it send a register read of each
    firmware, never anything else). Returns a :class:`Chassis` (2020) or a :class:`ChassisV1`
    (v1.0.0), with the host defaults (a 200 ms failsafe; at least 300 ms on v1.0.0) changed by
    the keyword arguments, and its pump thread running: the failsafe and the telemetry run
    whatever the program does.

    ``failsafe_ms`` is 50 to 5000, ``read_tries`` 2 to 10, ``idle_ms`` 1 to 500 and
    ``board_latency_ms`` 0 to 2000: anything else is a ``ValueError``, before the port is opened.

    The first ``open()`` puts a handler in front of what SIGTERM and SIGHUP do (an ignored one
    stays ignored): every open chassis is stopped at once, on a thread of the package's own,
    then the program's own handler runs, or, if it has none, the process ends by the signal.

    Raises :class:`TimeoutError` when nothing came from the board, :class:`TransportError`
    when the port cannot be opened, :class:`ChassisError` on bytes of neither firmware.
    """
    bot = _open(
        port,
        firmware=firmware,
        failsafe_ms=failsafe_ms,
        board_latency_ms=board_latency_ms,
        idle_ms=idle_ms,
        read_tries=read_tries,
    )
    _open_chassis.add(bot)
    return bot


@atexit.register
def _stop_all() -> None:
    for bot in list(_open_chassis):
        try:
            bot.close()
        except ChassisError:
            pass
    # Other threads still in a blocking call of this package stay there (see `detach` in the
    # native module): CPython before 3.14 would end them in a way that aborts the process.
    _interpreter_exiting()
