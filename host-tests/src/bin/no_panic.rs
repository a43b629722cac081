//! The link-time proof that the protocol crate's byte-facing functions cannot panic.
//!
//! Each function below is marked `#[no_panic]`: if the compiler cannot prove that it (with
//! everything it calls, after inlining) never panics, the link fails. `cargo xtask test` builds
//! this binary with the `no-panic` profile (release, fat LTO, one codegen unit: everything must
//! be inlined for the proof), so a panic path reachable from untrusted bytes breaks CI:
//!
//! ```text
//! cargo build --profile no-panic -p chassis-host-tests --features no-panic-proof --bin no_panic
//! ```

use chassis_protocol::v1::{self, Parser as _};
use chassis_protocol::{
    Command, CommandBytes, Downlink, DownlinkBytes, DownlinkParser, UplinkParser, Velocity,
};
use no_panic::no_panic;
use std::hint::black_box;

#[no_panic]
fn downlink_push(parser: &mut DownlinkParser, byte: u8) -> Option<Downlink> {
    parser.push(byte)
}

#[no_panic]
fn downlink_push_slice<'a>(
    parser: &mut DownlinkParser,
    bytes: &'a [u8],
) -> (Option<Downlink>, &'a [u8]) {
    parser.push_slice(bytes)
}

#[no_panic]
fn downlink_idle(parser: &mut DownlinkParser) -> Option<Downlink> {
    parser.idle()
}

#[no_panic]
fn uplink_push(parser: &mut UplinkParser, byte: u8) -> Option<Command> {
    parser.push(byte)
}

#[no_panic]
fn uplink_push_slice<'a>(
    parser: &mut UplinkParser,
    bytes: &'a [u8],
) -> (Option<Command>, &'a [u8]) {
    parser.push_slice(bytes)
}

#[no_panic]
fn v1_downlink_push(parser: &mut v1::DownlinkParser, byte: u8) -> Option<v1::Downlink> {
    parser.push(byte)
}

#[no_panic]
fn v1_downlink_poll(parser: &mut v1::DownlinkParser) -> Option<v1::Downlink> {
    parser.poll()
}

#[no_panic]
fn v1_downlink_push_slice<'a>(
    parser: &mut v1::DownlinkParser,
    bytes: &'a [u8],
) -> (Option<v1::Downlink>, &'a [u8]) {
    parser.push_slice(bytes)
}

#[no_panic]
fn v1_downlink_take_frame(
    parser: &mut v1::DownlinkParser,
    bytes: &mut &[u8],
) -> Option<v1::Downlink> {
    parser.take_frame(bytes)
}

#[no_panic]
fn v1_downlink_quiet(parser: &mut v1::DownlinkParser) -> Option<v1::Downlink> {
    v1::Parser::quiet(parser, 5)
}

#[no_panic]
fn v1_uplink_push(parser: &mut v1::UplinkParser, byte: u8) -> Option<v1::Command> {
    parser.push(byte)
}

#[no_panic]
fn v1_uplink_push_slice<'a>(
    parser: &mut v1::UplinkParser,
    bytes: &'a [u8],
) -> (Option<v1::Command>, &'a [u8]) {
    parser.push_slice(bytes)
}

#[no_panic]
fn decode_telemetry(bytes: &[u8]) -> Option<Downlink> {
    Downlink::decode(bytes).ok()
}

#[no_panic]
fn decode_command(bytes: &[u8]) -> Option<Command> {
    Command::decode(bytes).ok()
}

#[no_panic]
fn encode_command(command: Command) -> CommandBytes {
    command.encode()
}

#[no_panic]
fn encode_telemetry(frame: &Downlink) -> DownlinkBytes {
    frame.encode()
}

#[no_panic]
fn encode_velocity(x: i32, y: i32, z: i32) -> [u8; 10] {
    Velocity::new(x, y, z).encode()
}

fn main() {
    let input: Vec<u8> = black_box((0..=255u8).cycle().take(4_096).collect());
    let mut down = DownlinkParser::new();
    let mut up = UplinkParser::new();
    let mut frames = 0usize;
    for b in &input {
        frames += usize::from(downlink_push(&mut down, *b).is_some());
        frames += usize::from(uplink_push(&mut up, *b).is_some());
    }
    let mut rest = &input[..];
    while !rest.is_empty() {
        let (frame, later) = downlink_push_slice(&mut down, rest);
        frames += usize::from(frame.is_some());
        rest = later;
    }
    let (_, _) = uplink_push_slice(&mut up, &input);
    let mut v1_down = v1::DownlinkParser::new();
    let mut v1_up = v1::UplinkParser::new();
    for b in &input {
        frames += usize::from(v1_downlink_push(&mut v1_down, *b).is_some());
        frames += usize::from(v1_downlink_poll(&mut v1_down).is_some());
        frames += usize::from(v1_uplink_push(&mut v1_up, *b).is_some());
    }
    let mut rest = &input[..];
    while !rest.is_empty() {
        let (frame, later) = v1_downlink_push_slice(&mut v1_down, rest);
        frames += usize::from(frame.is_some());
        rest = later;
    }
    let mut rest = &input[..];
    while v1_downlink_take_frame(&mut v1_down, &mut rest).is_some() {
        frames += 1;
    }
    frames += usize::from(v1_downlink_quiet(&mut v1_down).is_some());
    let (_, _) = v1_uplink_push_slice(&mut v1_up, &input);
    frames += usize::from(downlink_idle(&mut down).is_some());
    for window in input.windows(15).take(64) {
        if let Some(t) = decode_telemetry(window) {
            frames += encode_telemetry(&t).len();
        }
        if let Some(c) = decode_command(&window[..12]) {
            frames += encode_command(c).len();
        }
    }
    frames += encode_velocity(black_box(1), black_box(-2), black_box(3)).len();
    println!("no-panic: every checked function linked ({frames})");
}
