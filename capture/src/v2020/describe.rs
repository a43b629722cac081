//! A 2020 frame as its JSON object and one line of text, as `chassis decode` prints it.

use chassis_protocol::{Command, Downlink, MotorLoop, Setting};
use serde_json::{Value, json};

/// A board → master frame: telemetry or a `#` reply.
pub(super) fn describe_downlink(frame: &Downlink) -> (Value, String) {
    match frame {
        Downlink::Imu(f) => (
            json!({"frame": "imu", "accel": f.accel, "gyro": f.gyro, "count": f.seq}),
            format!(
                "imu       accel {:?} gyro {:?} count {}",
                f.accel, f.gyro, f.seq
            ),
        ),
        Downlink::Encoders(f) => (
            json!({"frame": "encoders", "ticks": f.ticks, "count": f.seq}),
            format!("encoders  ticks {:?} count {}", f.ticks, f.seq),
        ),
        Downlink::Battery(f) => (
            json!({"frame": "battery", "centivolts": f.centivolts, "percent": f.percent, "count": f.seq}),
            format!(
                "battery   {}.{:02} V {} % count {}",
                f.centivolts / 100,
                f.centivolts % 100,
                f.percent,
                f.seq
            ),
        ),
        Downlink::Reply(r) => {
            // Code 0x20 (the pending angle) is signed.
            let value = if r.code == 0x20 {
                json!(r.value as i32)
            } else {
                json!(r.value)
            };
            (
                json!({"frame": "reply", "code": r.code, "value": value}),
                format!("reply     code 0x{:02X} value {value}", r.code),
            )
        }
    }
}

/// A master → board command.
pub(super) fn describe_uplink(command: &Command) -> (Value, String) {
    match command {
        Command::Velocity(v) => (
            json!({"frame": "velocity", "x": v.x, "y": v.y, "z": v.z, "angle": false}),
            format!("velocity  x {} y {} z {}", v.x, v.y, v.z),
        ),
        Command::Turn(t) => (
            json!({"frame": "velocity", "x": t.x, "y": t.y, "z": t.deci_degrees, "angle": true}),
            format!(
                "velocity  x {} y {} turn {} (0.1°, added up)",
                t.x, t.y, t.deci_degrees
            ),
        ),
        Command::Motors(m) => {
            let closed = m.control == MotorLoop::Closed;
            (
                json!({"frame": "motors", "closed_loop": closed, "speeds": m.values}),
                format!(
                    "motors    {} {:?}",
                    if closed { "closed loop" } else { "open loop" },
                    m.values
                ),
            )
        }
        Command::Setting(Setting::Action(a)) => (
            json!({"frame": "action", "action": a.number()}),
            format!("action    {} ({a:?})", a.number()),
        ),
        Command::Setting(Setting::Write(w)) => (
            json!({"frame": "write", "code": w.register().code(), "value": w.value()}),
            format!(
                "write     code 0x{:02X} value {}",
                w.register().code(),
                w.value()
            ),
        ),
        Command::Setting(Setting::Read(r)) => (
            json!({"frame": "read", "code": r.read_code()}),
            format!("read      code 0x{:02X} ({r:?})", r.read_code()),
        ),
        Command::Setting(Setting::Raw { code, value, .. }) => (
            json!({"frame": "setting", "code": code, "value": value}),
            format!("setting   code 0x{code:02X} value {value} (not in the spec)"),
        ),
    }
}
