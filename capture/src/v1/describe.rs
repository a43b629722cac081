//! A v1.0.0 frame as its JSON object (`"frame"`: `v1-…`, and its fields) and one line of text,
//! as `chassis decode` prints it.

use chassis_protocol::v1;
use serde_json::{Map, Value, json};

/// A readback request's name in the JSON (`"request"`) and the text.
const fn request_name(request: v1::Readback) -> &'static str {
    match request {
        v1::Readback::System => "system",
        v1::Readback::Geometry => "geometry",
        v1::Readback::BodyVelocity => "body-velocity",
        v1::Readback::MotorSpeeds => "motor-speeds",
        v1::Readback::Pid => "pid",
    }
}

/// `fields` (a JSON object) with `"frame": kind`.
fn object(kind: &str, fields: Value) -> Value {
    let mut map = Map::new();
    map.insert("frame".into(), json!(kind));
    if let Value::Object(fields) = fields {
        map.extend(fields);
    }
    Value::Object(map)
}

/// The JSON fields and text of a body velocity (a `0x25` command, a `0x35` reply).
fn body_velocity(v: &v1::BodyVelocity) -> (Value, String) {
    (
        json!({
            "ctl": v.ctl,
            "type": v.kind,
            "vx_mm_s": v.vx_mm_s,
            "vy_mm_s": v.vy_mm_s,
            "wz_mrad_s": v.wz_mrad_s,
        }),
        format!(
            "ctl 0x{:02X} type {} vx {} vy {} mm/s wz {} mrad/s",
            v.ctl, v.kind, v.vx_mm_s, v.vy_mm_s, v.wz_mrad_s
        ),
    )
}

/// The JSON fields and text of per-motor speeds (a `0x26` command, a `0x36` reply).
fn motor_speeds(m: &v1::MotorVelocity) -> (Value, String) {
    (
        json!({"ctl": m.ctl, "type": m.kind, "speeds_raw": m.speeds}),
        format!(
            "ctl 0x{:02X} type {} speeds {:?} (raw)",
            m.ctl, m.kind, m.speeds
        ),
    )
}

/// The JSON fields and text of the system settings (`0x23`, the `0x33` reply).
fn system(s: &v1::SystemSettings) -> (Value, String) {
    (
        json!({
            "motor_direction_bits": s.motor_directions,
            "encoder_direction_bits": s.encoder_directions,
            "pwm_max": s.pwm_max,
            "pwm_min": s.pwm_min,
            "encoder_ppr": s.encoder_ppr,
        }),
        format!(
            "motor direction bits 0x{:02X} encoder direction bits 0x{:02X} pwm max {} min {} encoder {} pulses/rev",
            s.motor_directions, s.encoder_directions, s.pwm_max, s.pwm_min, s.encoder_ppr
        ),
    )
}

/// The JSON fields and text of the geometry (`0x24`, the `0x34` reply).
fn geometry(g: &v1::Geometry) -> (Value, String) {
    (
        json!({
            "wheel_spacing_mm": g.wheel_spacing_mm,
            "axle_spacing_mm": g.axle_spacing_mm,
            "gear_ratio": g.gear_ratio,
            "wheel_diameter_mm": g.wheel_diameter_mm,
        }),
        format!(
            "wheel spacing {} mm axle spacing {} mm gear ratio {} wheel diameter {} mm",
            g.wheel_spacing_mm, g.axle_spacing_mm, g.gear_ratio, g.wheel_diameter_mm
        ),
    )
}

/// The JSON fields and text of the PID gains (`0x40`, the `0x50` reply).
fn pid(p: &v1::Pid) -> (Value, String) {
    (
        json!({
            "position_kp": p.position_kp,
            "position_ki": p.position_ki,
            "position_kd": p.position_kd,
            "velocity_kp": p.velocity_kp,
            "velocity_ki": p.velocity_ki,
        }),
        format!(
            "position kp {} ki {} kd {} velocity kp {} ki {}",
            p.position_kp, p.position_ki, p.position_kd, p.velocity_kp, p.velocity_ki
        ),
    )
}

