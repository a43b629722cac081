//! Big-endian field access that cannot panic.
//!
//! Every frame module keeps its byte offsets in a private `field` table and reads and writes
//! through these helpers. Offsets are constants, so after inlining the bounds checks fold
//! away; an offset past the end reads as 0 and writes nothing instead of panicking.

/// The byte at `at`, or 0 past the end.
#[inline]
pub(crate) fn u8_at(buf: &[u8], at: usize) -> u8 {
    buf.get(at).copied().unwrap_or(0)
}

/// The big-endian `u16` at `at..at + 2`, or 0 past the end.
#[inline]
pub(crate) fn u16_at(buf: &[u8], at: usize) -> u16 {
    match buf.get(at..at.saturating_add(2)) {
        Some(&[hi, lo]) => u16::from_be_bytes([hi, lo]),
        _ => 0,
    }
}

/// The big-endian `i16` at `at..at + 2`, or 0 past the end.
#[inline]
pub(crate) fn i16_at(buf: &[u8], at: usize) -> i16 {
    i16::from_be_bytes(u16_at(buf, at).to_be_bytes())
}

/// The big-endian `u32` at `at..at + 4`, or 0 past the end.
#[inline]
pub(crate) fn u32_at(buf: &[u8], at: usize) -> u32 {
    match buf.get(at..at.saturating_add(4)) {
        Some(&[b3, b2, b1, b0]) => u32::from_be_bytes([b3, b2, b1, b0]),
        _ => 0,
    }
}

/// Writes `bytes` at `at` (as many as fit: offsets are constants that always fit). A zip, not
/// `copy_from_slice`, so that no length check can panic.
#[inline]
pub(crate) fn put(buf: &mut [u8], at: usize, bytes: &[u8]) {
    if let Some(dst) = buf.get_mut(at..) {
        for (d, s) in dst.iter_mut().zip(bytes) {
            *d = *s;
        }
    }
}

/// Writes one byte at `at`; nothing if past the end.
#[inline]
pub(crate) fn put_u8(buf: &mut [u8], at: usize, value: u8) {
    put(buf, at, &[value]);
}

/// Writes a big-endian `u16` at `at`.
#[inline]
pub(crate) fn put_u16(buf: &mut [u8], at: usize, value: u16) {
    put(buf, at, &value.to_be_bytes());
}

/// Writes a big-endian `i16` at `at`.
#[inline]
pub(crate) fn put_i16(buf: &mut [u8], at: usize, value: i16) {
    put(buf, at, &value.to_be_bytes());
}

/// Writes a big-endian `u32` at `at`.
#[inline]
pub(crate) fn put_u32(buf: &mut [u8], at: usize, value: u32) {
    put(buf, at, &value.to_be_bytes());
}

/// Splits a signed value into the wire's magnitude (saturated at `max`) and reverse flag.
#[inline]
pub(crate) fn split_signed(value: i32, max: u16) -> (u16, bool) {
    let magnitude = value.unsigned_abs().min(u32::from(max));
    // `magnitude <= u16::MAX` after the `min`, so the conversion cannot fail.
    (u16::try_from(magnitude).unwrap_or(max), value < 0)
}

/// Joins a wire magnitude and reverse flag into a signed value.
#[inline]
pub(crate) fn join_signed(magnitude: u16, reverse: bool) -> i32 {
    let value = i32::from(magnitude);
    if reverse { value.wrapping_neg() } else { value }
}

/// Clamps `value` to `-limit..=limit`.
#[inline]
pub(crate) fn clamp_signed(value: i32, limit: u16) -> i32 {
    value.clamp(i32::from(limit).wrapping_neg(), i32::from(limit))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_past_the_end_are_zero_and_writes_are_cut() {
        let mut buf = [0xAAu8; 3];
        assert_eq!(u16_at(&buf, 2), 0);
        assert_eq!(u32_at(&buf, 0), 0);
        assert_eq!(u8_at(&buf, 3), 0);
        put_u16(&mut buf, usize::MAX, 0x1234);
        assert_eq!(buf, [0xAA; 3]);
        put_u16(&mut buf, 2, 0x1234);
        assert_eq!(buf, [0xAA, 0xAA, 0x12]);
    }

    #[test]
    fn big_endian() {
        let buf = [0x12, 0x34, 0xFF, 0xFA, 0x80, 0x00];
        assert_eq!(u16_at(&buf, 0), 0x1234);
        assert_eq!(i16_at(&buf, 2), -6);
        assert_eq!(u32_at(&buf, 2), 0xFFFA_8000);
    }

    #[test]
    fn signed_split_saturates_and_keeps_the_sign() {
        assert_eq!(split_signed(-300, u16::MAX), (300, true));
        assert_eq!(split_signed(70_000, u16::MAX), (65_535, false));
        assert_eq!(split_signed(i32::MIN, 10_000), (10_000, true));
        assert_eq!(join_signed(300, true), -300);
        assert_eq!(join_signed(0, true), 0);
        assert_eq!(clamp_signed(-20_000, 10_000), -10_000);
    }
}
