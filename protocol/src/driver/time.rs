//! [`Timebase`]: the driver's own milliseconds, monotonic whatever the caller's clock does.
//!
//! The core is handed the caller's clock reading on every call. It keeps its own time from the
//! **differences between readings, taken on their low 32 bits**, so:
//!
//! * a `u64` millisecond clock runs as it is: the core's time equals the clock's readings;
//! * a `u32` millisecond tick counter handed over as it is (`|| millis() as u64`, what many HALs
//!   give) wraps after 49.7 days, and the wrap is one millisecond like any other;
//! * a clock that goes back (an NTP step, a board's RTC set) makes time stand still until the
//!   clock is past where it was: time never goes back, so no deadline moves away;
//! * a clock that jumps forward moves time forward by the jump.
//!
//! The one limit: two readings more than 2³¹ ms (24.8 days) apart with no call in between are
//! taken as a clock that went back. Every shell reads the clock many times a second.

/// The core's monotonic milliseconds, built from the caller's clock readings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Timebase {
    /// The low 32 bits of the latest reading that moved time on (or the first).
    last: Option<u32>,
    /// The core's time at that reading.
    now: u64,
}

impl Timebase {
    /// Before the first reading.
    pub(crate) const fn new() -> Self {
        Timebase { last: None, now: 0 }
    }

    /// The core's time for the caller's reading `raw`, without keeping it.
    pub(crate) const fn peek(&self, raw: u64) -> u64 {
        match self.last {
            None => raw,
            Some(last) => self.now.saturating_add(Self::forward(last, raw)),
        }
    }

    /// Takes the caller's reading `raw` and gives the core's time for it.
    pub(crate) fn advance(&mut self, raw: u64) -> u64 {
        let low = raw as u32;
        match self.last {
            None => {
                self.last = Some(low);
                self.now = raw;
            }
            Some(last) => {
                let step = Self::forward(last, raw);
                if step > 0 {
                    self.now = self.now.saturating_add(step);
                    self.last = Some(low);
                }
            }
        }
        self.now
    }

    /// The core's latest time (0 before the first reading).
    pub(crate) const fn now(&self) -> u64 {
        self.now
    }

    /// How far `raw` is past `last`, in ms: 0 if it is behind (the clock went back).
    const fn forward(last: u32, raw: u64) -> u64 {
        let step = (raw as u32).wrapping_sub(last);
        if step > i32::MAX as u32 {
            0
        } else {
            step as u64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Timebase;

    #[test]
    fn a_u64_clock_runs_as_it_is() {
        let mut t = Timebase::new();
        assert_eq!(t.advance(5_000_000_000), 5_000_000_000);
        assert_eq!(t.advance(5_000_000_010), 5_000_000_010);
        assert_eq!(t.peek(5_000_000_020), 5_000_000_020);
        assert_eq!(t.now(), 5_000_000_010);
    }

    #[test]
    fn a_u32_counter_wraps_as_one_more_millisecond() {
        let mut t = Timebase::new();
        let before = u64::from(u32::MAX) - 2;
        assert_eq!(t.advance(before), before);
        assert_eq!(t.advance(u64::from(u32::MAX)), before + 2);
        assert_eq!(t.advance(0), before + 3);
        assert_eq!(t.advance(100), before + 103);
    }

    #[test]
    fn a_clock_that_goes_back_stands_still_until_it_is_past_where_it_was() {
        let mut t = Timebase::new();
        assert_eq!(t.advance(1_000), 1_000);
        assert_eq!(t.advance(950), 1_000);
        assert_eq!(t.advance(990), 1_000);
        assert_eq!(t.advance(1_001), 1_001);
        assert_eq!(t.advance(11_001), 11_001, "a jump forward is taken");
    }
}
