//! v1.0.0 frames: golden bytes written by hand from `docs/protocol-v1.md` (each BCC worked out by
//! hand: the XOR of the bytes before it), round trips, and the parsers on clean, split,
//! shifted and damaged streams.

use super::*;

/// The vendor's readback request for the system settings, as `docs/protocol-v1.md` quotes it.
const READ_SYSTEM: [u8; 14] = [0x7B, 0x33, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x48, 0x7D];

#[test]
fn golden_commands() {
    assert_eq!(Command::Readback(Readback::System).encode(), READ_SYSTEM);
    // The spec: the BCC of 0x34 is 4F, of 0x50 2B.
    assert_eq!(Command::Readback(Readback::Geometry).encode()[12], 0x4F);
    assert_eq!(Command::Readback(Readback::Pid).encode()[12], 0x2B);
    // The forced stop: ctl 0, everything 0; BCC 7B ^ 25 = 5E.
    assert_eq!(
        Command::BodyVelocity(BodyVelocity::FORCED_STOP).encode(),
        [0x7B, 0x25, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x5E, 0x7D]
    );
    // vx -0.1 m/s (FF9C), vy 0.3 m/s (012C), wz 0.5 rad/s (01F4), ctl 2, type 4:
    // 7B^25^02^04^FF^9C^01^2C^01^F4 = 0xE3.
    assert_eq!(
        Command::BodyVelocity(BodyVelocity::new(-100, 300, 500)).encode(),
        [
            0x7B, 0x25, 0x02, 0x04, 0xFF, 0x9C, 0x01, 0x2C, 0x01, 0xF4, 0, 0, 0xE3, 0x7D
        ]
    );
    // The vendor's geometry 110, 110, 55, 60: 7B^24^6E^6E^37^3C = 0x54.
    assert_eq!(
        Command::Geometry(Geometry {
            wheel_spacing_mm: 110,
            axle_spacing_mm: 110,
            gear_ratio: 55,
            wheel_diameter_mm: 60,
        })
        .encode(),
        [
            0x7B, 0x24, 0, 0x6E, 0, 0x6E, 0, 0x37, 0, 0x3C, 0, 0, 0x54, 0x7D
        ]
    );
}

/// A telemetry frame written by hand: velocity (0, 300, -50), accel (1, -2, 16384), gyro
/// (0, 0, 7), quaternion (1000, 0, 0, 0), battery 11 800 mV (2E18); BCC worked out below.
fn telemetry_bytes() -> [u8; 32] {
    let mut f = [
        0x7B, 0x00, // start, telemetry
        0x00, 0x00, 0x01, 0x2C, 0xFF, 0xCE, // velocity
        0x00, 0x01, 0xFF, 0xFE, 0x40, 0x00, // accel
        0x00, 0x00, 0x00, 0x00, 0x00, 0x07, // gyro
        0x03, 0xE8, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // quaternion
        0x2E, 0x18, // battery
        0x00, 0x7D, // BCC (below), end
    ];
    // 7B^01^2C^FF^CE^01^FF^FE^40^07^03^E8^2E^18, step by step: 7A 56 A9 67 66 99 67 27 20
    // 23 CB E5 FD.
    f[30] = 0xFD;
    f
}

#[test]
fn golden_telemetry() {
    let t = Telemetry::decode(&telemetry_bytes()).expect("the hand-made frame checks");
    assert_eq!(t.velocity, [0, 300, -50]);
    assert_eq!(t.accel, [1, -2, 16_384]);
    assert_eq!(t.gyro, [0, 0, 7]);
    assert_eq!(t.quaternion, [1_000, 0, 0, 0]);
    assert_eq!(t.battery_mv, 11_800);
    assert_eq!(t.encode(), telemetry_bytes());
}

#[test]
fn every_damage_is_refused() {
    let good = telemetry_bytes();
    for i in 0..good.len() {
        let mut bad = good;
        bad[i] ^= 0x10;
        assert!(Telemetry::decode(&bad).is_err(), "byte {i} changed");
    }
    let mut bad = READ_SYSTEM;
    bad[13] = 0x7C;
    assert_eq!(Command::decode(&bad), Err(FrameError::End));
    assert_eq!(Command::decode(&READ_SYSTEM[..13]), Err(FrameError::Length));
    let mut unknown = READ_SYSTEM;
    unknown[1] = 0x99;
    unknown[12] = 0x7B ^ 0x99;
    assert_eq!(
        Command::decode(&unknown),
        Err(FrameError::UnknownCode(0x99))
    );
    // A readback request with a payload, and a velocity frame whose last two bytes are not
    // 00 00: their BCC checks, but they are not what the layout allows.
    let mut payload = READ_SYSTEM;
    payload[2] = 0x01;
    payload[12] = 0x48 ^ 0x01;
    assert_eq!(Command::decode(&payload), Err(FrameError::Payload));
    let stop = Command::BodyVelocity(BodyVelocity::FORCED_STOP).encode();
    let mut tail = stop;
    tail[11] = 0x01;
    tail[12] ^= 0x01;
    assert_eq!(Command::decode(&tail), Err(FrameError::Payload));
    let mut parser = UplinkParser::new();
    assert_eq!(parser.frames(&payload).count(), 0);
    assert_eq!(parser.stats().refused, 1);
}

