# Types of the native module `chassis.chassis_native` (Rust sources in python/src/).
# The docstrings live in the Rust source (help() shows them); this file is for type checkers.
# Names starting with `_` exist only here (for type checkers), not at run time.

from collections.abc import Iterator, Sequence
from typing import Any, ClassVar, Generic, Literal, TypedDict, TypeVar, final, overload

from typing_extensions import Self

__version__: str

__all__ = [
    "__version__",
    "_interpreter_exiting",
    "Action",
    "Battery",
    "Board",
    "BodyVelocity",
    "Chassis",
    "ChassisError",
    "ChassisV1",
    "decode_capture",
    "Decoded",
    "DownlinkParser",
    "Encoders",
    "FrameError",
    "Imu",
    "Motors",
    "open",
    "Pty",
    "pty",
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
]

# ----- exceptions -----

# Called by `chassis` at interpreter exit, once every chassis is stopped and closed.
def _interpreter_exiting() -> None: ...

class ChassisError(Exception): ...
class TimeoutError(ChassisError): ...
class WrongReplyError(ChassisError): ...
class UnconfirmedError(ChassisError): ...
class TurnInProgressError(ChassisError): ...
class TransportError(ChassisError): ...
class FrameError(ChassisError): ...

# ----- names and dicts -----

# 2020 registers whose value is an int (`Chassis.read`; its overloads name the other three).
_IntRegister = Literal[
    "max-speed", "kp", "ki", "gyro-gain", "gyro-calibration", "motor-voltage"
]

# v1.0.0 readbacks and settings fields (`ChassisV1.read` / `write`).
_Readback = Literal["system", "geometry", "body-velocity", "pid"]
_V1Field = Literal[
    "motor-directions",
    "encoder-directions",
    "pwm-max",
    "pwm-min",
    "encoder-ppr",
    "wheel-spacing",
    "axle-spacing",
    "gear-ratio",
    "wheel-diameter",
    "position-kp",
    "position-ki",
    "position-kd",
    "velocity-kp",
    "velocity-ki",
]

# A readback's fields: ints, and the list of four speeds of `motor-speeds`.
_ReadbackFields = dict[str, int | list[int]]

# `(full_volts, cutoff_volts)`, `None` for the board's built-in table.
_BatteryRange = tuple[float | None, float | None]

class _StreamInfo(TypedDict):
    frames: int
    missed: int
    rate_hz: float

class _V1Settings(TypedDict):
    firmware: str
    system: dict[str, int]
    geometry: dict[str, int]
    pid: dict[str, int]

# ----- the driver -----

# `chassis.open` wraps it (typed there by the firmware asked for).
def open(
    port: str,
    *,
    firmware: str | None = None,
    failsafe_ms: int | None = None,
    board_latency_ms: int | None = None,
    idle_ms: int | None = None,
    read_tries: int | None = None,
) -> Chassis | ChassisV1: ...

# What a chassis and a simulated board's pseudo-terminal have alike: `close`, and a `with` block
# that closes it on the way out; in the stubs only.
class _Closable:
    def close(self) -> None: ...
    def __enter__(self) -> Self: ...
    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: object,
        /,
    ) -> Literal[False]: ...

_Yield = TypeVar("_Yield")

# What every chassis has (`Chassis`, `ChassisV1`), `_Yield` being the frames it gives; the classes
# share it in the stubs only (at run time each has its own methods).
class _Chassis(_Closable, Generic[_Yield]):
    @property
    def port(self) -> str: ...
    def stop(self) -> None: ...
    def poll(self) -> _Yield | None: ...
    def wait_frame(self, timeout: float | None = None) -> _Yield | None: ...
    def __iter__(self) -> Self: ...
    def __next__(self) -> _Yield: ...
    @property
    def link_alive(self) -> bool: ...
    @property
    def moving(self) -> bool: ...
    @property
    def failsafe_stops(self) -> int: ...
    @property
    def streams(self) -> dict[str, _StreamInfo]: ...
    @property
    def counters(self) -> dict[str, int]: ...

@final
class Chassis(_Chassis[Imu | Encoders | Battery]):
    @property
    def firmware(self) -> Literal["2020"]: ...
    def set_velocity(self, x: int = 0, y: int = 0, z: int = 0) -> None: ...
    def set_motors(self, values: Sequence[int], open_loop: bool = False) -> None: ...
    def turn(self, degrees: float) -> None: ...
    def wait_turn(self, timeout: float | None = None) -> bool: ...
    @overload
    def read(self, register: _IntRegister) -> int: ...
    @overload
    def read(self, register: Literal["system-mode"]) -> SystemMode: ...
    @overload
    def read(self, register: Literal["battery-range"]) -> _BatteryRange: ...
    @overload
    def read(self, register: Literal["pending-angle"]) -> float: ...
    @overload
    def read(self, register: str) -> int | SystemMode | _BatteryRange | float: ...
    def write(
        self,
        register: str,
        value: int | SystemMode | tuple[float | None, float | None],
        *,
        calibrate: bool = False,
    ) -> None: ...
    def settings(self) -> dict[str, int]: ...
    def restore(self, settings: dict[str, int]) -> dict[str, tuple[int, int]]: ...
    @property
    def imu(self) -> Imu | None: ...
    @property
    def encoders(self) -> Encoders | None: ...
    @property
    def battery(self) -> Battery | None: ...

