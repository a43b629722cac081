//! When a modelled board sends its next reply, for both generations' boards: replies come at
//! random times, each gap drawn between half and one and a half times the mean.

use rand::Rng;

/// When a board's next reply is due.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Replies {
    /// Mean microseconds between replies (0: none).
    every_us: u64,
    /// When the next reply is due, µs (`u64::MAX`: never).
    next_us: u64,
}

impl Replies {
    /// `per_second` replies on average (0: none), the first drawn from `rng` within one mean gap.
    pub(crate) fn new(rng: &mut impl Rng, per_second: f64) -> Self {
        let every_us = if per_second > 0.0 {
            (1e6 / per_second) as u64
        } else {
            0
        };
        Replies {
            every_us,
            next_us: if every_us > 0 {
                rng.random_range(0..every_us)
            } else {
                u64::MAX
            },
        }
    }

    /// When the next reply is due, µs (`u64::MAX`: never).
    pub(crate) fn next_us(&self) -> u64 {
        self.next_us
    }

    /// The reply that was due is sent: the next one falls due a gap drawn from `rng` later.
    pub(crate) fn sent(&mut self, rng: &mut impl Rng) {
        let every = self.every_us;
        self.next_us += rng.random_range(every / 2..=every * 3 / 2).max(1);
    }
}
