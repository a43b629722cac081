//! The decoder of `chassis decode` and of the Python package's `decode_capture`: a capture
//! in, one JSON object per frame out (JSON Lines), in stream order, and a one-line summary.
//!
//! The JSON is a public contract (documented in `docs/cli.md`): every object has `"offset"` (the
//! byte offset of the frame's first byte in the input) and `"frame"`, the fields of its kind,
//! and `"t"` (seconds) when the capture has time stamps.
//!
//! A capture of either firmware generation is decoded: the 2020 one (`FF FE` frames) or v1.0.0
//! (`7B … BCC 7D` frames, kinds named `v1-…`). Unless the caller gives the generation, it is
//! found from the capture itself ([`Detection`]); when nothing decides, the capture is decoded
//! as 2020 and the summary says the generation was not recognised.

use chassis_protocol::detect::{Detector, Firmware};
use chassis_protocol::driver::Config;
use chassis_protocol::v1;
use chassis_protocol::{Command, Downlink, DownlinkParser, Register, Setting, UplinkParser};
use serde_json::{Map, Value, json};

/// How the input is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
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
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
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

/// How the generation of a capture was chosen, and what detection heard.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Detection {
    /// The caller gave it.
    Given(Firmware),
    /// The capture's frames decided it.
    Detected(Firmware),
    /// Nothing decided: decoded as 2020. The frames of each generation heard (both 0: no
    /// frame of either).
    NotRecognised {
        /// 2020 frames found.
        frames_2020: u32,
        /// v1.0.0 frames found (each with its BCC right).
        frames_v1: u32,
    },
    /// The two sides of a capture disagree: decoded as 2020.
    SidesDisagree {
        /// The board side's generation.
        board: Firmware,
        /// The master side's generation.
        master: Firmware,
    },
}

impl Detection {
    /// The generation the capture is decoded as.
    #[must_use]
    pub fn firmware(self) -> Firmware {
        match self {
            Detection::Given(f) | Detection::Detected(f) => f,
            Detection::NotRecognised { .. } | Detection::SidesDisagree { .. } => Firmware::V2020,
        }
    }

    /// The summary's first words: `firmware v1.0.0 (detected)`, `firmware 2020 (given)`, or why
    /// the generation was not recognised.
    #[must_use]
    pub fn words(self) -> String {
        match self {
            Detection::Given(f) => format!("firmware {} (given)", f.name()),
            Detection::Detected(f) => format!("firmware {} (detected)", f.name()),
            Detection::NotRecognised {
                frames_2020: 0,
                frames_v1: 0,
            } => "firmware not recognised (no frames of either generation), decoded as 2020".into(),
            Detection::NotRecognised {
                frames_2020,
                frames_v1,
            } => format!(
                "firmware not recognised ({frames_2020} frames of 2020, {frames_v1} of v1.0.0: \
                 neither decides), decoded as 2020"
            ),
            Detection::SidesDisagree { board, master } => format!(
                "firmware not recognised (the board side's frames are {}, the master side's {}), \
                 decoded as 2020",
                board.name(),
                master.name()
            ),
        }
    }
}

/// The board → master side's generation: [`Detector`] over the whole capture, told of each
/// quiet gap in its time stamps and of the quiet end.
#[must_use]
pub fn detect_downlink(capture: &Capture) -> Detection {
    let mut detector = Detector::new();
    for (i, &byte) in capture.bytes.iter().enumerate() {
        if let Some(ms) = gap_before(capture, i) {
            detector.quiet(ms);
        }
        detector.feed(&[byte]);
    }
    // The end of a capture is a quiet line.
    detector.quiet(1_000);
    let heard = detector.heard();
    match detector.verdict() {
        Some(f) => Detection::Detected(f),
        None => Detection::NotRecognised {
            frames_2020: heard.frames_2020,
            frames_v1: heard.frames_v1,
        },
    }
}

/// The master → board side's generation: the frames each generation's uplink parser finds; the
/// one with at least one and four times as many as the other decides.
#[must_use]
pub fn detect_uplink(capture: &Capture) -> Detection {
    let mut ff = UplinkParser::new();
    let mut seven = v1::UplinkParser::new();
    for (i, &byte) in capture.bytes.iter().enumerate() {
        if gap_before(capture, i).is_some() {
            ff.idle();
        }
        let _ = ff.push(byte);
        let mut next = seven.push(byte);
        while next.is_some() {
            next = seven.poll();
        }
    }
    let (frames_2020, frames_v1) = (ff.stats().frames, seven.stats().frames);
    if frames_v1 > 0 && frames_v1 >= frames_2020.saturating_mul(4) {
        Detection::Detected(Firmware::V1_0_0)
    } else if frames_2020 > 0 && frames_2020 >= frames_v1.saturating_mul(4) {
        Detection::Detected(Firmware::V2020)
    } else {
        Detection::NotRecognised {
            frames_2020,
            frames_v1,
        }
    }
}