@final
class SystemMode:
    def __new__(cls, bits: int) -> SystemMode: ...
    @property
    def bits(self) -> int: ...
    @property
    def drive_type(
        self,
    ) -> Literal["omni", "mecanum", "differential", "differential-open-loop", "reserved"]: ...
    @property
    def gyro_compensation(self) -> bool: ...
    @property
    def gyro_correction_at_rest(self) -> bool: ...
    @property
    def motor_reversed(self) -> bool: ...
    @property
    def encoder_reversed(self) -> bool: ...
    @property
    def steering_reversed(self) -> bool: ...
    @property
    def gyro_reversed(self) -> bool: ...
    def __eq__(self, other: object, /) -> bool: ...
    __hash__: ClassVar[None]  # type: ignore[assignment]

@final
class ChassisV1(_Chassis[Telemetry | ReadbackReply]):
    @property
    def firmware(self) -> Literal["v1.0.0"]: ...
    def set_velocity(self, vx: float = 0.0, vy: float = 0.0, wz: float = 0.0) -> None: ...
    def set_motors(self, speeds: Sequence[int]) -> None: ...
    @overload
    def read(self, name: _Readback) -> dict[str, int]: ...
    @overload
    def read(self, name: Literal["motor-speeds"]) -> _ReadbackFields: ...
    @overload
    def read(self, name: _V1Field) -> int: ...
    @overload
    def read(self, name: str) -> _ReadbackFields | int: ...
    def write(self, name: str, value: int) -> None: ...
    def settings(self) -> _V1Settings: ...
    def restore(self, settings: _V1Settings) -> None: ...
    @property
    def telemetry(self) -> Telemetry | None: ...

# ----- frames -----

_Decoded = TypeVar("_Decoded")

# What every frame class has: `encode`, and `decode` giving that class; in the stubs only.
class _Frame(Generic[_Decoded]):
    def encode(self) -> bytes: ...
    @staticmethod
    def decode(data: bytes) -> _Decoded: ...

# ----- 2020 frames: master → board -----

@final
class Velocity(_Frame[Velocity]):
    def __new__(cls, x: int = 0, y: int = 0, z: int = 0) -> Velocity: ...
    @property
    def x(self) -> int: ...
    @property
    def y(self) -> int: ...
    @property
    def z(self) -> int: ...

@final
class Turn(_Frame[Turn]):
    def __new__(cls, deci_degrees: int, x: int = 0, y: int = 0) -> Turn: ...
    @property
    def deci_degrees(self) -> int: ...
    @property
    def x(self) -> int: ...
    @property
    def y(self) -> int: ...

@final
class Motors(_Frame[Motors]):
    def __new__(cls, values: Sequence[int], open_loop: bool = False) -> Motors: ...
    @property
    def values(self) -> list[int]: ...
    @property
    def open_loop(self) -> bool: ...

@final
class Read(_Frame[Read]):
    def __new__(cls, register: str) -> Read: ...
    @property
    def register(self) -> str: ...

@final
class Write(_Frame[Write]):
    def __new__(cls, register: str, value: int) -> Write: ...
    @property
    def register(self) -> str: ...
    @property
    def value(self) -> int: ...

@final
class Action(_Frame[Action]):
    def __new__(cls, number: int) -> Action: ...
    @property
    def number(self) -> int: ...

# ----- 2020 frames: board → master (made by parsers and `decode`, not by a constructor) -----

@final
class Imu(_Frame[Imu]):
    def __new__(cls, accel: Sequence[int], gyro: Sequence[int], seq: int) -> Imu: ...
    @property
    def accel(self) -> list[int]: ...
    @property
    def gyro(self) -> list[int]: ...
    @property
    def seq(self) -> int: ...

@final
class Encoders(_Frame[Encoders]):
    def __new__(cls, ticks: Sequence[int], seq: int) -> Encoders: ...
    @property
    def ticks(self) -> list[int]: ...
    @property
    def seq(self) -> int: ...

@final
class Battery(_Frame[Battery]):
    def __new__(cls, centivolts: int, percent: int, seq: int) -> Battery: ...
    @property
    def centivolts(self) -> int: ...
    @property
    def percent(self) -> int: ...
    @property
    def seq(self) -> int: ...

@final
class Reply(_Frame[Reply]):
    def __new__(cls, register: str, value: int) -> Reply: ...
    @property
    def register(self) -> str | None: ...
    @property
    def code(self) -> int: ...
    @property
    def value(self) -> int: ...

