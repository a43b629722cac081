//! The `/cmd_vel` watchdog: the velocity last commanded is held while commands keep coming,
//! and the chassis is stopped once they have been silent for the timeout. A stamped command
//! (`TwistStamped`) older than the timeout by its header stamp, against the node's clock, is
//! ignored: it says where the robot should have been going, not where it should go now.
//!
//! Pure logic on millisecond readings of a monotonic clock, so that it is tested without time
//! passing; the node feeds it and acts on [`Wanted`].

/// What the chassis should be doing now.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Wanted<T> {
    /// Moving at the velocity last commanded (re-sent every command period).
    Move(T),
    /// Stopping: the commands went silent just now (said once per silence).
    Stop,
    /// Nothing: never commanded, or stopped already.
    Idle,
}

/// What became of a stamped command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Taken: the chassis follows it.
    Taken,
    /// Ignored: its stamp is older than the timeout by this much, ns (how old it is).
    Stale {
        /// Its age by the node's clock, ns.
        age_ns: i64,
    },
}

/// The watchdog, over commands of type `T`.
#[derive(Clone, Debug)]
pub struct Watchdog<T> {
    timeout_ms: u64,
    /// The last command taken and when (ms), while it holds.
    last: Option<(u64, T)>,
    /// Stops for silence so far.
    stops: u32,
    /// Stamped commands ignored as stale so far.
    stale: u32,
}

impl<T: Copy> Watchdog<T> {
    /// A watchdog that stops after `timeout_ms` of silence.
    pub const fn new(timeout_ms: u64) -> Self {
        Watchdog {
            timeout_ms,
            last: None,
            stops: 0,
            stale: 0,
        }
    }

    /// The timeout, ms.
    pub const fn timeout_ms(&self) -> u64 {
        self.timeout_ms
    }

    /// A command (`geometry_msgs/Twist`) taken in at `at_ms`.
    pub fn command(&mut self, at_ms: u64, command: T) {
        self.last = Some((at_ms, command));
    }

    /// A stamped command taken in at `at_ms`, its header stamp `stamp_ns` and the node's clock
    /// `now_ns` (both ns since the clock's epoch): taken unless older than the timeout. A stamp
    /// from the future (another machine's clock a little ahead) is taken.
    pub fn stamped(&mut self, at_ms: u64, stamp_ns: i64, now_ns: i64, command: T) -> Verdict {
        let age_ns = now_ns.saturating_sub(stamp_ns);
        let limit_ns = i64::try_from(self.timeout_ms)
            .unwrap_or(i64::MAX)
            .saturating_mul(1_000_000);
        if age_ns > limit_ns {
            self.stale = self.stale.saturating_add(1);
            return Verdict::Stale { age_ns };
        }
        self.command(at_ms, command);
        Verdict::Taken
    }

    /// What the chassis should do at `now_ms`: [`Wanted::Stop`] once when the last command
    /// is older than the timeout, [`Wanted::Idle`] after it.
    pub fn wanted(&mut self, now_ms: u64) -> Wanted<T> {
        match self.last {
            Some((at_ms, command)) if now_ms.saturating_sub(at_ms) <= self.timeout_ms => {
                Wanted::Move(command)
            }
            Some(_) => {
                self.last = None;
                self.stops = self.stops.saturating_add(1);
                Wanted::Stop
            }
            None => Wanted::Idle,
        }
    }

    /// Forgets the command held (the chassis was stopped for another reason: a signal).
    pub fn clear(&mut self) {
        self.last = None;
    }

    /// Stops for silence so far.
    pub const fn stops(&self) -> u32 {
        self.stops
    }

    /// Stamped commands ignored as stale so far.
    pub const fn stale(&self) -> u32 {
        self.stale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_while_commanded_and_stops_once_after_the_timeout() {
        let mut dog = Watchdog::new(500);
        assert_eq!(dog.wanted(0), Wanted::Idle);
        dog.command(1_000, 7);
        assert_eq!(dog.wanted(1_000), Wanted::Move(7));
        assert_eq!(dog.wanted(1_500), Wanted::Move(7));
        assert_eq!(dog.wanted(1_501), Wanted::Stop);
        assert_eq!(dog.wanted(1_502), Wanted::Idle);
        assert_eq!(dog.stops(), 1);
        dog.command(2_000, 8);
        assert_eq!(dog.wanted(2_400), Wanted::Move(8));
    }

    #[test]
    fn a_stale_stamp_is_ignored_a_fresh_one_taken() {
        let mut dog = Watchdog::new(500);
        let now_ns = 10_000_000_000;
        assert_eq!(
            dog.stamped(0, now_ns - 501_000_000, now_ns, 1),
            Verdict::Stale {
                age_ns: 501_000_000
            }
        );
        assert_eq!(dog.wanted(0), Wanted::Idle);
        assert_eq!(
            dog.stamped(0, now_ns - 500_000_000, now_ns, 2),
            Verdict::Taken
        );
        assert_eq!(dog.wanted(0), Wanted::Move(2));
        // A stamp a second ahead (another clock) is taken.
        assert_eq!(
            dog.stamped(1, now_ns + 1_000_000_000, now_ns, 3),
            Verdict::Taken
        );
        // The zero stamp of a publisher that does not stamp is stale by decades.
        assert!(matches!(
            dog.stamped(2, 0, now_ns, 4),
            Verdict::Stale { .. }
        ));
        assert_eq!(dog.stale(), 2);
        assert_eq!(dog.wanted(3), Wanted::Move(3));
    }

    #[test]
    fn extreme_stamps_do_not_overflow() {
        let mut dog = Watchdog::new(u64::MAX);
        assert_eq!(dog.stamped(0, i64::MIN, i64::MAX, 1), Verdict::Taken);
        let mut dog = Watchdog::new(0);
        assert!(matches!(
            dog.stamped(0, i64::MIN, i64::MAX, 1),
            Verdict::Stale { age_ns: i64::MAX }
        ));
    }
}