/// A board → master v1.0.0 frame as JSON and one line of text.
pub(super) fn describe_v1_downlink(frame: &v1::Downlink) -> (Value, String) {
    match frame {
        v1::Downlink::Telemetry(t) => {
            let [vx, vy, wz] = t.velocity;
            (
                json!({
                    "frame": "v1-telemetry",
                    "velocity_mm_s": [vx, vy],
                    "wz_mrad_s": wz,
                    "accel_raw": t.accel,
                    "gyro_raw": t.gyro,
                    "quaternion_milli": t.quaternion,
                    "battery_mv": t.battery_mv,
                }),
                format!(
                    "{:<17} vx {vx} vy {vy} mm/s wz {wz} mrad/s accel {:?} gyro {:?} (raw) quaternion {:?} (x1000) battery {} mV",
                    "v1-telemetry", t.accel, t.gyro, t.quaternion, t.battery_mv
                ),
            )
        }
        v1::Downlink::Reply(r) => describe_reply(r),
    }
}

/// A reply to a readback request: the request (`"request"`, `"code"`) and the fields read
/// back.
fn describe_reply(r: &v1::Reply) -> (Value, String) {
    let (fields, text) = if let Some(s) = r.system() {
        system(&s)
    } else if let Some(g) = r.geometry() {
        geometry(&g)
    } else if let Some(v) = r.body_velocity() {
        body_velocity(&v)
    } else if let Some(m) = r.motor_speeds() {
        motor_speeds(&m)
    } else if let Some(p) = r.pid() {
        pid(&p)
    } else {
        (json!({}), String::new())
    };
    let mut json = object("v1-reply", fields);
    let name = request_name(r.request);
    let code = r.request.code();
    let mut text = format!("{:<17} {name} (0x{code:02X}): {text}", "v1-reply");
    if let Some(map) = json.as_object_mut() {
        map.insert("request".into(), json!(name));
        map.insert("code".into(), json!(code));
        // The last two bytes of a system, geometry or body-velocity reply are given as
        // 00 00: anything else is shown as it came.
        let reserved = r.payload.get(8..).unwrap_or(&[]);
        let laid_out_as_00 = matches!(
            r.request,
            v1::Readback::System | v1::Readback::Geometry | v1::Readback::BodyVelocity
        );
        if laid_out_as_00 && reserved.iter().any(|b| *b != 0) {
            map.insert("reserved_raw".into(), json!(reserved));
            text.push_str(&format!(" reserved {reserved:02X?}"));
        }
    }
    (json, text)
}

/// A v1.0.0 command (master → board) as its JSON object (the `"frame"` kind and its fields)
/// and a line of text, as `chassis decode` prints it.
pub fn describe_v1_uplink(command: &v1::Command) -> (Value, String) {
    let (kind, (fields, text)) = match command {
        v1::Command::BodyVelocity(v) if v.is_forced_stop() => {
            let (mut fields, _) = body_velocity(v);
            if let Some(map) = fields.as_object_mut() {
                map.insert("forced_stop".into(), json!(true));
            }
            ("v1-body-velocity", (fields, "forced stop".to_string()))
        }
        v1::Command::BodyVelocity(v) => ("v1-body-velocity", body_velocity(v)),
        v1::Command::MotorVelocity(m) => ("v1-motor-velocity", motor_speeds(m)),
        v1::Command::System(s) => ("v1-system", system(s)),
        v1::Command::Geometry(g) => ("v1-geometry", geometry(g)),
        v1::Command::Pid(p) => ("v1-pid", pid(p)),
        v1::Command::Readback(r) => {
            let (name, code) = (request_name(*r), r.code());
            (
                "v1-readback",
                (
                    json!({"request": name, "code": code}),
                    format!("{name} (0x{code:02X})"),
                ),
            )
        }
    };
    (object(kind, fields), format!("{kind:<17} {text}"))
}
