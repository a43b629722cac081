//! The line from the board to the master: bytes leave at 115 200 bps (10 bits a byte), a
//! bounded buffer holds them, and injected faults drop, change or add bytes on the way. Both
//! boards (2020 and [v1.0.0](super::v1)) send through one.

use heapless::Deque;

/// Bytes the board's line can hold for the master before it drops telemetry: a second of
/// telemetry (1 782 bytes) fits, as it does in a host's serial buffer, so a master that reads
/// once a second loses nothing.
pub const OUT_CAPACITY: usize = 2_048;

/// Time a byte takes on the wire at 115 200 bps, 8N1 (10 bits), in ns.
const BYTE_NS: u64 = 86_806;

/// Faults to inject into what the board sends; rates are per million bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Faults {
    /// A byte is lost.
    pub drop_per_million: u32,
    /// A byte arrives changed.
    pub corrupt_per_million: u32,
    /// A spurious byte arrives.
    pub insert_per_million: u32,
    /// The board sends no telemetry at all (a dead link, or a hung board).
    pub telemetry_stopped: bool,
    /// The board sends no replies.
    pub replies_stopped: bool,
}

/// The board's side of the line: what it has sent and when each frame goes on the wire, the
/// faults, and the random numbers (of the faults and of the board's noise).
#[derive(Clone, Debug)]
pub(super) struct Line {
    pub(super) faults: Faults,
    out: Deque<u8, OUT_CAPACITY>,
    /// The frames in `out` as (when their first byte starts on the wire in ns, length): bytes
    /// leave at the line's pace (10 bits a byte at 115 200 bps), a frame from the moment it is
    /// sent or the moment the one before it has left.
    on_wire: Deque<(u64, u16), 160>,
    /// Bytes of the front frame of `on_wire` already handed over.
    front_taken: u16,
    /// When the last byte queued will have left, in ns.
    line_free_ns: u64,
    rng: u64,
    /// Frames dropped because the buffer was full.
    pub(super) dropped_frames: u32,
}

impl Line {
    /// An empty line, no faults; random numbers from `seed`.
    pub(super) fn new(seed: u64) -> Self {
        Line {
            faults: Faults::default(),
            out: Deque::new(),
            on_wire: Deque::new(),
            front_taken: 0,
            line_free_ns: 0,
            rng: seed | 1,
            dropped_frames: 0,
        }
    }

    /// Bytes waiting to go.
    #[cfg(feature = "defmt")]
    pub(super) fn queued(&self) -> usize {
        self.out.len()
    }

    /// Copies bytes that have crossed the wire by `now_ms` into `buf`, with the faults
    /// applied; returns how many.
    pub(super) fn transmit(&mut self, now_ms: u64, buf: &mut [u8]) -> usize {
        let mut n = 0;
        let now_ns = now_ms.saturating_mul(1_000_000);
        while n < buf.len() {
            // Only the bytes that have crossed the wire by now.
            let Some(&(start, len)) = self.on_wire.front() else {
                break;
            };
            let taken = self.front_taken.saturating_add(1);
            if start.saturating_add(u64::from(taken).saturating_mul(BYTE_NS)) > now_ns {
                break;
            }
            let Some(byte) = self.out.pop_front() else {
                break;
            };
            if taken >= len {
                let _ = self.on_wire.pop_front();
                self.front_taken = 0;
            } else {
                self.front_taken = taken;
            }
            if self.chance(self.faults.drop_per_million) {
                continue;
            }
            let byte = if self.chance(self.faults.corrupt_per_million) {
                byte ^ (self.next_random() as u8 | 1)
            } else {
                byte
            };
            if self.chance(self.faults.insert_per_million) {
                if let Some(slot) = buf.get_mut(n) {
                    *slot = self.next_random() as u8;
                    n = n.saturating_add(1);
                }
            }
            if let Some(slot) = buf.get_mut(n) {
                *slot = byte;
                n = n.saturating_add(1);
            } else {
                // No room left for it after an insertion: keep it for the next call.
                let _ = self.out.push_front(byte);
            }
        }
        n
    }

    /// Whether a byte has crossed the wire by `now_ms`.
    pub(super) fn byte_arrived(&self, now_ms: u64) -> bool {
        let now_ns = now_ms.saturating_mul(1_000_000);
        self.on_wire.front().is_some_and(|&(start, _)| {
            let next = u64::from(self.front_taken.saturating_add(1));
            start.saturating_add(next.saturating_mul(BYTE_NS)) <= now_ns
        })
    }

    /// Queues a frame sent at `now_ms`; a frame that does not fit is dropped and counted.
    pub(super) fn send(&mut self, now_ms: u64, bytes: &[u8]) {
        let room = self.out.capacity().saturating_sub(self.out.len());
        let (Ok(len), false) = (u16::try_from(bytes.len()), room < bytes.len()) else {
            self.dropped_frames = self.dropped_frames.wrapping_add(1);
            return;
        };
        let start = self.line_free_ns.max(now_ms.saturating_mul(1_000_000));
        if self.on_wire.push_back((start, len)).is_err() {
            self.dropped_frames = self.dropped_frames.wrapping_add(1);
            return;
        }
        self.line_free_ns = start.saturating_add(u64::from(len).saturating_mul(BYTE_NS));
        for b in bytes {
            let _ = self.out.push_back(*b);
        }
    }

    /// True `per_million` times in a million (never for 0, and then no number is drawn).
    pub(super) fn chance(&mut self, per_million: u32) -> bool {
        per_million > 0 && (self.next_random() % 1_000_000) < u64::from(per_million)
    }

    /// xorshift64: enough for noise and faults, and the same on every target.
    pub(super) fn next_random(&mut self) -> u64 {
        let mut x = self.rng;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.rng = x;
        x
    }
}
