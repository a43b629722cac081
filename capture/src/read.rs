//! Reading a capture: raw bytes, hex text or a logic analyser's async-serial export (Saleae
//! Logic 1 or 2 CSV), into [`Capture`]: the bytes, and the time of each when it has them.

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

impl Capture {
    /// The time of byte `offset`, if the capture has times.
    pub(crate) fn time_of(&self, offset: usize) -> Option<f64> {
        self.times.as_ref().and_then(|t| t.get(offset).copied())
    }

    /// How long the line was quiet before byte `i`, in ms, if longer than the capture's quiet
    /// gap.
    pub(crate) fn gap_before(&self, i: usize) -> Option<u32> {
        let times = self.times.as_ref()?;
        let (a, b) = (times.get(i.checked_sub(1)?)?, times.get(i)?);
        let gap = b - a;
        (gap > self.quiet_s.unwrap_or(QUIET_GAP_S))
            .then(|| (gap * 1000.0).round().clamp(1.0, 60_000.0) as u32)
    }
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
    let columns = Columns::of(header)?;
    let mut capture = Capture {
        times: Some(Vec::new()),
        ..Capture::default()
    };
    for (line_no, line) in lines {
        let fields = split_csv(line);
        if !keep(&fields) {
            continue;
        }
        let Some((time, byte)) = columns.row(&fields, line_no + 1)? else {
            continue;
        };
        capture.bytes.push(byte);
        if let Some(times) = capture.times.as_mut() {
            times.push(time);
        }
    }
    Ok(capture)
}

/// Where the columns an async-serial export's rows are read from stand.
struct Columns {
    /// The time stamp's.
    time: usize,
    /// The byte's.
    value: usize,
    /// The row's type (Logic 2), if the export has one.
    kind: Option<usize>,
}

impl Columns {
    /// The columns `header` names: a time column and a value/data column, or an error.
    fn of(header: &str) -> Result<Columns, String> {
        let columns: Vec<String> = split_csv(header)
            .iter()
            .map(|c| c.trim().to_ascii_lowercase())
            .collect();
        let time = columns.iter().position(|c| c.contains("time"));
        let value = columns
            .iter()
            .position(|c| c == "value" || c == "data" || c.starts_with("value"));
        let (Some(time), Some(value)) = (time, value) else {
            return Err(format!(
                "CSV input: not an async-serial export (its header {header:?} names no time and \
                 value/data columns)"
            ));
        };
        let kind = columns.iter().position(|c| c == "type");
        Ok(Columns { time, value, kind })
    }

    /// The time and byte of the row `fields` (line `line` of the input), or `None` for a row
    /// that is not a byte.
    fn row(&self, fields: &[String], line: usize) -> Result<Option<(f64, u8)>, String> {
        // Logic 2 exports errors and other rows with a type other than "data".
        if let Some(t) = self.kind.and_then(|i| fields.get(i)) {
            if !t.trim().eq_ignore_ascii_case("data") {
                return Ok(None);
            }
        }
        let (Some(time), Some(value)) = (fields.get(self.time), fields.get(self.value)) else {
            return Err(format!("CSV input, line {line}: too few columns"));
        };
        let time: f64 = time
            .trim()
            .parse()
            .map_err(|_| format!("CSV input, line {line}: {time:?} is not a time"))?;
        let value = value.trim().trim_matches('\'');
        let byte = match value
            .strip_prefix("0x")
            .or_else(|| value.strip_prefix("0X"))
        {
            Some(hex) => u8::from_str_radix(hex, 16).ok(),
            None => value.parse::<u8>().ok(),
        }
        .ok_or_else(|| format!("CSV input, line {line}: {value:?} is not a byte"))?;
        Ok(Some((time, byte)))
    }
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
