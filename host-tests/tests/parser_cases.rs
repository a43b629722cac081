//! The board → master parser on the cases issue 7 found it failing on, each reproduced on a fresh
//! parser. Frames are written out by hand from the spec table (2E-1..3).

use chassis_host_tests::{BoardStream, CountModel, Payload};
use chassis_protocol::{Battery, Downlink, DownlinkParser, Encoders, Imu, Kind, Stream};

/// An IMU frame at rest with count `seq`.
fn imu(seq: u8) -> Imu {
    Imu {
        accel: [1, 2, 16_384],
        gyro: [3, 4, 5],
        seq,
    }
}

fn feed(parser: &mut DownlinkParser, bytes: &[u8]) -> Vec<Downlink> {
    let mut out = Vec::new();
    for b in bytes {
        out.extend(parser.push(*b));
        out.extend(std::iter::from_fn(|| parser.poll()));
    }
    out
}

fn quiet(parser: &mut DownlinkParser, ms: u32) -> Vec<Downlink> {
    std::iter::from_fn(|| parser.quiet(ms)).collect()
}

fn imu_counts(frames: &[Downlink]) -> Vec<u8> {
    frames
        .iter()
        .filter(|f| f.kind() == Kind::Telemetry(Stream::Imu))
        .filter_map(Downlink::seq)
        .collect()
}

/// Case 1: a damaged frame's tail holding `23 01` and four bytes, followed by a header, was taken
/// as a reply.
#[test]
fn case1_a_damaged_frames_tail_is_no_reply() {
    let mut p = DownlinkParser::new();
    let mut line = Vec::new();
    for seq in 10..=12 {
        line.extend_from_slice(&imu(seq).encode());
    }
    // IMU #13, gyro X = 0x2301, its count byte lost.
    line.extend_from_slice(&[
        0xFF, 0xFA, 0x00, 0x01, 0x00, 0x02, 0x00, 0x03, 0x23, 0x01, 0x44, 0x55, 0x66, 0x77,
    ]);
    for seq in 14..=15 {
        line.extend_from_slice(&imu(seq).encode());
    }
    quiet(&mut p, 5);
    let mut out = feed(&mut p, &line);
    out.extend(quiet(&mut p, 5));
    assert!(
        out.iter().all(|f| !matches!(f, Downlink::Reply(_))),
        "{out:?}"
    );
    assert_eq!(imu_counts(&out), vec![10, 11, 12, 14, 15]);
}

/// Case 2: a quiet line used to make every count provisional, so after it the count check was
/// gone and a false encoder frame in a damaged burst was taken.
#[test]
fn case2_a_quiet_line_keeps_the_count_check() {
    let mut p = DownlinkParser::new();
    quiet(&mut p, 5);
    let mut out = Vec::new();
    for seq in 1..=3 {
        out.extend(feed(&mut p, &imu(seq).encode()));
        out.extend(quiet(&mut p, 8));
    }
    assert_eq!(imu_counts(&out), vec![1, 2, 3]);
    let burst = [
        0x00, 0xFA, 0x12, 0x34, 0xFF, 0xFB, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x67,
    ];
    let mut out = feed(&mut p, &burst);
    out.extend(quiet(&mut p, 8));
    assert_eq!(out, vec![]);
}

/// Case 3: one junk byte between frames dropped the lock and lost a frame whose count continues.
#[test]
fn case3_a_junk_byte_between_frames_loses_nothing() {
    let mut p = DownlinkParser::new();
    let mut line = Vec::new();
    for seq in 0..=2 {
        line.extend_from_slice(&imu(seq).encode());
    }
    line.push(0x00);
    line.extend_from_slice(&imu(3).encode());
    line.push(0x00);
    for seq in 4..=5 {
        line.extend_from_slice(&imu(seq).encode());
    }
    quiet(&mut p, 5);
    let mut out = feed(&mut p, &line);
    out.extend(quiet(&mut p, 5));
    assert_eq!(imu_counts(&out), vec![0, 1, 2, 3, 4, 5]);
}

/// Case 4: junk `23 0C` before an IMU frame whose accel Y is -5 (`FF FB`) gave a false reply,
/// lost the IMU frame, then took a false encoder frame with a far count.
#[test]
fn case4_junk_before_a_frame_gives_nothing_false_and_loses_nothing() {
    let mut p = DownlinkParser::new();
    quiet(&mut p, 5);
    let mut line = Vec::new();
    let mut enc = 40u8;
    for seq in 20..=27u8 {
        line.extend_from_slice(&imu(seq).encode());
        if seq % 4 == 3 {
            enc += 1;
            line.extend_from_slice(
                &Encoders {
                    ticks: [1, 2, 3, 4],
                    seq: enc,
                }
                .encode(),
            );
        }
    }
    line.extend_from_slice(&[0x23, 0x0C]);
    let odd = Imu {
        accel: [16, -5, 16_384],
        gyro: [0, 0, 0],
        seq: 28,
    };
    line.extend_from_slice(&odd.encode());
    for seq in 29..=31 {
        line.extend_from_slice(&imu(seq).encode());
    }
    let mut out = feed(&mut p, &line);
    out.extend(quiet(&mut p, 5));
    assert!(
        out.iter().all(|f| !matches!(f, Downlink::Reply(_))),
        "{out:?}"
    );
    let encoders: Vec<u8> = out
        .iter()
        .filter(|f| f.kind() == Kind::Telemetry(Stream::Encoders))
        .filter_map(Downlink::seq)
        .collect();
    assert_eq!(encoders, vec![41, 42]);
    assert_eq!(imu_counts(&out), (20..=31).collect::<Vec<u8>>());
}