/// One generation for both sides of a capture: the one either side decides (both, if both do
/// and agree).
fn detect_both(board: &Capture, master: &Capture) -> Detection {
    match (detect_downlink(board), detect_uplink(master)) {
        (Detection::Detected(b), Detection::Detected(m)) if b != m => Detection::SidesDisagree {
            board: b,
            master: m,
        },
        (Detection::Detected(f), _) | (_, Detection::Detected(f)) => Detection::Detected(f),
        (b, m) => {
            let count = |d: Detection| match d {
                Detection::NotRecognised {
                    frames_2020,
                    frames_v1,
                } => (frames_2020, frames_v1),
                _ => (0, 0),
            };
            let ((b20, b1), (m20, m1)) = (count(b), count(m));
            Detection::NotRecognised {
                frames_2020: b20.saturating_add(m20),
                frames_v1: b1.saturating_add(m1),
            }
        }
    }
}

/// Decodes `capture` (board → master, or master → board with `uplink`) as `firmware`, or as
/// the generation its frames show (`None`).
pub fn decode(capture: &Capture, uplink: bool, firmware: Option<Firmware>) -> Decoded {
    let detection = match firmware {
        Some(f) => Detection::Given(f),
        None if uplink => detect_uplink(capture),
        None => detect_downlink(capture),
    };
    let (frames, summary) = match (detection.firmware(), uplink) {
        (Firmware::V1_0_0, true) => decode_v1_uplink(capture),
        (Firmware::V1_0_0, false) => decode_v1_downlink(capture),
        (Firmware::V2020, true) => {
            let (frames, _, summary) = decode_uplink(capture);
            (frames, summary)
        }
        (Firmware::V2020, false) => decode_downlink(capture, &[]),
    };
    Decoded {
        frames,
        summary: format!("{}; {summary}", detection.words()),
    }
}

/// Decodes both sides of one capture, `board` (board → master) and `master` (master → board),
/// both time-stamped, as `firmware` or as the generation their frames show (`None`). The frames
/// of both sides come out in time order, each with `"from"`: `"board"` or `"master"` (offsets
/// are into its own side's input).
///
/// In a 2020 capture, each read the master sent tells the board side's parser which reply is
/// awaited from the read's last byte on (until the driver's reply timeout), as the driver does.
/// A v1.0.0 reply carries its request's code and a BCC: each side is decoded on its own.
pub fn decode_both(
    board: &Capture,
    master: &Capture,
    firmware: Option<Firmware>,
) -> Result<Decoded, String> {
    let (Some(_), Some(master_times)) = (&board.times, &master.times) else {
        return Err(
            "--master needs the time of every byte on both sides, to line them up: \
                    export each side as an async-serial CSV and give --input saleae-csv"
                .into(),
        );
    };
    let detection = match firmware {
        Some(f) => Detection::Given(f),
        None => detect_both(board, master),
    };
    if detection.firmware() == Firmware::V1_0_0 {
        let (master_frames, master_summary) = decode_v1_uplink(master);
        let (board_frames, board_summary) = decode_v1_downlink(board);
        return Ok(Decoded {
            frames: merge(board_frames, master_frames),
            summary: format!(
                "{}; board: {board_summary}; master: {master_summary}",
                detection.words()
            ),
        });
    }
    let (master_frames, reads, master_summary) = decode_uplink(master);
    let reads: Vec<(f64, Register)> = reads
        .iter()
        .filter_map(|(last, register)| Some((*master_times.get(*last)?, *register)))
        .collect();
    let (board_frames, board_summary) = decode_downlink(board, &reads);
    Ok(Decoded {
        frames: merge(board_frames, master_frames),
        summary: format!(
            "{}; board: {board_summary}; master: {master_summary}; {} reads told the board side's parser which reply to await",
            detection.words(),
            reads.len()
        ),
    })
}