fn every_command() -> [Command; 10] {
    [
        Command::BodyVelocity(BodyVelocity::new(-1, i16::MAX, i16::MIN)),
        Command::BodyVelocity(BodyVelocity::FORCED_STOP),
        Command::MotorVelocity(MotorVelocity::new([1, -2, 3, -4])),
        Command::System(SystemSettings {
            motor_directions: 0,
            encoder_directions: 10,
            pwm_max: 3_600,
            pwm_min: 2_100,
            encoder_ppr: 165,
        }),
        Command::Geometry(Geometry::default()),
        Command::Pid(Pid {
            position_kp: 3_000,
            position_ki: 1_050,
            position_kd: 0,
            velocity_kp: 3_000,
            velocity_ki: 1_050,
        }),
        Command::Readback(Readback::System),
        Command::Readback(Readback::BodyVelocity),
        Command::Readback(Readback::MotorSpeeds),
        Command::Readback(Readback::Pid),
    ]
}

#[test]
fn commands_round_trip_and_parse_from_any_offset_in_any_chunking() {
    let commands = every_command();
    for c in commands {
        assert_eq!(Command::decode(&c.encode()), Ok(c));
    }
    let stream: Vec<u8> = commands.iter().flat_map(|c| c.encode()).collect();
    for chunk in 1..=stream.len() {
        for start in [0usize, 1, 5, 13] {
            let mut parser = UplinkParser::new();
            let mut found = Vec::new();
            for piece in stream[start..].chunks(chunk) {
                found.extend(parser.frames(piece));
            }
            // From an offset inside the first frame: every later one, exactly.
            let skip = usize::from(start > 0);
            assert_eq!(
                found,
                commands[skip..].to_vec(),
                "chunk {chunk}, start {start}"
            );
        }
    }
}

fn downlink_stream() -> (Vec<Downlink>, Vec<u8>) {
    let mut frames = Vec::new();
    for i in 0..12i16 {
        frames.push(Downlink::Telemetry(Telemetry {
            velocity: [i, i.wrapping_mul(3), -i],
            // Payload bytes that are 7B, 7D and 00, as real values make them.
            accel: [0x7B7D, 0x007B, i],
            gyro: [0x7B00, 0, 0x7D7B],
            quaternion: [1_000, 0, 0, i],
            battery_mv: 11_800,
        }));
        if i % 4 == 1 {
            frames.push(Downlink::Reply(Reply {
                request: Readback::ALL[usize::try_from(i).unwrap() % 5],
                payload: [0x7B, 0x00, 0x7D, 1, 2, 3, 4, 5, 6, 0x7B],
            }));
        }
    }
    let bytes = frames
        .iter()
        .flat_map(|f| f.encode().as_slice().to_vec())
        .collect();
    (frames, bytes)
}

#[test]
fn downlink_frames_from_any_offset_in_any_chunking() {
    let (frames, stream) = downlink_stream();
    for chunk in [1usize, 2, 3, 7, 13, 14, 31, 32, 33, 64, stream.len()] {
        for start in 0..40 {
            let mut parser = DownlinkParser::new();
            let mut found = Vec::new();
            for piece in stream[start..].chunks(chunk) {
                found.extend(parser.frames(piece));
            }
            // Every frame that starts at or after `start`, exactly, and nothing else.
            let mut at = 0;
            let mut want = Vec::new();
            for f in &frames {
                if at >= start {
                    want.push(*f);
                }
                at += f.encode().as_slice().len();
            }
            assert_eq!(found, want, "chunk {chunk}, start {start}");
        }
    }
}

#[test]
fn a_frame_inside_a_damaged_one_is_found_and_damage_is_counted() {
    let (frames, stream) = downlink_stream();
    // A telemetry frame cut after 10 bytes, then the whole stream.
    let mut bytes = stream[..10].to_vec();
    bytes.extend_from_slice(&stream);
    let mut parser = DownlinkParser::new();
    let found: Vec<_> = parser.frames(&bytes).collect();
    assert_eq!(found, frames, "every whole frame");
    let stats = parser.stats();
    assert_eq!(stats.frames, u32::try_from(frames.len()).unwrap());
    assert!(stats.bad_checksum + stats.bad_end >= 1, "{stats:?}");

    // One changed byte in each of three frames: exactly those lost, every other one found.
    let mut noisy = stream.clone();
    for at in [5usize, 40, 100] {
        noisy[at] ^= 0x01;
    }
    let mut parser = DownlinkParser::new();
    let found: Vec<_> = parser.frames(&noisy).collect();
    assert_eq!(found.len(), frames.len() - 3, "{:?}", parser.stats());
    assert!(found.iter().all(|f| frames.contains(f)), "nothing made up");
}

