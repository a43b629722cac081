//! A USB-UART adapter between the line and the host: it hands the host the received bytes in
//! packets (at most 62 bytes, sent at a USB frame, every 1 ms), a packet going out when it is
//! full or when the adapter's latency timer expires (1 ms for an adapter that sends whatever it
//! has at every frame; 16 ms, the common default of another kind). So the host sees gaps
//! between packets that are not quiet on the line, and a quiet line it sees only as a longer
//! gap between packets.
//!
//! Two hosts read it: one that reports [`DownlinkParser::quiet`] only when no packet came for
//! more than a threshold it sets, and the naive read loop that reports
//! [`DownlinkParser::idle`] after every packet.

use crate::board::{SentFrame, Timed};
use crate::channel::Received;
use crate::score::{Judge, Score};
use chassis_protocol::{Downlink, DownlinkParser};

/// How an adapter packs the line into USB packets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Adapter {
    /// Most bytes in one packet (62: a 64-byte packet less two status bytes).
    pub max_packet: usize,
    /// The latency timer, in ms: what the adapter holds is sent when it expires (at least 1).
    pub latency_ms: u64,
}

impl Adapter {
    /// An adapter that sends what it holds at every 1 ms USB frame.
    pub const EVERY_MS: Adapter = Adapter {
        max_packet: 62,
        latency_ms: 1,
    };

    /// An adapter that holds bytes until 62 are in or its 16 ms latency timer expires.
    pub const LATENCY_16_MS: Adapter = Adapter {
        max_packet: 62,
        latency_ms: 16,
    };
}

/// One packet as the host gets it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Packet {
    /// Offset one past its last byte in the received bytes (it starts where the one before ends).
    pub end: usize,
    /// When the host gets it, in ms.
    pub at_ms: u64,
}

/// When each received byte was whole at the adapter, µs: a sent byte when it was sent
/// ([`Timed::byte_done_us`]), an inserted byte with the byte before it.
pub fn received_us(timed: &Timed, rx: &Received) -> Vec<u64> {
    let done = timed.byte_done_us();
    let mut last = 0;
    rx.origin
        .iter()
        .map(|origin| {
            if let Some(at) = origin.and_then(|i| done.get(i)) {
                last = *at;
            }
            last
        })
        .collect()
}

/// The packets `adapter` sends of bytes received at `times_us` (one per received byte, in
/// order). The latency timer restarts whenever it expires or a packet goes out.
pub fn packets(adapter: Adapter, times_us: &[u64]) -> Vec<Packet> {
    let latency = adapter.latency_ms.max(1);
    let max = adapter.max_packet.max(1);
    let mut out = Vec::new();
    let (mut from, mut arrived, mut timer_ms) = (0usize, 0usize, 0u64);
    let mut tick = 0u64;
    while from < times_us.len() {
        tick += 1;
        while times_us.get(arrived).is_some_and(|t| *t <= tick * 1_000) {
            arrived += 1;
        }
        while arrived - from >= max {
            from += max;
            out.push(Packet {
                end: from,
                at_ms: tick,
            });
            timer_ms = tick;
        }
        if tick - timer_ms >= latency {
            if arrived > from {
                from = arrived;
                out.push(Packet {
                    end: from,
                    at_ms: tick,
                });
            }
            timer_ms = tick;
        }
    }
    out
}

/// What the host tells the parser between packets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Host {
    /// `quiet(ms)` with the gap's length when no packet came for more than this many ms.
    QuietAfter(u64),
    /// `idle()` after every packet: a naive read loop.
    IdleEveryPacket,
}

/// Runs the packets of `rx` into a new parser as `host` does, each fed with
/// [`DownlinkParser::push_slice`], then `idle()` at the end; scores what comes out against
/// `sent` (latency in bytes counts from a frame's last byte to the last byte of the packet, or
/// the slice, that brought it out).
pub fn score_packets(sent: &[SentFrame], rx: &Received, packets: &[Packet], host: Host) -> Score {
    let mut score = Score::start(sent, rx);
    let mut parser = DownlinkParser::new();
    let mut judge = Judge::new(sent, rx);
    let mut emit = |frame: Downlink, now: usize, buffered: usize, score: &mut Score| {
        judge.judge(frame, (now - buffered, now, false), score, &mut |_| {});
    };
    let (mut from, mut last_ms) = (0usize, None);
    for packet in packets {
        let gap = last_ms.map_or(0, |last| packet.at_ms - last);
        if matches!(host, Host::QuietAfter(threshold) if gap > threshold) && from > 0 {
            while let Some(frame) = parser.quiet(gap as u32) {
                emit(frame, from - 1, parser.buffered(), &mut score);
            }
        }
        let mut rest = rx.bytes.get(from..packet.end).unwrap_or(&[]);
        while let (Some(frame), later) = parser.push_slice(rest) {
            rest = later;
            emit(
                frame,
                packet.end - rest.len() - 1,
                parser.buffered(),
                &mut score,
            );
        }
        if host == Host::IdleEveryPacket {
            while let Some(frame) = parser.idle() {
                emit(frame, packet.end - 1, parser.buffered(), &mut score);
            }
        }
        from = packet.end;
        last_ms = Some(packet.at_ms);
    }
    while let Some(frame) = parser.idle() {
        emit(frame, from.saturating_sub(1), parser.buffered(), &mut score);
    }
    score.finish(sent, rx, &parser)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packets_are_full_or_flushed_by_the_timer() {
        // A byte every 0.1 ms for 20 ms, then nothing.
        let times: Vec<u64> = (1..=200).map(|i| i * 100).collect();
        let every_ms = packets(Adapter::EVERY_MS, &times);
        assert_eq!(every_ms.len(), 20);
        assert!(every_ms.iter().all(|p| p.end % 10 == 0));
        let held = packets(Adapter::LATENCY_16_MS, &times);
        // Full at 62, 124 and 186 bytes (sent at the frames after 6.2, 12.4 and 18.6 ms), each
        // restarting the timer; the rest 16 ms after the last.
        let ends: Vec<(usize, u64)> = held.iter().map(|p| (p.end, p.at_ms)).collect();
        assert_eq!(ends, [(62, 7), (124, 13), (186, 19), (200, 35)]);
    }
}
