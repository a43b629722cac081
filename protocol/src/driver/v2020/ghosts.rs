//! Late replies never answer a later read.
//!
//! A 2020 reply carries its register's code and nothing else: a reply that comes after its read
//! timed out would look like the answer to the next read of the same register. So a read that
//! went unanswered leaves a *ghost* until its reply comes or [`Config::late_reply_ms`] has
//! passed; a read of that register is not sent meanwhile, and a reply with the ghost's code is
//! taken as the late one. Late replies and timeouts teach the core how slow the board is.

use crate::command::Register;
use crate::driver::Config;

/// A read that went unanswered: its reply may still come, until `until_ms`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Ghost {
    pub(super) register: Register,
    /// How long before `until_ms` the read went (a few seconds at most: 32 bits, which keeps
    /// the four ghosts in 64 bytes).
    sent_before_ms: u32,
    pub(super) until_ms: u64,
}

impl Ghost {
    /// The read of `register` that went at `sent_ms`, whose reply may come until `until_ms`.
    pub(super) fn new(register: Register, sent_ms: u64, until_ms: u64) -> Self {
        let before = until_ms.saturating_sub(sent_ms);
        Ghost {
            register,
            sent_before_ms: u32::try_from(before).unwrap_or(u32::MAX),
            until_ms,
        }
    }

    /// When the read went.
    fn sent_ms(&self) -> u64 {
        self.until_ms.saturating_sub(u64::from(self.sent_before_ms))
    }
}

/// Unanswered reads remembered at once.
const GHOSTS: usize = 4;

/// The unanswered reads, and the board's slowness they showed.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Ghosts {
    slots: [Option<Ghost>; GHOSTS],
    /// The longest round trip of a late reply: later reads wait for it.
    late_rtt_ms: u32,
}

impl Ghosts {
    pub(super) const fn new() -> Self {
        Ghosts {
            slots: [None; GHOSTS],
            late_rtt_ms: 0,
        }
    }

    /// Remembers `ghost`, in a free place or in place of the one that ends first.
    pub(super) fn remember(&mut self, ghost: Ghost) {
        let mut place = 0;
        let mut first_end = u64::MAX;
        for (i, slot) in self.slots.iter().enumerate() {
            let Some(g) = slot else {
                place = i;
                break;
            };
            if g.until_ms < first_end {
                first_end = g.until_ms;
                place = i;
            }
        }
        if let Some(slot) = self.slots.get_mut(place) {
            *slot = Some(ghost);
        }
    }

    /// Forgets the ghosts whose reply can no longer come.
    pub(super) fn expire(&mut self, now: u64) {
        for g in &mut self.slots {
            if g.is_some_and(|g| now > g.until_ms) {
                *g = None;
            }
        }
    }

    /// The ghost of `register` whose reply may still come at `now`.
    pub(super) fn live(&self, register: Register, now: u64) -> Option<Ghost> {
        self.of(register).filter(|g| now <= g.until_ms)
    }

    /// The ghost of `register`, if any.
    pub(super) fn of(&self, register: Register) -> Option<Ghost> {
        self.slots
            .iter()
            .flatten()
            .find(|g| g.register == register)
            .copied()
    }

    /// A reply with `code` came: if it is a ghost's, that read is answered at last (late), and
    /// its round trip teaches the core how slow the board is.
    pub(super) fn take(&mut self, code: u8, now: u64) -> bool {
        for g in &mut self.slots {
            if let Some(ghost) = *g {
                if ghost.register.reply_code() == code && now <= ghost.until_ms {
                    *g = None;
                    let rtt =
                        u32::try_from(now.saturating_sub(ghost.sent_ms())).unwrap_or(u32::MAX);
                    self.late_rtt_ms = self.late_rtt_ms.max(rtt);
                    return true;
                }
            }
        }
        false
    }

    /// A read was answered in time after `rtt` ms: the learnt round trip moves back towards
    /// what the board does.
    pub(super) fn answered(&mut self, rtt: u32) {
        let decayed = self.late_rtt_ms.saturating_sub(self.late_rtt_ms / 8);
        self.late_rtt_ms = decayed.max(rtt.min(self.late_rtt_ms));
    }

    /// A read waited `waited` ms for nothing: the board may be slower than that. Reads from
    /// now on wait twice as long (within [`reply_timeout_ms`](Self::reply_timeout_ms)'s bound)
    /// until replies show otherwise.
    pub(super) fn timed_out(&mut self, waited: u32) {
        self.late_rtt_ms = self.late_rtt_ms.max(waited.saturating_mul(2));
    }

    /// How long a read waits for its reply now: [`Config::reply_timeout_ms`], or longer once a
    /// timeout or a late reply has shown the board to be slower (at most
    /// [`Config::late_reply_ms`] more).
    pub(super) fn reply_timeout_ms(&self, config: &Config) -> u64 {
        let base = u64::from(config.reply_timeout_ms());
        let rtt = u64::from(self.late_rtt_ms);
        let learnt = rtt
            .saturating_add(rtt / 4)
            .saturating_add(u64::from(config.idle_ms));
        base.max(learnt)
            .min(base.saturating_add(u64::from(config.late_reply_ms)))
    }
}
