"""The hand-declared message types against the ROS 2 definitions `rosbags` ships and against
bytes worked out by hand from the CDR rules."""

import dataclasses
import struct

import pytest

from chassis_peer import cdr, msgs, samples

# What `rosbags` calls the base types the declarations use.
_BASE = {"float64", "float32", "int32", "uint32", "uint8", "byte", "bool", "string"}


@pytest.mark.parametrize("cls", list(msgs.ROS_NAME), ids=lambda c: msgs.ROS_NAME[c])
def test_fields_are_those_of_the_ros_definition(cls):
    """Each declaration has the fields of the ROS 2 message, in its order (CDR has no field
    names: an order mistake would pass unnoticed between two ends that share it)."""
    _, fields = cdr.STORE.fielddefs[msgs.ROS_NAME[cls]]
    ours = [f.name for f in dataclasses.fields(cls)]
    theirs = [name for name, _ in fields]
    assert ours == theirs, f"{cls.__name__}: declared {ours}, ROS 2 has {theirs}"


@pytest.mark.parametrize("name", list(samples.ALL))
def test_own_bytes_equal_rosbags_bytes(name):
    """Cyclone DDS serializing a declared type gives the bytes `rosbags` gives for the same
    values, for values at the edges (alignment after strings, NaN, infinities, -0.0)."""
    sample = samples.ALL[name]()
    ours = sample.serialize()
    theirs = cdr.rosbags_bytes(sample)
    assert ours == theirs, f"{name}:\n cyclonedds {ours.hex()}\n rosbags    {theirs.hex()}"


@pytest.mark.parametrize("name", list(samples.ALL))
def test_round_trip(name):
    """A declared type decodes its own bytes to the same values, bit for bit."""
    sample = samples.ALL[name]()
    back = type(sample).deserialize(sample.serialize())
    assert cdr.same_field_values(back, sample), f"{name}: {sample} came back as {back}"


def test_twist_golden_bytes():
    """`Twist` (linear 1.0, 0, 0; angular 0, 0, -0.5) in bytes worked out by hand: the
    little-endian CDR header 00 01 00 00, then six IEEE-754 doubles little-endian."""
    twist = msgs.Twist_(msgs.Vector3_(1.0, 0.0, 0.0), msgs.Vector3_(0.0, 0.0, -0.5))
    expected = (
        bytes([0x00, 0x01, 0x00, 0x00])
        + bytes([0, 0, 0, 0, 0, 0, 0xF0, 0x3F])  # 1.0
        + bytes(8 * 4)  # 0.0 four times
        + bytes([0, 0, 0, 0, 0, 0, 0xE0, 0xBF])  # -0.5
    )
    assert twist.serialize() == expected
    assert cdr.rosbags_bytes(twist) == expected


def test_header_golden_bytes_align_after_string():
    """A `TransformStamped` with frame "ab" and child "c": sec, nanosec, the string's length
    (3, with its NUL), "ab\\0", one byte of padding to the next 4, length 2, "c\\0", then padding
    to 8 (offsets count from after the 4-byte header) before the first double."""
    msg = msgs.TransformStamped_(
        msgs.Header_(msgs.Time_(-1, 2), "ab"),
        "c",
        msgs.Transform_(msgs.Vector3_(2.0, 0, 0), msgs.Quaternion_(0, 0, 0, 1)),
    )
    body = (
        struct.pack("<iI", -1, 2)  # offset 0..8
        + struct.pack("<I", 3) + b"ab\x00" + b"\x00"  # 8..16
        + struct.pack("<I", 2) + b"c\x00" + b"\x00\x00"  # 16..24, already 8-aligned
        + struct.pack("<7d", 2.0, 0, 0, 0, 0, 0, 1.0)
    )
    expected = b"\x00\x01\x00\x00" + body
    assert msg.serialize() == expected
    assert cdr.rosbags_bytes(msg) == expected


def test_payload_strips_declared_padding():
    """The encapsulation options' low two bits count padding at the end (XTypes 7.6.3.1.2)."""
    assert cdr.payload(b"\x00\x01\x00\x02" + b"abcd\x00\x00") == (b"\x00\x01\x00\x02", b"abcd")
    assert cdr.payload(b"\x00\x01\x00\x00" + b"abcd") == (b"\x00\x01\x00\x00", b"abcd")
    with pytest.raises(ValueError):
        cdr.payload(b"\x00\x01")


def test_wire_mismatch_allows_only_zero_padding_to_four():
    """A received stream may carry up to three zero bytes to a multiple of 4, nothing else."""
    want = b"\x00\x01\x00\x00" + b"abcde"
    assert cdr.wire_mismatch(want, want) is None
    assert cdr.wire_mismatch(want + b"\x00\x00\x00", want) is None
    assert cdr.wire_mismatch(want + b"\x00\x00\x01", want) is not None
    assert cdr.wire_mismatch(want + b"\x00" * 7, want) is not None
    assert cdr.wire_mismatch(b"\x00\x00\x00\x00abcde", want) is not None  # big-endian CDR
    assert cdr.wire_mismatch(b"\x00\x01\x00\x00abcdf", want) is not None


def test_yaw_of_quaternion():
    """A rotation of 90° about z (w = cos 45°, z = sin 45°) is yaw π/2."""
    import math

    s = math.sqrt(0.5)
    assert math.isclose(msgs.yaw_of(msgs.Quaternion_(0, 0, s, s)), math.pi / 2)
    assert math.isclose(msgs.yaw_of(msgs.Quaternion_(0, 0, -1, 0)), math.pi) or math.isclose(
        msgs.yaw_of(msgs.Quaternion_(0, 0, -1, 0)), -math.pi
    )
