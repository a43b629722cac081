//! The link-time proof that the protocol crate's byte-facing functions cannot panic.
//!
//! Each function below is marked `#[no_panic]`: if the compiler cannot prove that it (with
//! everything it calls, after inlining) never panics, the link fails. `cargo xtask test` builds
//! this example with the `no-panic` profile (release, fat LTO, one codegen unit: everything must
//! be inlined for the proof), so a panic path reachable from untrusted bytes breaks CI:
//!
//! ```text
//! cargo build --profile no-panic -p chassis-host-tests --features no-panic-proof --example no_panic
//! ```

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
