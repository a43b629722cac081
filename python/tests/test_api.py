"""Frames, parsers, captures and errors: golden bytes written by hand from the spec's tables;
captures decoded to exactly what `chassis decode` prints (its golden files)."""

from __future__ import annotations

import json
import os
import pathlib

import pytest

import chassis
from conftest import FORCED_STOP, FORWARD, STOP, TURN_90, V1_FORWARD, frames_2020

GOLDEN = pathlib.Path(__file__).resolve().parents[2] / "cli" / "tests" / "golden"


def hex_file(name: str) -> bytes:
    """A golden hex capture's bytes (groups of hex digits, `0x` allowed, commas)."""
    text = (GOLDEN / name).read_text().replace(",", " ")
    return bytes.fromhex("".join(g[2:] if g.lower().startswith("0x") else g for g in text.split()))


def test_frames_encode_to_the_spec_bytes_and_decode_back() -> None:
    assert chassis.Velocity(0, 300, 0).encode() == FORWARD
    assert chassis.Velocity().encode() == STOP
    assert chassis.Turn(900).encode() == TURN_90
    assert chassis.Read("motor-voltage").encode() == bytes.fromhex("FF FE 80 80 1B 00 00 00 00 00")
    assert chassis.Write("max-speed", 800).encode() == bytes.fromhex("FF FE 80 80 01 00 00 03 20 00")
    assert chassis.Velocity.decode(FORWARD) == chassis.Velocity(y=300)
    assert repr(chassis.Velocity(1, 2, 3)) == "Velocity(x=1, y=2, z=3)"
    assert chassis.BodyVelocity(vy_mm_s=300).encode() == V1_FORWARD
    assert chassis.BodyVelocity.forced_stop().encode() == FORCED_STOP
    assert chassis.BodyVelocity.decode(FORCED_STOP).is_forced_stop
    imu = bytes.fromhex("FF FA 00 01 00 02 00 03 00 04 00 05 00 06 02")
    assert chassis.Imu.decode(imu) == chassis.Imu.decode(chassis.Imu.decode(imu).encode())
    assert chassis.Imu.decode(imu).accel == [1, 2, 3]
    with pytest.raises(chassis.FrameError):
        chassis.Velocity.decode(b"\x00\x01")
    with pytest.raises(ValueError):
        chassis.Velocity(70_000)
    with pytest.raises(ValueError, match="not a register"):
        chassis.Read("speed")


def test_the_parsers_find_frames_in_any_chunking_and_count() -> None:
    data = hex_file("downlink.hex")
    whole = chassis.DownlinkParser()
    expected = whole.feed(data) + whole.quiet(5)
    chunked = chassis.DownlinkParser()
    got = []
    for i in range(0, len(data), 7):
        got += chunked.feed(data[i : i + 7])
    got += chunked.quiet(5)
    assert got == expected and len(got) > 5
    assert chunked.stats["frames"] == len(got)
    v1 = chassis.V1DownlinkParser()
    t = chassis.Telemetry(battery_mv=11_800).encode()
    assert v1.feed(b"\x00\x7b" + t[:10]) == []
    assert v1.feed(t[10:]) == [chassis.Telemetry(battery_mv=11_800)]
    assert v1.stats["discarded"] == 2
    up = chassis.UplinkParser()
    assert up.feed(FORWARD + TURN_90) == [chassis.Velocity(y=300), chassis.Turn(900)]


@pytest.mark.parametrize(
    "capture, options, golden",
    [
        ("downlink.hex", {"input": "hex"}, "downlink.jsonl"),
        ("uplink.hex", {"input": "hex", "uplink": True}, "uplink.jsonl"),
        ("v1_downlink.hex", {"input": "hex"}, "v1_downlink.jsonl"),
        ("v1_uplink.hex", {"input": "hex", "uplink": True}, "v1_uplink.jsonl"),
        ("v1_noisy.hex", {"input": "hex"}, "v1_noisy.jsonl"),
    ],
)
def test_decode_capture_gives_what_chassis_decode_prints(capture: str, options: dict, golden: str) -> None:
    decoded = chassis.decode_capture((GOLDEN / capture).read_bytes(), **options)
    expected = [json.loads(line) for line in (GOLDEN / golden).read_text().splitlines() if line.strip()]
    assert list(decoded) == expected
    assert "firmware" in decoded.summary