/// Case 5: the board resets mid-frame (7 bytes of an IMU frame, then every count from 0). The
/// old parser gave a false frame and lost nine (about 160 bytes).
#[test]
fn case5_a_board_reset_mid_frame_recovers_quickly_with_nothing_false() {
    let mut p = DownlinkParser::new();
    quiet(&mut p, 5);
    let mut line = Vec::new();
    for seq in 100..=110 {
        line.extend_from_slice(&imu(seq).encode());
    }
    line.extend_from_slice(&imu(111).encode()[..7]);
    let mut after = Vec::new();
    let mut enc = 0u8;
    for seq in 0..=15u8 {
        after.push(Downlink::Imu(imu(seq)));
        if seq % 4 == 3 {
            after.push(Downlink::Encoders(Encoders {
                ticks: [0; 4],
                seq: enc,
            }));
            enc += 1;
        }
    }
    for f in &after {
        line.extend_from_slice(&f.encode());
    }
    let mut out = feed(&mut p, &line);
    out.extend(quiet(&mut p, 5));
    let before: Vec<Downlink> = (100..=110).map(|s| Downlink::Imu(imu(s))).collect();
    for f in &out {
        assert!(before.contains(f) || after.contains(f), "false frame {f:?}");
    }
    // Every frame from the fourth after the reset on.
    for f in &after[3..] {
        assert!(out.contains(f), "lost {f:?}: {out:?}");
    }
}

/// Case 6: a line carrying only battery frames, back to back: none was decoded.
#[test]
fn case6_a_line_of_battery_frames_only() {
    let frames: Vec<Battery> = (0..30u8)
        .map(|seq| Battery {
            centivolts: 1_180,
            percent: 62,
            seq,
        })
        .collect();
    let line: Vec<u8> = frames.iter().flat_map(|b| b.encode()).collect();
    // From a quiet line: every frame. Without one: every frame too, once four show the count
    // moving in step.
    for start_quiet in [true, false] {
        let mut p = DownlinkParser::new();
        if start_quiet {
            quiet(&mut p, 5);
        }
        let mut out = feed(&mut p, &line);
        out.extend(quiet(&mut p, 5));
        let expected: Vec<Downlink> = frames.iter().copied().map(Downlink::Battery).collect();
        assert_eq!(out, expected, "quiet before: {start_quiet}");
    }
}

/// Case 7: starting to listen at every byte of the first 2,000 of an adversarial stream (every
/// payload field often a header or `23` and a reply code), with and without the line's quiet
/// stretches reported: no start emits a frame the board did not send.
#[test]
fn case7_no_start_offset_gives_a_false_frame() {
    for counts in [CountModel::PerStream([1, 1, 1]), CountModel::Shared] {
        let (bytes, sent, gaps) = BoardStream::new(7, 2.0)
            .with_models(Payload::Adversarial, counts)
            .take_with_gaps(260);
        for with_quiet in [false, true] {
            for offset in 0..2_000 {
                let mut p = DownlinkParser::new();
                let mut out = Vec::new();
                let mut next_gap = gaps.iter().skip_while(|g| g.offset <= offset).peekable();
                for (i, b) in bytes.iter().enumerate().skip(offset) {
                    if with_quiet && next_gap.next_if(|g| g.offset == i).is_some() {
                        out.extend(quiet(&mut p, 5));
                    }
                    out.extend(p.push(*b));
                    out.extend(std::iter::from_fn(|| p.poll()));
                }
                out.extend(quiet(&mut p, 5));
                for f in &out {
                    assert!(
                        sent.iter().any(|s| s.start >= offset && s.frame == *f),
                        "{counts:?}, quiet {with_quiet}, offset {offset}: false {f:?}"
                    );
                }
            }
        }
    }
}

/// Case 8: a motors frame whose payload ends in `FF FE 02`, repeated back to back, started 3
/// bytes before the end of the first: the master → board parser took every frame at the false
/// phase and never realigned. On a line with no gap at all the two phases cannot be told apart
/// by any parser: the false phase is itself a valid stream of valid motors frames (shown below).
/// A master leaves the line quiet between commands (it sends one, then waits for its next
/// period); reported with `idle()`, the parser realigns at the first gap.
#[test]
fn case8_the_uplink_parser_realigns_at_the_masters_gaps() {
    use chassis_protocol::{Command, Motors, UplinkParser};
    let frame: [u8; 12] = [
        0xFF, 0xFE, 0x02, 0x00, 0x01, 0x00, 0x02, 0x00, 0x03, 0xFF, 0xFE, 0x02,
    ];
    let real = Command::decode(&frame).unwrap();
    // The false phase: three bytes of one frame and nine of the next, a valid frame too.
    let shifted: Vec<u8> = frame[9..].iter().chain(&frame[..9]).copied().collect();
    assert!(matches!(
        Command::decode(&shifted),
        Ok(Command::Motors(Motors { .. }))
    ));
    assert_ne!(Command::decode(&shifted).unwrap(), real);

    // With the master's gaps reported: every frame after the cut one.
    let mut p = UplinkParser::new();
    let mut out = Vec::new();
    out.extend(p.frames(&frame[9..]));
    p.idle();
    for _ in 0..18 {
        out.extend(p.frames(&frame));
        p.idle();
    }
    assert_eq!(out, vec![real; 18]);
}