/// The frames of both sides in time order, each with `"from"` (and its name before its text).
fn merge(board: Vec<Found>, master: Vec<Found>) -> Vec<Found> {
    let mut frames: Vec<(f64, u8, Found)> = Vec::new();
    for (side, list, name) in [(0u8, board, "board"), (1, master, "master")] {
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
    frames.into_iter().map(|(_, _, f)| f).collect()
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

/// The counters of a v1.0.0 parser, a frame cut by the end of the capture (`held` bytes)
/// counted with the bytes discarded.
fn v1_counters(s: &v1::Stats, held: usize) -> String {
    let discarded = u64::from(s.discarded).saturating_add(held as u64);
    format!(
        "{} bad BCC, {} bad end, {} refused; {discarded} bytes discarded",
        s.bad_checksum, s.bad_end, s.refused
    )
}

/// The board → master side of a v1.0.0 capture: telemetry and replies, each checked by its
/// BCC (gaps in the time stamps change nothing: a frame is whole and checked, or not a frame).
fn decode_v1_downlink(capture: &Capture) -> (Vec<Found>, String) {
    let mut frames = Vec::new();
    let mut placer = Placer {
        bytes: &capture.bytes,
        search_from: 0,
    };
    let (mut telemetry, mut replies) = (0u32, 0u32);
    let mut parser = v1::DownlinkParser::new();
    for (i, &byte) in capture.bytes.iter().enumerate() {
        // A frame's bytes come back to back: none spans a quiet line in the time stamps.
        if gap_before(capture, i).is_some() {
            parser.quiet();
        }
        let mut next = parser.push(byte);
        while let Some(frame) = next {
            match frame {
                v1::Downlink::Telemetry(_) => telemetry = telemetry.saturating_add(1),
                v1::Downlink::Reply(_) => replies = replies.saturating_add(1),
            }
            let (json, text) = describe_v1_downlink(&frame);
            let offset = placer.place(frame.encode().as_slice(), i + 1);
            frames.push(found(offset, time_of(capture, offset), json, &text));
            next = parser.poll();
        }
    }
    let s = parser.stats();
    let summary = format!(
        "{} bytes: {} frames (telemetry {telemetry}, reply {replies}); {}",
        capture.bytes.len(),
        s.frames,
        v1_counters(&s, parser.buffered())
    );
    (frames, summary)
}

/// The master → board side of a v1.0.0 capture.
fn decode_v1_uplink(capture: &Capture) -> (Vec<Found>, String) {
    let mut frames = Vec::new();
    let mut placer = Placer {
        bytes: &capture.bytes,
        search_from: 0,
    };
    let mut parser = v1::UplinkParser::new();
    for (i, &byte) in capture.bytes.iter().enumerate() {
        if gap_before(capture, i).is_some() {
            parser.quiet();
        }
        let mut next = parser.push(byte);
        while let Some(command) = next {
            let (json, text) = describe_v1_uplink(&command);
            let offset = placer.place(&command.encode(), i + 1);
            frames.push(found(offset, time_of(capture, offset), json, &text));
            next = parser.poll();
        }
    }
    let s = parser.stats();
    let summary = format!(
        "{} bytes: {} frames; {}",
        capture.bytes.len(),
        s.frames,
        v1_counters(&s, parser.buffered())
    );
    (frames, summary)
}

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
fn describe_v1_downlink(frame: &v1::Downlink) -> (Value, String) {
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
        v1::Downlink::Reply(r) => {
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
    }
}

/// A master → board v1.0.0 frame as JSON and one line of text.
/// A v1.0.0 command as its JSON object (the `"frame"` kind and its fields) and a line of
/// text, as `chassis decode` prints it.
pub fn describe_v1_uplink(command: &v1::Command) -> (Value, String) {
    let (kind, fields, text) = match command {
        v1::Command::BodyVelocity(v) if v.is_forced_stop() => {
            let (mut fields, _) = body_velocity(v);
            if let Some(map) = fields.as_object_mut() {
                map.insert("forced_stop".into(), json!(true));
            }
            ("v1-body-velocity", fields, "forced stop".to_string())
        }
        v1::Command::BodyVelocity(v) => {
            let (fields, text) = body_velocity(v);
            ("v1-body-velocity", fields, text)
        }
        v1::Command::MotorVelocity(m) => {
            let (fields, text) = motor_speeds(m);
            ("v1-motor-velocity", fields, text)
        }
        v1::Command::System(s) => {
            let (fields, text) = system(s);
            ("v1-system", fields, text)
        }
        v1::Command::Geometry(g) => {
            let (fields, text) = geometry(g);
            ("v1-geometry", fields, text)
        }
        v1::Command::Pid(p) => {
            let (fields, text) = pid(p);
            ("v1-pid", fields, text)
        }
        v1::Command::Readback(r) => {
            let (name, code) = (request_name(*r), r.code());
            (
                "v1-readback",
                json!({"request": name, "code": code}),
                format!("{name} (0x{code:02X})"),
            )
        }
    };
    (object(kind, fields), format!("{kind:<17} {text}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bytes of a hex golden file (`tests/golden/`), pairs only.
    fn golden(text: &str) -> Capture {
        Capture {
            bytes: parse_hex(text.as_bytes()).unwrap_or_default(),
            ..Capture::default()
        }
    }

    const V1_DOWNLINK: &str = include_str!("../../cli/tests/golden/v1_downlink.hex");
    const V1_UPLINK: &str = include_str!("../../cli/tests/golden/v1_uplink.hex");
    const DOWNLINK_2020: &str = include_str!("../../cli/tests/golden/downlink.hex");
    const UPLINK_2020: &str = include_str!("../../cli/tests/golden/uplink.hex");

    #[test]
    fn a_given_generation_skips_detection() {
        let v1 = golden(V1_DOWNLINK);
        let as_2020 = decode(&v1, false, Some(Firmware::V2020));
        assert!(as_2020.summary.starts_with("firmware 2020 (given); "));
        assert!(
            as_2020
                .frames
                .iter()
                .all(|f| f.json["frame"] != "v1-telemetry")
        );
        let as_v1 = decode(&v1, false, Some(Firmware::V1_0_0));
        assert!(as_v1.summary.starts_with("firmware v1.0.0 (given); "));
        assert_eq!(as_v1.frames.len(), 8);

        let ff = golden(DOWNLINK_2020);
        let as_v1 = decode(&ff, false, Some(Firmware::V1_0_0));
        assert!(as_v1.summary.starts_with("firmware v1.0.0 (given); "));
        assert!(as_v1.frames.is_empty());
        let up = decode(&golden(V1_UPLINK), true, Some(Firmware::V1_0_0));
        assert!(
            up.summary
                .starts_with("firmware v1.0.0 (given); 126 bytes: 9 frames")
        );
    }

    #[test]
    fn each_side_detected_by_its_own_rule() {
        assert_eq!(
            detect_downlink(&golden(V1_DOWNLINK)),
            Detection::Detected(Firmware::V1_0_0)
        );
        assert_eq!(
            detect_downlink(&golden(DOWNLINK_2020)),
            Detection::Detected(Firmware::V2020)
        );
        assert_eq!(
            detect_uplink(&golden(V1_UPLINK)),
            Detection::Detected(Firmware::V1_0_0)
        );
        assert_eq!(
            detect_uplink(&golden(UPLINK_2020)),
            Detection::Detected(Firmware::V2020)
        );
        // Nine of each generation: neither has clearly more.
        let mut mixed = golden(V1_UPLINK);
        mixed.bytes.extend(golden(UPLINK_2020).bytes);
        assert_eq!(
            detect_uplink(&mixed),
            Detection::NotRecognised {
                frames_2020: 9,
                frames_v1: 9
            }
        );
        let words = detect_uplink(&mixed).words();
        assert!(
            words.contains("not recognised (9 frames of 2020, 9 of v1.0.0"),
            "{words}"
        );
    }

    #[test]
    fn sides_that_disagree_are_not_recognised() {
        let stamped = |mut c: Capture| {
            c.times = Some((0..c.bytes.len()).map(|i| i as f64 * 1e-4).collect());
            c
        };
        let board = stamped(golden(DOWNLINK_2020));
        let master = stamped(golden(V1_UPLINK));
        let decoded = decode_both(&board, &master, None).unwrap_or_default();
        assert!(
            decoded.summary.starts_with(
                "firmware not recognised (the board side's frames are 2020, the master side's \
                 v1.0.0), decoded as 2020; "
            ),
            "{}",
            decoded.summary
        );
        // A side that decides nothing follows the other.
        let silent = stamped(Capture::default());
        let decoded = decode_both(&silent, &master, None).unwrap_or_default();
        assert!(decoded.summary.starts_with("firmware v1.0.0 (detected); "));
        assert_eq!(decoded.frames.len(), 9);
    }

    #[test]
    fn no_bytes_make_it_panic() {
        // A deterministic stream of bytes biased to frame starts and ends, in every path.
        let mut x: u32 = 0x1234_5678;
        let mut bytes = Vec::new();
        for _ in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let b = x.to_le_bytes()[0];
            bytes.push(match b % 8 {
                0 => 0x7B,
                1 => 0x7D,
                2 => 0xFF,
                _ => b,
            });
        }
        let times: Vec<f64> = (0..bytes.len()).map(|i| i as f64 * 3e-4).collect();
        let capture = Capture {
            bytes,
            times: Some(times),
            quiet_s: None,
        };
        for firmware in [None, Some(Firmware::V2020), Some(Firmware::V1_0_0)] {
            let _ = decode(&capture, false, firmware);
            let _ = decode(&capture, true, firmware);
            let _ = decode_both(&capture, &capture, firmware);
        }
    }
}
