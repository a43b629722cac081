//! Files and standard input, read up to a stated size: past it, a clear error at once (a
//! `settings --restore /dev/zero` or `decode /dev/zero` is refused, not read until memory runs
//! out).

use std::io::Read;

/// The largest settings file `settings --restore` reads (a saved one is under 1 KiB).
pub const SETTINGS_MAX: u64 = 64 << 10;

/// The largest capture `decode` reads: 256 MiB (a `chassis record` capture of the 2020 board
/// grows by about 80 KB a second: some 50 minutes).
pub const CAPTURE_MAX: u64 = 256 << 20;

/// The size in words: "64 KiB", "256 MiB".
fn size_words(bytes: u64) -> String {
    if bytes >= 1 << 20 {
        format!("{} MiB", bytes >> 20)
    } else {
        format!("{} KiB", bytes >> 10)
    }
}

/// Everything `source` holds, refused past `max` bytes; `name` names it in errors.
fn read_up_to(source: impl Read, max: u64, name: &str, what: &str) -> Result<Vec<u8>, String> {
    let mut data = Vec::new();
    source
        .take(max.saturating_add(1))
        .read_to_end(&mut data)
        .map_err(|e| format!("cannot read {name}: {e}"))?;
    if u64::try_from(data.len()).unwrap_or(u64::MAX) > max {
        return Err(format!(
            "{name} holds more than {}: larger than any {what} (nothing was done)",
            size_words(max)
        ));
    }
    Ok(data)
}

/// The bytes of `file` (`None` or "-": standard input), at most `max`.
pub fn read(file: Option<&str>, max: u64, what: &str) -> Result<Vec<u8>, String> {
    match file {
        None | Some("-") => read_up_to(std::io::stdin().lock(), max, "standard input", what),
        Some(path) => {
            let file = std::fs::File::open(path).map_err(|e| format!("cannot read {path}: {e}"))?;
            read_up_to(file, max, path, what)
        }
    }
}

/// The text of `file`, at most `max` bytes.
pub fn read_text(file: &str, max: u64, what: &str) -> Result<String, String> {
    let bytes = read(Some(file), max, what)?;
    String::from_utf8(bytes).map_err(|_| format!("{file}: not text: not a {what}"))
}
