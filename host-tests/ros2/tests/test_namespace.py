"""The private network namespace, and the peer against a stand-in publisher in another
process (so that the samples cross the namespace's loopback, not Cyclone's in-process path)."""

import subprocess
import sys
from pathlib import Path

from chassis_peer import cdr, dds, netns, samples


def test_only_loopback_in_the_namespace():
    """The tests run where `ip -brief addr` lists `lo` alone: no DDS packet can leave."""
    assert netns.entered()
    assert netns.interfaces() == ["lo"]


def test_peer_receives_every_topic_bit_exact_from_another_process():
    """Samples of each type the node publishes, written by another process over loopback, reach
    the peer with their raw bytes equal to `rosbags`' for the same values and decode to them."""
    with dds.Peer() as peer:
        talker = subprocess.run(
            [sys.executable, "-m", "chassis_peer.talker", "10"],
            cwd=Path(__file__).resolve().parents[1],
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert talker.returncode == 0, talker.stderr
        for topic, make in samples.BY_TOPIC.items():
            got = peer.wait_for(topic, 5.0)
            assert got is not None, f"nothing on {topic}"
            expected = make()
            mismatch = cdr.wire_mismatch(got.raw, cdr.rosbags_bytes(expected))
            assert mismatch is None, f"{topic}: {mismatch}"
            assert cdr.same_field_values(got.value, expected)
        # Reliable QoS over loopback: all of them.
        counts = {t: len(peer.samples(t)) for t in samples.BY_TOPIC}
        assert all(n == 10 for n in counts.values()), counts
