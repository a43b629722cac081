//! `chassis decode`: a capture in, one JSON object per frame per line out (JSON Lines), in
//! stream order, and a one-line summary on stderr.
//!
//! The JSON is a public contract (documented in the README): every object has `"offset"` (the
//! byte offset of the frame's first byte in the input) and `"frame"`, the fields of its kind,
//! and `"t"` (seconds) when the capture has time stamps.

use chassis_protocol::driver::Config;
use chassis_protocol::{Command, Downlink, DownlinkParser, Register, Setting, UplinkParser};
use serde_json::{Value, json};

/// How the input is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Input {
    /// The bytes themselves.
    Raw,
    /// Hex text: pairs of digits, spaces, commas, newlines and `0x` allowed.
    Hex,
    /// A logic analyser's async-serial export (Saleae Logic 1 or 2 CSV): time stamps and bytes;
    /// gaps in the time stamps are quiet lines for the parser.
    SaleaeCsv,
}

/// How frames are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// One JSON object per line.
    Json,
    /// One line of text per frame.
    Text,
}

/// A gap between two bytes longer than this is a quiet line (two and a half characters at
/// 115 200 bps are 0.2 ms; a board's frames come back to back).
pub const QUIET_GAP_S: f64 = 0.002;

/// The bytes of a capture, with the time of each when it has them.
#[derive(Debug, Default)]
pub struct Capture {
    /// The bytes.
    pub bytes: Vec<u8>,
    /// Their time stamps in seconds, if the capture has them (as many as the bytes).
    pub times: Option<Vec<f64>>,
    /// A gap longer than this, in seconds, is a quiet line ([`QUIET_GAP_S`] if not given).
    pub quiet_s: Option<f64>,
}

/// Reads `data` as `input`.
pub fn read_capture(data: &[u8], input: Input) -> Result<Capture, String> {
    match input {
        Input::Raw => Ok(Capture {
            bytes: data.to_vec(),
            ..Capture::default()
        }),
        Input::Hex => parse_hex(data).map(|bytes| Capture {
            bytes,
            ..Capture::default()
        }),
        Input::SaleaeCsv => parse_saleae(data),
    }
}

/// Hex text to bytes: whitespace and commas separate, `0x` may lead a group, a group holds an
/// even number of digits.
pub fn parse_hex(data: &[u8]) -> Result<Vec<u8>, String> {
    let text = std::str::from_utf8(data).map_err(|_| "hex input: not text".to_string())?;
    let mut bytes = Vec::new();
    for (line_no, line) in text.lines().enumerate() {
        for group in line.split(|c: char| c.is_whitespace() || c == ',') {
            if group.is_empty() {
                continue;
            }
            let digits = group
                .strip_prefix("0x")
                .or_else(|| group.strip_prefix("0X"))
                .unwrap_or(group);
            if digits.len() % 2 != 0 {
                return Err(format!(
                    "hex input, line {}: {group:?} has an odd number of digits",
                    line_no + 1
                ));
            }
            for pair in digits.as_bytes().chunks(2) {
                let pair = std::str::from_utf8(pair).unwrap_or("");
                let byte = u8::from_str_radix(pair, 16).map_err(|_| {
                    format!("hex input, line {}: {group:?} is not hex", line_no + 1)
                })?;
                bytes.push(byte);
            }
        }
    }
    Ok(bytes)
}

/// A Saleae async-serial export: a header naming a time column (`Time [s]`, `start_time`) and
/// a byte column (`Value`, `data`), then one row per byte.
pub fn parse_saleae(data: &[u8]) -> Result<Capture, String> {
    parse_saleae_rows(data, |_| true)
}

