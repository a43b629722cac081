//! Numbers from the command line: decimal, or hexadecimal with `0x`; a value out of range is a
//! clear error.

fn parse_i64(text: &str) -> Option<i64> {
    let t = text.trim().replace('_', "");
    let (negative, digits) = match t.strip_prefix('-') {
        Some(rest) => (true, rest.to_string()),
        None => (false, t.strip_prefix('+').unwrap_or(&t).to_string()),
    };
    let magnitude = match digits
        .strip_prefix("0x")
        .or_else(|| digits.strip_prefix("0X"))
    {
        Some(hex) => i64::from_str_radix(hex, 16).ok()?,
        None => digits.parse::<i64>().ok()?,
    };
    Some(if negative { -magnitude } else { magnitude })
}

/// `text` as a signed number within `min..=max`.
pub fn parse_i32(text: &str, name: &str, min: i64, max: i64) -> Result<i32, String> {
    let v = parse_i64(text).ok_or_else(|| format!("{name}: {text:?} is not a number"))?;
    if v < min || v > max {
        return Err(format!("{name}: {v} is out of range ({min}..={max})"));
    }
    i32::try_from(v).map_err(|_| format!("{name}: {v} is out of range"))
}

/// `text` as an unsigned number within `min..=max`.
pub fn parse_u32(text: &str, name: &str, min: u32, max: u32) -> Result<u32, String> {
    let v = parse_i64(text).ok_or_else(|| format!("{name}: {text:?} is not a number"))?;
    if v < i64::from(min) || v > i64::from(max) {
        return Err(format!("{name}: {v} is out of range ({min}..={max})"));
    }
    u32::try_from(v).map_err(|_| format!("{name}: {v} is out of range"))
}
