"""The peer: a Cyclone DDS participant that publishes `/cmd_vel` and records every sample the
node publishes, with its bytes as they came off the wire.

ROS 2 names a topic `/x` `rt/x` in DDS, and uses reliable, volatile, keep-last-10 QoS by
default; the node keeps to both.
"""

import os
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable, Optional

from cyclonedds._clayer import ddspy_take
from cyclonedds.core import InstanceState, Policy, Qos, SampleState, ViewState
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from . import msgs

ROS_QOS = Qos(
    Policy.Reliability.Reliable(duration(milliseconds=100)),
    Policy.Durability.Volatile,
    Policy.History.KeepLast(10),
)
"""ROS 2's default QoS: reliable, volatile, keep last 10."""

PUBLISHED = {
    "/odom": msgs.Odometry_,
    "/tf": msgs.TFMessage_,
    "/imu/data_raw": msgs.Imu_,
    "/battery_state": msgs.BatteryState_,
    "/diagnostics": msgs.DiagnosticArray_,
}
"""The topics the node publishes and their types."""


def dds_topic(ros_name: str) -> str:
    """The DDS topic of a ROS topic (`/cmd_vel` → `rt/cmd_vel`)."""
    return "rt/" + ros_name.lstrip("/")


@dataclass
class Received:
    """One sample the peer received."""

    at: float
    """When the peer took it (`time.monotonic()`)."""
    raw: bytes
    """Its serialized bytes as received: the 4-byte encapsulation header, then the CDR."""
    value: Any
    """It decoded with the declared type."""


class Peer:
    """A participant on `ROS_DOMAIN_ID` (0 if unset) with a `/cmd_vel` writer (`Twist`, or
    `TwistStamped` if `stamped`) and a reader on each topic of `PUBLISHED`, drained by a
    thread into `received[topic]`."""

    def __init__(self, stamped: bool = False, topics: Optional[dict] = None):
        domain = int(os.environ.get("ROS_DOMAIN_ID", "0"))
        self.participant = DomainParticipant(domain)
        self.stamped = stamped
        cmd_type = msgs.TwistStamped_ if stamped else msgs.Twist_
        cmd_topic = Topic(self.participant, dds_topic("/cmd_vel"), cmd_type, qos=ROS_QOS)
        self.cmd_vel = DataWriter(self.participant, cmd_topic, qos=ROS_QOS)
        self.readers: dict[str, tuple[DataReader, type]] = {}
        for name, cls in (topics if topics is not None else PUBLISHED).items():
            topic = Topic(self.participant, dds_topic(name), cls, qos=ROS_QOS)
            self.readers[name] = (DataReader(self.participant, topic, qos=ROS_QOS), cls)
        self.received: dict[str, list[Received]] = {name: [] for name in self.readers}
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._drain, daemon=True)
        self._thread.start()

    def _drain(self) -> None:
        mask = SampleState.Any | ViewState.Any | InstanceState.Any
        while not self._stop.is_set():
            for name, (reader, cls) in self.readers.items():
                # The raw take: the sample's bytes as the writer serialized them.
                got = ddspy_take(reader._ref, mask, 64)
                if isinstance(got, int):
                    continue
                now = time.monotonic()
                for data, info in got:
                    if not info.valid_data:
                        continue
                    raw = bytes(data)
                    item = Received(now, raw, cls.deserialize(raw))
                    with self._lock:
                        self.received[name].append(item)
            self._stop.wait(0.002)

    def close(self) -> None:
        """Stops the draining thread (the participant goes with the object)."""
        self._stop.set()
        self._thread.join()

    def __enter__(self) -> "Peer":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # What came in.

    def samples(self, topic: str, since: float = 0.0) -> list[Received]:
        """The samples of `topic` taken at or after `since` (monotonic seconds)."""
        with self._lock:
            return [r for r in self.received[topic] if r.at >= since]

    def latest(self, topic: str) -> Optional[Received]:
        """The last sample of `topic`, if any."""
        with self._lock:
            seen = self.received[topic]
            return seen[-1] if seen else None

    def wait_for(
        self,
        topic: str,
        timeout: float,
        since: float = 0.0,
        where: Callable[[Any], bool] = lambda _: True,
    ) -> Optional[Received]:
        """The first sample of `topic` taken at or after `since` whose value satisfies `where`,
        waiting up to `timeout` seconds; None if none came."""
        end = time.monotonic() + timeout
        while True:
            for r in self.samples(topic, since):
                if where(r.value):
                    return r
            if time.monotonic() >= end:
                return None
            time.sleep(0.01)

    # What goes out.

    def matched(self) -> bool:
        """Whether the node's `/cmd_vel` reader has matched the writer."""
        return bool(self.cmd_vel.get_matched_subscriptions())

    def wait_matched(self, timeout: float, topics: Optional[list[str]] = None) -> bool:
        """Waits up to `timeout` s for the node's `/cmd_vel` reader and the node's writer on each
        of `topics` (all the peer reads if None)."""
        names = list(self.readers) if topics is None else topics
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.matched() and all(
                self.readers[name][0].get_matched_publications() for name in names
            ):
                return True
            time.sleep(0.02)
        return False

    def send(self, vx: float = 0.0, vy: float = 0.0, wz: float = 0.0) -> None:
        """Publishes one `/cmd_vel`: vx, vy (m/s), wz (rad/s)."""
        twist = msgs.Twist_(msgs.Vector3_(vx, vy, 0.0), msgs.Vector3_(0.0, 0.0, wz))
        if self.stamped:
            ns = time.time_ns()
            header = msgs.Header_(msgs.Time_(ns // 1_000_000_000, ns % 1_000_000_000), "base_link")
            self.cmd_vel.write(msgs.TwistStamped_(header, twist))
        else:
            self.cmd_vel.write(twist)

    def drive(self, vx: float, vy: float, wz: float, seconds: float, rate_hz: float = 20.0) -> None:
        """Publishes the same `/cmd_vel` at `rate_hz` for `seconds`, on the clock (no drift)."""
        start = time.monotonic()
        n = 0
        while True:
            due = start + n / rate_hz
            if due - start >= seconds:
                break
            pause = due - time.monotonic()
            if pause > 0:
                time.sleep(pause)
            self.send(vx, vy, wz)
            n += 1
