"""The independent encoder: a message declared in `msgs` serialized by `rosbags` (its own CDR
serializer over the ROS 2 message definitions it ships), to compare with the bytes Cyclone DDS
or the node produced for the same values.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from cyclonedds.idl import IdlStruct
from rosbags.typesys import Stores, get_typestore

from .msgs import ROS_NAME

STORE = get_typestore(Stores.ROS2_JAZZY)
"""The ROS 2 Jazzy message definitions, as `rosbags` ships them."""

_NUMPY = {"float64": np.float64, "float32": np.float32, "uint8": np.uint8, "int32": np.int32}


def to_rosbags(message: IdlStruct) -> Any:
    """The `rosbags` message with the same field values as `message` (a type of `msgs`)."""
    name = ROS_NAME[type(message)]
    cls = STORE.types[name]
    _, fields = STORE.fielddefs[name]
    values = {}
    for fname, (node, desc) in fields:
        value = getattr(message, fname)
        values[fname] = _convert(value, node, desc)
    return cls(**values)


def _convert(value: Any, node: Any, desc: Any) -> Any:
    kind = int(node)
    if kind == 2:  # a named (nested) message
        return to_rosbags(value)
    if kind == 1:  # a base type
        return value
    # kind 3 (fixed array) or 4 (sequence): (element, length)
    (enode, edesc), _ = desc
    if int(enode) == 1 and edesc[0] in _NUMPY:
        return np.array(value, dtype=_NUMPY[edesc[0]])
    return [_convert(v, enode, edesc) for v in value]


def rosbags_bytes(message: IdlStruct) -> bytes:
    """`message` serialized by `rosbags` (little-endian CDR, with its 4-byte encapsulation
    header)."""
    return bytes(STORE.serialize_cdr(to_rosbags(message), ROS_NAME[type(message)]))


def payload(sample: bytes) -> tuple[bytes, bytes]:
    """A serialized sample split into its encapsulation header (4 bytes) and its payload,
    without the padding the header's options say was added at the end (XTypes 7.6.3.1.2: the
    low two bits of the options are the count of padding bytes)."""
    if len(sample) < 4:
        raise ValueError(f"a serialized sample of {len(sample)} bytes has no header")
    header, body = sample[:4], sample[4:]
    padding = header[3] & 0x3
    if padding > len(body):
        raise ValueError(f"the header claims {padding} bytes of padding in {len(body)}")
    return header, body[: len(body) - padding]


def wire_mismatch(received: bytes, expected: bytes) -> str | None:
    """How a sample received from the wire differs from `expected` (a serialized sample, such as
    `rosbags_bytes` gives), or None if it is the same.

    The same means: the same representation (the header's first two bytes), and the same CDR
    stream once the padding the header's options declare is removed, except that the received
    stream may end with up to three zero bytes that take it to a multiple of 4 (a DDS sample
    travels in an RTPS submessage, whose length is a multiple of 4: Cyclone DDS pads so without
    declaring it in the options)."""
    try:
        got_header, got = payload(received)
        want_header, want = payload(expected)
    except ValueError as e:
        return str(e)
    if got_header[:2] != want_header[:2]:
        return f"representation {got_header[:2].hex()}, expected {want_header[:2].hex()}"
    tail = got[len(want) :]
    if got[: len(want)] != want or len(tail) > 3 or any(tail) or (tail and len(got) % 4):
        return f"CDR differs:\n received {got.hex()}\n expected {want.hex()}"
    return None


def same_field_values(a: IdlStruct, b: IdlStruct) -> bool:
    """Whether two messages of `msgs` hold the same values, every number compared as the bits of
    a double (so NaN equals NaN, -0.0 differs from 0.0, and 0 equals 0.0)."""
    import struct

    def norm(v: Any) -> Any:
        if dataclasses.is_dataclass(v):
            return tuple(norm(getattr(v, f.name)) for f in dataclasses.fields(v))
        if isinstance(v, bool):
            return v
        if isinstance(v, (int, float)):
            return struct.pack("<d", v)
        if isinstance(v, (list, tuple)):
            return tuple(norm(x) for x in v)
        return v

    return type(a) is type(b) and norm(a) == norm(b)