/// One Saleae Logic 2 export holding both sides of a capture (one async-serial analyser per
/// line, told apart by the `name` column): the board side (every analyser but `master`) and
/// the master side (the analyser named `master`).
pub fn parse_saleae_sides(data: &[u8], master: &str) -> Result<(Capture, Capture), String> {
    let text = std::str::from_utf8(data).map_err(|_| "CSV input: not text".to_string())?;
    let header = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    let name_col = split_csv(header)
        .iter()
        .position(|c| c.trim().eq_ignore_ascii_case("name"))
        .ok_or_else(|| {
            format!(
                "--master-analyzer: the CSV has no \"name\" column (its header is {header:?}): \
                 export both analysers from Logic 2's data table, or each side to its own file \
                 and give --master FILE"
            )
        })?;
    let is_master = |fields: &[String]| {
        fields
            .get(name_col)
            .is_some_and(|n| n.trim() == master.trim())
    };
    let board = parse_saleae_rows(data, |f| !is_master(f))?;
    let master_side = parse_saleae_rows(data, is_master)?;
    if master_side.bytes.is_empty() {
        return Err(format!(
            "--master-analyzer: no row of the CSV comes from an analyser named {master:?}"
        ));
    }
    Ok((board, master_side))
}

/// [`parse_saleae`], keeping only the rows `keep` accepts (given the row's fields).
fn parse_saleae_rows(data: &[u8], keep: impl Fn(&[String]) -> bool) -> Result<Capture, String> {
    let text = std::str::from_utf8(data).map_err(|_| "CSV input: not text".to_string())?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err("CSV input: empty".into());
    };
    let columns: Vec<String> = split_csv(header)
        .iter()
        .map(|c| c.trim().to_ascii_lowercase())
        .collect();
    let time_col = columns.iter().position(|c| c.contains("time"));
    let value_col = columns
        .iter()
        .position(|c| c == "value" || c == "data" || c.starts_with("value"));
    let (Some(time_col), Some(value_col)) = (time_col, value_col) else {
        return Err(format!(
            "CSV input: not an async-serial export (its header {header:?} names no time and \
             value/data columns)"
        ));
    };
    let type_col = columns.iter().position(|c| c == "type");
    let mut capture = Capture {
        times: Some(Vec::new()),
        ..Capture::default()
    };
    for (line_no, line) in lines {
        let fields = split_csv(line);
        if !keep(&fields) {
            continue;
        }
        // Logic 2 exports errors and other rows with a type other than "data".
        if let Some(t) = type_col.and_then(|i| fields.get(i)) {
            if !t.trim().eq_ignore_ascii_case("data") {
                continue;
            }
        }
        let (Some(time), Some(value)) = (fields.get(time_col), fields.get(value_col)) else {
            return Err(format!("CSV input, line {}: too few columns", line_no + 1));
        };
        let time: f64 = time
            .trim()
            .parse()
            .map_err(|_| format!("CSV input, line {}: {time:?} is not a time", line_no + 1))?;
        let value = value.trim().trim_matches('\'');
        let byte = match value
            .strip_prefix("0x")
            .or_else(|| value.strip_prefix("0X"))
        {
            Some(hex) => u8::from_str_radix(hex, 16).ok(),
            None => value.parse::<u8>().ok(),
        }
        .ok_or_else(|| format!("CSV input, line {}: {value:?} is not a byte", line_no + 1))?;
        capture.bytes.push(byte);
        if let Some(times) = capture.times.as_mut() {
            times.push(time);
        }
    }
    Ok(capture)
}

/// Fields of one CSV line (double quotes group, `""` inside quotes is a quote).
fn split_csv(line: &str) -> Vec<String> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                field.push('"');
                let _ = chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    fields.push(field);
    fields
}

/// One decoded frame and where it starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// Byte offset of its first byte in the input.
    pub offset: usize,
    /// The frame as JSON (offset and time included).
    pub json: Value,
    /// One line of text.
    pub text: String,
}

/// What a decode found, with its counters.
#[derive(Debug, Default)]
pub struct Decoded {
    /// The frames, in stream order.
    pub frames: Vec<Found>,
    /// The summary line.
    pub summary: String,
}

