//! What the decode tests of both generations share: the golden captures under `tests/golden/`
//! (written by hand from the specs' tables), the JSON Lines they must decode to, and the binary
//! run with a capture on its standard input.

use super::{bin, chassis};
use serde_json::Value;
use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Output, Stdio};

/// The 2020 firmware's golden captures of one side each: the capture, the options that decode
/// it, the golden JSON Lines it decodes to.
pub const CAPTURES_2020: [(&str, &[&str], &str); 4] = [
    ("downlink.hex", &["--input", "hex"], "downlink.jsonl"),
    (
        "uplink.hex",
        &["--input", "hex", "--uplink"],
        "uplink.jsonl",
    ),
    (
        "downlink_logic2.csv",
        &["--input", "saleae-csv"],
        "downlink_logic2.jsonl",
    ),
    (
        "uplink_logic1.csv",
        &["--input", "saleae-csv", "--uplink"],
        "uplink_logic1.jsonl",
    ),
];

/// The path of the golden file `name`.
pub fn golden(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// The JSON objects of `text`, one a line (blank lines passed over).
pub fn json_lines(text: &str) -> Vec<Value> {
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| serde_json::from_str(l).expect("a JSON object per line"))
        .collect()
}

/// `chassis args` succeeds and writes the JSON Lines of the golden file `expected`.
pub fn assert_decodes_to(args: &[&str], expected: &str) -> Output {
    let out = chassis(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let got = json_lines(&String::from_utf8_lossy(&out.stdout));
    let want = json_lines(&std::fs::read_to_string(golden(expected)).unwrap());
    assert_eq!(got, want, "{expected}");
    out
}

/// `chassis decode INPUT ARGS…` on the golden capture `input` succeeds and writes the JSON
/// Lines of the golden file `expected`.
pub fn assert_golden_decodes(input: &str, args: &[&str], expected: &str) -> Output {
    let path = golden(input);
    let mut all = vec!["decode", path.as_str()];
    all.extend_from_slice(args);
    assert_decodes_to(&all, expected)
}

/// `chassis args` with `input` on its standard input, run to its end.
pub fn chassis_with_input(args: &[&str], input: &[u8]) -> Output {
    let mut child = Command::new(bin())
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    child
        .stdin
        .take()
        .expect("its standard input")
        .write_all(input)
        .expect("the input written");
    child.wait_with_output().expect("the binary ends")
}
