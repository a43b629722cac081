"""A stand-in for the node, to test the peer itself: publishes the samples of `samples.BY_TOPIC`
on their topics, `COUNT` rounds 50 ms apart once a reader has matched each topic, then exits.

    python -m chassis_peer.talker COUNT
"""

import os
import sys
import time

from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.topic import Topic

from .dds import PUBLISHED, ROS_QOS, dds_topic
from .samples import BY_TOPIC


def main() -> int:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    participant = DomainParticipant(int(os.environ.get("ROS_DOMAIN_ID", "0")))
    writers = {}
    for name, cls in PUBLISHED.items():
        topic = Topic(participant, dds_topic(name), cls, qos=ROS_QOS)
        writers[name] = DataWriter(participant, topic, qos=ROS_QOS)
    end = time.monotonic() + 10.0
    while not all(w.get_matched_subscriptions() for w in writers.values()):
        if time.monotonic() > end:
            print("talker: no reader matched within 10 s", file=sys.stderr)
            return 1
        time.sleep(0.02)
    for _ in range(count):
        for name, writer in writers.items():
            writer.write(BY_TOPIC[name]())
        time.sleep(0.05)
    for writer in writers.values():
        writer.wait_for_acks(2_000_000_000)
    return 0


if __name__ == "__main__":
    sys.exit(main())