/// Decodes `capture` (board → master, or master → board with `uplink`).
pub fn decode(capture: &Capture, uplink: bool) -> Decoded {
    let (frames, summary) = if uplink {
        let (frames, _, summary) = decode_uplink(capture);
        (frames, summary)
    } else {
        decode_downlink(capture, &[])
    };
    Decoded { frames, summary }
}

/// Decodes both sides of one capture, `board` (board → master) and `master` (master → board),
/// both time-stamped: each read the master sent tells the board side's parser which reply is
/// awaited from the read's last byte on (until the driver's reply timeout), as the driver does.
/// The frames of both sides come out in time order, each with `"from"`: `"board"` or
/// `"master"` (offsets are into its own side's input).
pub fn decode_both(board: &Capture, master: &Capture) -> Result<Decoded, String> {
    let (Some(_), Some(master_times)) = (&board.times, &master.times) else {
        return Err(
            "--master needs the time of every byte on both sides, to line them up: \
                    export each side as an async-serial CSV and give --input saleae-csv"
                .into(),
        );
    };
    let (master_frames, reads, master_summary) = decode_uplink(master);
    let reads: Vec<(f64, Register)> = reads
        .iter()
        .filter_map(|(last, register)| Some((*master_times.get(*last)?, *register)))
        .collect();
    let (board_frames, board_summary) = decode_downlink(board, &reads);
    let mut frames: Vec<(f64, u8, Found)> = Vec::new();
    for (side, list, name) in [(0u8, board_frames, "board"), (1, master_frames, "master")] {
        for mut found in list {
            let t = found.json.get("t").and_then(Value::as_f64).unwrap_or(0.0);
            if let Some(map) = found.json.as_object_mut() {
                map.insert("from".into(), json!(name));
            }
            found.text = format!("{name:<6} {}", found.text);
            frames.push((t, side, found));
        }
    }
    // Stable: frames of one side keep their order; at the same instant the board's first.
    frames.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    Ok(Decoded {
        frames: frames.into_iter().map(|(_, _, f)| f).collect(),
        summary: format!(
            "board: {board_summary}; master: {master_summary}; {} reads told the board side's parser which reply to await",
            reads.len()
        ),
    })
}

/// Places each frame a parser emits in its input: the frame's bytes, searched from where the
/// previous frame ended up to the byte that let it out (the parsers emit frames in order and
/// never two from the same bytes).
struct Placer<'a> {
    bytes: &'a [u8],
    search_from: usize,
}

impl Placer<'_> {
    fn place(&mut self, wire: &[u8], upto: usize) -> usize {
        let end = upto.min(self.bytes.len());
        let found = self
            .bytes
            .get(self.search_from..end)
            .and_then(|hay| hay.windows(wire.len()).position(|w| w == wire))
            .map(|p| p + self.search_from)
            .unwrap_or(self.search_from);
        self.search_from = found + wire.len();
        found
    }
}

/// The time of byte `offset`, if the capture has times.
fn time_of(capture: &Capture, offset: usize) -> Option<f64> {
    capture.times.as_ref().and_then(|t| t.get(offset).copied())
}

/// How long the line was quiet before byte `i`, in ms, if longer than the capture's quiet gap.
fn gap_before(capture: &Capture, i: usize) -> Option<u32> {
    let times = capture.times.as_ref()?;
    let (a, b) = (times.get(i.checked_sub(1)?)?, times.get(i)?);
    let gap = b - a;
    (gap > capture.quiet_s.unwrap_or(QUIET_GAP_S))
        .then(|| (gap * 1000.0).round().clamp(1.0, 60_000.0) as u32)
}