#[test]
fn random_bytes_never_stick_the_parser() {
    // A xorshift stream of 20 000 bytes, then a frame: the frame is found.
    let mut x = 0x2545_F491_4F6C_DD1Du64;
    let mut parser = DownlinkParser::new();
    for _ in 0..20_000 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let _ = parser.push(x.to_le_bytes()[0]);
        while parser.poll().is_some() {}
        assert!(parser.buffered() <= TELEMETRY_LEN);
    }
    // Whatever is held is dropped by the time a whole frame has come after it: of a frame
    // sent twice, the second is found whatever the first met.
    let frame = telemetry_bytes();
    let mut twice = frame.to_vec();
    twice.extend_from_slice(&frame);
    let found: Vec<_> = parser.frames(&twice).collect();
    assert_eq!(found.last(), Some(&Downlink::decode(&frame).unwrap()));
}

/// A run of exactly one frame's length lost across a frame boundary joins the start of one
/// telemetry frame to the end of the next, and the BCC can match (the protocol has no count or
/// length to tell): A = velocity (1, 0, 0), 12 000 mV; B = velocity (256, 0, 0), 11 900 mV; bytes
/// 4..36 of A then B lost. What arrives, written out: A's `7B 00 00 01`, then B from its byte 4.
#[test]
fn a_frame_never_spans_a_quiet_line() {
    let joined: [u8; 32] = [
        0x7B, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
        0x00, 0x00, 0x00, 0x00, 0x00, 0x03, 0xE8, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x2E, 0x7C,
        0xC3, 0x7D,
    ];
    // Without the line's timing, the parser takes it (its rules see a good frame).
    let mut blind = DownlinkParser::new();
    let got: Vec<Downlink> = blind.frames(&joined).collect();
    assert_eq!(got.len(), 1);
    // With the quiet line reported between A's start and B's rest (45 ms apart on the wire),
    // nothing is made of it, and the bytes are counted.
    let mut told = DownlinkParser::new();
    assert_eq!(told.frames(&joined[..4]).count(), 0);
    assert_eq!(told.quiet(), None);
    assert_eq!(told.buffered(), 0);
    assert_eq!(told.frames(&joined[4..]).count(), 0);
    assert_eq!(told.stats().frames, 0);
    assert_eq!(told.stats().discarded, 32);
    // A whole frame after a quiet line is taken as ever.
    let whole = Telemetry {
        battery_mv: 11_900,
        ..Telemetry::default()
    }
    .encode();
    assert_eq!(told.quiet(), None);
    assert_eq!(told.frames(&whole).count(), 1);
}

/// The worked examples of `docs/protocol-v1.md` that no other test holds, byte for byte as the
/// page gives them (each BCC worked out there).
#[test]
fn golden_frames_of_the_protocol_page() {
    // `0x26`: motors 200, -200, 200, -200: BCC 5B.
    assert_eq!(
        Command::MotorVelocity(MotorVelocity::new([200, -200, 200, -200])).encode(),
        [
            0x7B, 0x26, 0x02, 0x04, 0x00, 0xC8, 0xFF, 0x38, 0x00, 0xC8, 0xFF, 0x38, 0x5B, 0x7D
        ]
    );
    // `0x40`: the vendor's gains 3000, 1050, 0, 3000, 1050: BCC 3B.
    assert_eq!(
        Command::Pid(Pid {
            position_kp: 3000,
            position_ki: 1050,
            position_kd: 0,
            velocity_kp: 3000,
            velocity_ki: 1050,
        })
        .encode(),
        [
            0x7B, 0x40, 0x0B, 0xB8, 0x04, 0x1A, 0x00, 0x00, 0x0B, 0xB8, 0x04, 0x1A, 0x3B, 0x7D
        ]
    );
    // The reply to `0x36`: control mode 2, type 4, motors 120, -118, 121, -119: BCC 49.
    let reply = [
        0x7B, 0x36, 0x02, 0x04, 0x00, 0x78, 0xFF, 0x8A, 0x00, 0x79, 0xFF, 0x89, 0x49, 0x7D,
    ];
    let decoded = Reply::decode(&reply).expect("the page's reply decodes");
    assert_eq!(
        decoded.motor_speeds(),
        Some(MotorVelocity {
            ctl: 2,
            kind: 4,
            speeds: [120, -118, 121, -119],
        })
    );
    assert_eq!(decoded.encode(), reply);
}