def test_errors_are_one_class_per_kind_with_the_cli_words(board: chassis.sim.Pty) -> None:
    with pytest.raises(chassis.TransportError, match="cannot open"):
        chassis.open("/nonexistent/ttyUSB9")
    with pytest.raises(ValueError, match="firmware"):
        chassis.open(board.path, firmware="2019")
    master, slave = os.openpty()
    try:
        with pytest.raises(chassis.TimeoutError, match="nothing came from the board"):
            chassis.open(os.ttyname(slave))
    finally:
        os.close(master)
        os.close(slave)
    with chassis.open(board.path) as bot:
        with pytest.raises(ValueError, match="not a register"):
            bot.read("speed")
        with pytest.raises(ValueError, match="gyro calibration"):
            bot.write("gyro-calibration", 0xFFFF)
        assert bot.wait_frame(timeout=2) is not None
        board.silent = True
        with pytest.raises(chassis.ChassisError, match="went quiet: no answer to the read of max-speed"):
            bot.read("max-speed")
        board.silent = False
        # Every error leaves the driver usable.
        assert bot.read("max-speed") == 1000
    assert issubclass(chassis.TurnInProgressError, chassis.ChassisError)
    with pytest.raises(chassis.ChassisError, match="closed"):
        bot.read("max-speed")


def test_registers_read_typed_and_settings_round_trip(board: chassis.sim.Pty) -> None:
    with chassis.open(board.path, firmware="2020") as bot:
        assert bot.firmware == "2020"
        assert bot.read("motor-voltage") == 1200
        mode = bot.read("system-mode")
        assert isinstance(mode, chassis.SystemMode) and mode.drive_type == "mecanum"
        assert bot.read("battery-range") == (None, None)
        assert bot.read("pending-angle") == 0.0
        saved = bot.settings()
        assert saved["max_speed"] == 1000
        bot.write("max-speed", 800)
        assert bot.read("max-speed") == 800
        assert bot.restore(saved) == {}
        assert bot.read("max-speed") == 1000


def test_v1_settings_and_telemetry(v1_board: chassis.sim.Pty) -> None:
    with chassis.open(v1_board.path) as bot:
        assert bot.firmware == "v1.0.0"
        assert bot.read("geometry")["wheel_diameter_mm"] == 60
        bot.write("wheel-diameter", 65)
        assert bot.read("wheel-diameter") == 65
        saved = bot.settings()
        bot.write("pwm-max", 3000)
        bot.restore(saved)
        assert bot.read("pwm-max") == 3600
        frame = bot.wait_frame(timeout=2)
        assert isinstance(frame, chassis.Telemetry) and frame.battery_mv == 12_000
        assert bot.link_alive
        with pytest.raises(ValueError, match="not a v1.0.0"):
            bot.read("max-speed")
    # Settings written: the field's frame twice, then the three of the restore; 0x24 first.
    codes = [f[1] for f in (v1_board.received[i : i + 14] for i in range(0, len(v1_board.received), 14))]
    assert [c for c in codes if c in (0x23, 0x24, 0x40)] == [0x24, 0x23, 0x23, 0x24, 0x40]


def test_iterating_a_chassis_yields_telemetry(board: chassis.sim.Pty) -> None:
    with chassis.open(board.path) as bot:
        kinds = set()
        for frame in bot:
            kinds.add(type(frame).__name__)
            if {"Imu", "Encoders"} <= kinds:
                break
        assert bot.streams["imu"]["frames"] > 0
        assert bot.counters["frames"] > 0


def test_an_in_process_board_answers_a_read() -> None:
    board = chassis.sim.Board()
    board.receive(chassis.Read("motor-voltage").encode())
    parser = chassis.DownlinkParser()
    parser.expect_reply("motor-voltage")
    replies = []
    for ms in range(1, 200):
        board.advance(ms)
        replies += [f for f in parser.feed(board.transmit()) if isinstance(f, chassis.Reply)]
    replies += [f for f in parser.quiet(5) if isinstance(f, chassis.Reply)]
    assert replies == [chassis.Reply.decode(bytes.fromhex("23 0B 00 00 04 B0"))]


