//! Arbitrary typed frames: encode → decode gives them back, and each comes out of its
//! direction's streaming parser on its own bytes.
#![no_main]

use chassis_protocol::{Command, Downlink, DownlinkParser, UplinkParser};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|frames: (Command, Downlink)| {
    let (command, telemetry) = frames;

    let bytes = command.clone().encode();
    assert_eq!(Command::decode(&bytes), Ok(command.clone()));
    let mut uplink = UplinkParser::new();
    let out: Vec<Command> = uplink.frames(&bytes).collect();
    assert_eq!(out, [command]);

    let bytes = telemetry.encode();
    assert_eq!(Downlink::decode(&bytes), Ok(telemetry));
    let defined = !matches!(telemetry, Downlink::Reply(r) if r.register().is_none());

    // A lone frame between quiet lines comes out, but for a reply with a code the spec does not
    // define (the parser does not take those as replies).
    let mut downlink = DownlinkParser::new();
    assert_eq!(downlink.idle(), None);
    let mut out: Vec<Downlink> = downlink.frames(&bytes).collect();
    out.extend(std::iter::from_fn(|| downlink.idle()));
    if defined {
        assert_eq!(out, [telemetry]);
    } else {
        assert!(out.is_empty());
    }

    // With no quiet line before it, the parser may have started listening in the middle of
    // a frame: a lone frame cannot be told from another frame's tail, so nothing comes out.
    let mut downlink = DownlinkParser::new();
    let mut out: Vec<Downlink> = downlink.frames(&bytes).collect();
    out.extend(std::iter::from_fn(|| downlink.idle()));
    assert!(out.is_empty(), "{out:?}");
});