# ----- v1.0.0 frames -----

@final
class BodyVelocity(_Frame[BodyVelocity]):
    def __new__(
        cls,
        vx_mm_s: int = 0,
        vy_mm_s: int = 0,
        wz_mrad_s: int = 0,
        ctl: int = 2,
        kind: int = 4,
    ) -> BodyVelocity: ...
    @property
    def vx_mm_s(self) -> int: ...
    @property
    def vy_mm_s(self) -> int: ...
    @property
    def wz_mrad_s(self) -> int: ...
    @property
    def ctl(self) -> int: ...
    @property
    def kind(self) -> int: ...
    @staticmethod
    def forced_stop() -> BodyVelocity: ...
    @property
    def is_forced_stop(self) -> bool: ...

@final
class Telemetry(_Frame[Telemetry]):
    def __new__(
        cls,
        velocity: Sequence[int] = (0, 0, 0),
        accel: Sequence[int] = (0, 0, 0),
        gyro: Sequence[int] = (0, 0, 0),
        quaternion: Sequence[int] = (1000, 0, 0, 0),
        battery_mv: int = 0,
    ) -> Telemetry: ...
    @property
    def velocity(self) -> list[int]: ...
    @property
    def accel(self) -> list[int]: ...
    @property
    def gyro(self) -> list[int]: ...
    @property
    def quaternion(self) -> list[int]: ...
    @property
    def battery_mv(self) -> int: ...
    @property
    def yaw_degrees(self) -> float: ...

@final
class ReadbackReply(_Frame[ReadbackReply]):
    def __new__(
        cls,
        request: Literal["system", "geometry", "body-velocity", "motor-speeds", "pid"],
        payload: Sequence[int],
    ) -> ReadbackReply: ...
    @property
    def request(self) -> Literal["system", "geometry", "body-velocity", "motor-speeds", "pid"]: ...
    @property
    def code(self) -> int: ...
    @property
    def payload(self) -> bytes: ...
    def fields(self) -> _ReadbackFields: ...

# ----- parsers -----

_Parsed = TypeVar("_Parsed")

# What every parser has (each generation, each direction), `_Parsed` being what `feed` gives: made
# with no arguments, `feed` and `stats`; in the stubs only.
class _Parser(Generic[_Parsed]):
    def __new__(cls) -> Self: ...
    def feed(self, data: bytes | bytearray) -> list[_Parsed]: ...
    @property
    def stats(self) -> dict[str, int]: ...

@final
class DownlinkParser(_Parser[Imu | Encoders | Battery | Reply]):
    def quiet(self, ms: int) -> list[Imu | Encoders | Battery | Reply]: ...
    def expect_reply(self, register: str | None) -> None: ...

# Its `feed` gives a settings frame of no known form as a dict:
# {"frame": "setting-raw", "code": int, "value": int, "tail": int}.
@final
class UplinkParser(
    _Parser[Velocity | Turn | Motors | Read | Write | Action | dict[str, str | int]]
):
    def quiet(self, ms: int) -> None: ...

@final
class V1DownlinkParser(_Parser[Telemetry | ReadbackReply]):
    def quiet(self) -> list[Telemetry | ReadbackReply]: ...

# Its `feed` gives commands other than a body velocity as dicts of their fields (JSON-like values).
@final
class V1UplinkParser(_Parser[BodyVelocity | dict[str, Any]]):
    def quiet(self) -> list[BodyVelocity | dict[str, Any]]: ...

# ----- captures -----

@final
class Decoded:
    # Each frame is a dict as `chassis decode` prints it in JSON: "frame", "offset", and the
    # frame's fields (ints, strings, bools, lists of ints).
    @property
    def frames(self) -> list[dict[str, Any]]: ...
    @property
    def summary(self) -> str: ...
    def __len__(self) -> int: ...
    def __iter__(self) -> Iterator[dict[str, Any]]: ...

def decode_capture(
    data: bytes | bytearray,
    *,
    input: str = "raw",
    uplink: bool = False,
    master: bytes | bytearray | None = None,
    firmware: str | None = None,
    quiet_ms: float | None = None,
) -> Decoded: ...

# ----- simulated boards (re-exported by `chassis.sim`) -----

@final
class Board:
    def __new__(cls, firmware: str = "2020", seed: int = 1) -> Board: ...
    def receive(self, data: bytes | bytearray) -> None: ...
    def advance(self, now_ms: int) -> None: ...
    def transmit(self) -> bytes: ...
    @property
    def now_ms(self) -> int: ...

@final
class Pty(_Closable):
    @property
    def path(self) -> str: ...
    @property
    def firmware(self) -> str: ...
    @property
    def received(self) -> bytes: ...
    @property
    def silent(self) -> bool: ...
    @silent.setter
    def silent(self, silent: bool) -> None: ...

def pty(firmware: str = "2020", seed: int = 1) -> Pty: ...