def test_bad_values_are_value_errors_with_nothing_sent(board: chassis.sim.Pty, v1_board: chassis.sim.Pty) -> None:
    # Out of range: refused, not clamped (the frame classes and the drivers alike).
    with pytest.raises(ValueError, match="out of range"):
        chassis.Motors([10**6, 2, 3, 4])
    with pytest.raises(ValueError, match="out of range"):
        chassis.Motors([10_001, 0, 0, 0], open_loop=True)
    # The limit itself is a frame (table 1D, mode 0x02: MOTO1 = 65535 big-endian, dir 00).
    assert chassis.Motors([65_535, 0, 0, 0]).encode() == bytes.fromhex("FF FE 02 FF FF 00 00 00 00 00 00 00")
    with chassis.open(board.path, firmware="2020") as bot:
        before = len(board.received)
        for call in (
            lambda: bot.set_motors([10**6, 2, 3, 4]),
            lambda: bot.set_motors([10**20, 0, 0, 0]),
            lambda: bot.set_motors([-10_001, 0, 0, 0], open_loop=True),
            lambda: bot.wait_frame(-1),
            lambda: bot.wait_frame(float("nan")),
            lambda: bot.wait_turn(-1),
            lambda: bot.wait_turn(float("nan")),
        ):
            with pytest.raises(ValueError):
                call()
        assert len(board.received) == before
        # An infinite or huge timeout waits (for ever): a frame comes.
        assert bot.wait_frame(float("inf")) is not None
        assert bot.wait_frame(1e300) is not None
        assert bot.wait_turn(float("inf")) is True  # no turn outstanding
    with chassis.open(v1_board.path, firmware="v1.0.0") as v1:
        before = len(v1_board.received)
        with pytest.raises(ValueError, match="out of range"):
            v1.set_motors([40_000, 0, 0, 0])
        with pytest.raises(ValueError):
            v1.wait_frame(-0.5)
        assert len(v1_board.received) == before
        assert v1.wait_frame(float("inf")) is not None


def test_write_takes_what_read_gives_and_refuses_what_no_owner_means(board: chassis.sim.Pty, v1_board: chassis.sim.Pty) -> None:
    with chassis.open(board.path, firmware="2020") as bot:
        bot.write("battery-range", (12.6, 10.5))
        assert bot.read("battery-range") == (12.6, 10.5)
        bot.write("battery-range", (None, None))
        assert bot.read("battery-range") == (None, None)
        mode = bot.read("system-mode")
        assert isinstance(mode, chassis.SystemMode)
        bot.write("system-mode", mode)
        assert bot.read("system-mode") == mode
        before = len(board.received)
        with pytest.raises(ValueError, match="not above cut-off"):
            bot.write("battery-range", (10.0, 12.0))
        with pytest.raises(TypeError, match="bool"):
            bot.write("max-speed", True)
        with pytest.raises(ValueError, match="out of range"):
            bot.write("max-speed", 10**30)
        saved = bot.settings()
        inverted = dict(saved, battery_full_centivolts=1000, battery_cutoff_centivolts=1200)
        with pytest.raises(ValueError, match="nothing was written"):
            bot.restore(inverted)
        # The refusals sent nothing; settings() only read (2C: settings frames, read codes
        # 0x11 and up; the writes' codes are 0x01..0x0C).
        assert all(f[2] == 0x80 and f[4] >= 0x11 for f in frames_2020(board.received[before:]))
    with chassis.open(v1_board.path, firmware="v1.0.0") as v1:
        before = len(v1_board.received)
        with pytest.raises(TypeError, match="bool"):
            v1.write("wheel-diameter", True)
        with pytest.raises(ValueError, match="out of range"):
            v1.write("wheel-diameter", 70_000)
        assert v1_board.received[before:] == b""



def test_v1_reads_name_the_fields_as_chassis_decode_does(v1_board: chassis.sim.Pty) -> None:
    with chassis.open(v1_board.path, firmware="v1.0.0") as v1:
        assert sorted(v1.read("system")) == [
            "encoder_direction_bits",
            "encoder_ppr",
            "motor_direction_bits",
            "pwm_max",
            "pwm_min",
        ]
        assert sorted(v1.read("motor-speeds")) == ["ctl", "speeds_raw", "type"]
        assert sorted(v1.read("body-velocity")) == ["ctl", "type", "vx_mm_s", "vy_mm_s", "wz_mrad_s"]
