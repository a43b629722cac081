//! `/diagnostics`: one status for the board's link, its figures as key-value pairs.

use crate::board::Link;
use crate::msg::{DiagnosticArray, DiagnosticStatus, Header, KeyValue};

/// What the node counts itself, beside the driver's [`Link`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Stops because `/cmd_vel` went silent.
    pub watchdog_stops: u32,
    /// Stamped commands ignored as stale.
    pub stale_commands: u32,
    /// Commands whose sideways speed was refused (differential chassis).
    pub sideways_refused: u32,
    /// Commands the driver could not send.
    pub send_errors: u32,
}

/// The diagnostics of the board on `port` running `firmware`, as the node named `node` sees
/// it.
pub fn array(
    header: Header,
    node: &str,
    firmware: &str,
    port: &str,
    link: &Link,
    counters: &Counters,
) -> DiagnosticArray {
    let (level, message) = match (link.alive, link.heard) {
        (true, _) if link.failsafe_stops > 0 => (
            DiagnosticStatus::WARN,
            "link up (the driver's failsafe has stopped the chassis before)",
        ),
        (true, _) => (DiagnosticStatus::OK, "link up"),
        (false, true) => (
            DiagnosticStatus::ERROR,
            "link stale: no frame from the board within the failsafe time",
        ),
        (false, false) => (
            DiagnosticStatus::ERROR,
            "link stale: nothing from the board yet",
        ),
    };
    let mut values = vec![
        kv("firmware", firmware),
        kv("port", port),
        kv("link", if link.alive { "up" } else { "stale" }),
    ];
    for (stream, hz) in &link.rates {
        values.push(kv(&format!("rate {stream} (Hz)"), &format!("{hz:.1}")));
    }
    for (key, n) in [
        ("frames dropped", link.dropped),
        ("bytes discarded", link.discarded),
        ("failsafe stops", link.failsafe_stops),
        ("cmd_vel timeout stops", counters.watchdog_stops),
        ("stale cmd_vel ignored", counters.stale_commands),
        ("sideways speed refused", counters.sideways_refused),
        ("send errors", counters.send_errors),
    ] {
        values.push(kv(key, &n.to_string()));
    }
    DiagnosticArray {
        header,
        status: vec![DiagnosticStatus {
            level,
            name: format!("{node}: chassis board"),
            message: message.into(),
            hardware_id: port.into(),
            values,
        }],
    }
}

fn kv(key: &str, value: &str) -> KeyValue {
    KeyValue {
        key: key.into(),
        value: value.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value<'a>(a: &'a DiagnosticArray, key: &str) -> &'a str {
        &a.status[0]
            .values
            .iter()
            .find(|kv| kv.key == key)
            .unwrap()
            .value
    }

    #[test]
    fn a_live_link_is_ok_a_silent_one_an_error() {
        let mut link = Link {
            alive: true,
            heard: true,
            rates: vec![("imu", 100.0), ("encoders", 25.0)],
            dropped: 3,
            discarded: 7,
            failsafe_stops: 0,
        };
        let counters = Counters {
            watchdog_stops: 2,
            ..Counters::default()
        };
        let a = array(
            Header::default(),
            "chassis",
            "2020",
            "/dev/ttyUSB0",
            &link,
            &counters,
        );
        assert_eq!(a.status[0].level, DiagnosticStatus::OK);
        assert_eq!(value(&a, "firmware"), "2020");
        assert_eq!(value(&a, "link"), "up");
        assert_eq!(value(&a, "rate imu (Hz)"), "100.0");
        assert_eq!(value(&a, "frames dropped"), "3");
        assert_eq!(value(&a, "cmd_vel timeout stops"), "2");
        link.alive = false;
        link.failsafe_stops = 1;
        let a = array(Header::default(), "chassis", "2020", "p", &link, &counters);
        assert_eq!(a.status[0].level, DiagnosticStatus::ERROR);
        assert_eq!(value(&a, "link"), "stale");
        assert_eq!(value(&a, "failsafe stops"), "1");
        link.alive = true;
        let a = array(Header::default(), "chassis", "2020", "p", &link, &counters);
        assert_eq!(a.status[0].level, DiagnosticStatus::WARN);
    }
}
