//! `--stats`: how long a `/cmd_vel` sample takes from its arrival in the node to its frame
//! written to the port, summarised in one line on exit.

/// Latency samples, ns.
#[derive(Clone, Debug, Default)]
pub struct Latency {
    samples: Vec<u64>,
}

impl Latency {
    /// Keeps one sample, ns.
    pub fn add(&mut self, ns: u64) {
        self.samples.push(ns);
    }

    /// Samples kept.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// No sample yet.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The `p`-th percentile (0 to 100), ns, by the nearest-rank method: the smallest sample
    /// with at least `p` % of the samples at or below it. `None` without samples.
    pub fn percentile(&self, p: f64) -> Option<u64> {
        let mut sorted = self.samples.clone();
        sorted.sort_unstable();
        let n = sorted.len();
        if n == 0 {
            return None;
        }
        let rank = ((p.clamp(0.0, 100.0) / 100.0) * n as f64).ceil() as usize;
        sorted.get(rank.clamp(1, n) - 1).copied()
    }

    /// `cmd_vel to wire: n=N p50=X.XXX ms p99=Y.YYY ms max=Z.ZZZ ms`.
    pub fn line(&self) -> String {
        let ms = |ns: Option<u64>| ns.map_or(0.0, |ns| ns as f64 / 1e6);
        format!(
            "cmd_vel to wire: n={} p50={:.3} ms p99={:.3} ms max={:.3} ms",
            self.samples.len(),
            ms(self.percentile(50.0)),
            ms(self.percentile(99.0)),
            ms(self.percentile(100.0)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentiles_and_the_line() {
        let mut l = Latency::default();
        assert_eq!(l.percentile(50.0), None);
        assert_eq!(
            l.line(),
            "cmd_vel to wire: n=0 p50=0.000 ms p99=0.000 ms max=0.000 ms"
        );
        // 1..=100 µs, added out of order.
        for i in (1..=100u64).rev() {
            l.add(i * 1_000);
        }
        assert_eq!(l.percentile(50.0), Some(50_000));
        assert_eq!(l.percentile(99.0), Some(99_000));
        assert_eq!(l.percentile(100.0), Some(100_000));
        assert_eq!(l.percentile(0.0), Some(1_000));
        assert_eq!(
            l.line(),
            "cmd_vel to wire: n=100 p50=0.050 ms p99=0.099 ms max=0.100 ms"
        );
    }
}