/// The master → board side: its frames, each read (the index of its last byte and the register
/// read), and the summary.
fn decode_uplink(capture: &Capture) -> (Vec<Found>, Vec<(usize, Register)>, String) {
    let mut frames = Vec::new();
    let mut reads = Vec::new();
    let mut placer = Placer {
        bytes: &capture.bytes,
        search_from: 0,
    };
    let mut parser = UplinkParser::new();
    for (i, &byte) in capture.bytes.iter().enumerate() {
        if gap_before(capture, i).is_some() {
            parser.idle();
        }
        if let Some(command) = parser.push(byte) {
            if let Command::Setting(Setting::Read(register)) = command {
                reads.push((i, register));
            }
            let (json, text) = describe_uplink(&command);
            // Encoding consumes the command (a turn is sent once, even in a decoder).
            let wire = command.encode();
            let offset = placer.place(wire.as_slice(), i + 1);
            frames.push(found(offset, time_of(capture, offset), json, &text));
        }
    }
    let s = parser.stats();
    let summary = format!(
        "{} bytes: {} frames; {} bytes discarded, {} resyncs",
        capture.bytes.len(),
        s.frames,
        s.discarded,
        s.resyncs
    );
    (frames, reads, summary)
}

/// The board → master side, the parser told of each read in `reads` (the time of its last
/// byte, in the capture's clock, and the register) from the first byte received after it.
fn decode_downlink(capture: &Capture, reads: &[(f64, Register)]) -> (Vec<Found>, String) {
    let mut frames = Vec::new();
    let mut placer = Placer {
        bytes: &capture.bytes,
        search_from: 0,
    };
    let timeout_s = f64::from(Config::DEFAULT.reply_timeout_ms()) / 1000.0;
    let mut reads = reads.iter().peekable();
    // The read awaited, and when the master gives up on it.
    let mut awaited: Option<f64> = None;
    let mut parser = DownlinkParser::new();
    let mut emit = |frame: Downlink, upto: usize, frames: &mut Vec<Found>| {
        let (json, text) = describe_downlink(&frame);
        let offset = placer.place(frame.encode().as_slice(), upto);
        frames.push(found(offset, time_of(capture, offset), json, &text));
    };
    for (i, &byte) in capture.bytes.iter().enumerate() {
        if let Some(ms) = gap_before(capture, i) {
            while let Some(frame) = parser.quiet(ms) {
                emit(frame, i, &mut frames);
            }
        }
        if let Some(now) = time_of(capture, i) {
            while let Some((sent, register)) = reads.next_if(|(t, _)| *t <= now) {
                parser.expect_reply(Some(*register));
                awaited = Some(sent + timeout_s);
            }
            if awaited.is_some_and(|deadline| now > deadline) {
                parser.expect_reply(None);
                awaited = None;
            }
        }
        if let Some(frame) = parser.push(byte) {
            emit(frame, i + 1, &mut frames);
        }
        while let Some(frame) = parser.poll() {
            emit(frame, i + 1, &mut frames);
        }
    }
    // The end of a capture is a quiet line.
    while let Some(frame) = parser.quiet(1_000) {
        emit(frame, capture.bytes.len(), &mut frames);
    }
    let s = parser.stats();
    let gaps: u32 = s.gaps.iter().sum();
    let missed: u32 = s.missed.iter().sum();
    let summary = format!(
        "{} bytes: imu {}, encoders {}, battery {}, reply {}; {} bytes discarded; {} count gaps ({} frames missed)",
        capture.bytes.len(),
        s.frames[0],
        s.frames[1],
        s.frames[2],
        s.frames[3],
        s.discarded,
        gaps,
        missed
    );
    (frames, summary)
}

/// A frame's description placed in the input: `offset` (and `t`) added to its JSON, the offset
/// in front of its text.
fn found(offset: usize, t: Option<f64>, mut json: Value, text: &str) -> Found {
    if let Some(map) = json.as_object_mut() {
        map.insert("offset".into(), json!(offset));
        if let Some(t) = t {
            map.insert("t".into(), json!(t));
        }
    }
    Found {
        offset,
        json,
        text: format!("{offset:>8}  {text}"),
    }
}

fn describe_downlink(frame: &Downlink) -> (Value, String) {
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

fn describe_uplink(command: &Command) -> (Value, String) {
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
            let closed = m.control == chassis_protocol::MotorLoop::Closed;
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
