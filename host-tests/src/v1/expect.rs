//! What the XOR checksum cannot see, worked out: the probability that bit errors damage a frame
//! in place and it still passes.
//!
//! A frame passes when its start is `7B`, its code one of its length's, its end `7D`, and the
//! XOR of every byte from the start through the BCC is zero. Flip each bit independently with
//! probability `p`. The XOR is zero exactly when, at each of the 8 bit positions, an even number
//! of the bytes between start and end flipped there. Over `m` bytes, an even number of flips at
//! one position has probability `(1 + (1 − 2p)^m) / 2`, an odd number `(1 − (1 − 2p)^m) / 2`.
//!
//! * **Telemetry** (32 bytes): start, code `00` and end unflipped (24 bits), every position even
//!   over the `m = 29` payload and BCC bytes, less the case with no flip at all:
//!   `(1 − p)^24 · [((1 + (1 − 2p)^29) / 2)^8 − (1 − p)^232]` ≈ `8 · C(29, 2) · p² = 3248 p²`.
//! * **Reply** (14 bytes): start and end unflipped (16 bits); the code may turn into another
//!   readback code (`34` ↔ `35` and `34` ↔ `36` differ by one bit): for each code `c'` of the
//!   five, the code's flips make the mask `c ⊕ c'`, and each position of the `m = 11` payload
//!   and BCC bytes must flip an odd number of times where the mask has a 1, even where it has a
//!   0; less the case with no flip: about `(8 · C(11, 2) + k · 11) · p² = (440 + 11k) p²`, `k`
//!   the one-bit neighbours of the code (2 for `34`, 1 for `35` and `36`, 0 for `33` and `50`).

use chassis_protocol::v1::{Downlink, Readback};

/// Probability that the bits flipped at `p` over `m` bytes give, at each of the 8 positions,
/// the parity of `mask`'s bit there.
fn parities(p: f64, m: i32, mask: u8) -> f64 {
    let d = (1.0 - 2.0 * p).powi(m);
    let (even, odd) = ((1.0 + d) / 2.0, (1.0 - d) / 2.0);
    (0..8)
        .map(|b| if mask & (1 << b) != 0 { odd } else { even })
        .product()
}

/// Probability that a telemetry frame comes out of bit errors at `p` changed and still passes.
pub fn undetected_telemetry(p: f64) -> f64 {
    let q = 1.0 - p;
    q.powi(24) * (parities(p, 29, 0) - q.powi(8 * 29))
}

/// Probability that a reply with `code` comes out of bit errors at `p` changed and still passes
/// (as a reply with this code or another readback code).
pub fn undetected_reply(p: f64, code: u8) -> f64 {
    let q = 1.0 - p;
    let mut pass = 0.0;
    for other in Readback::ALL {
        let mask = code ^ other.code();
        let w = mask.count_ones() as i32;
        pass += p.powi(w) * q.powi(8 - w) * parities(p, 11, mask);
    }
    q.powi(16) * pass - q.powi(8 * 14)
}

/// [`undetected_telemetry`] or [`undetected_reply`], for `frame`.
pub fn undetected(frame: &Downlink, p: f64) -> f64 {
    if p <= 0.0 {
        return 0.0;
    }
    match frame {
        Downlink::Telemetry(_) => undetected_telemetry(p),
        Downlink::Reply(r) => undetected_reply(p, r.request.code()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chassis_protocol::v1::{Reply, Telemetry};
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    #[test]
    fn small_p_agrees_with_counting_pairs() {
        let p = 1e-6;
        let t = undetected_telemetry(p) / (p * p);
        assert!((t - 3_248.0).abs() < 1.0, "{t}");
        let r = undetected_reply(p, 0x34) / (p * p);
        assert!((r - (440.0 + 22.0)).abs() < 1.0, "{r}");
        let r = undetected_reply(p, 0x50) / (p * p);
        assert!((r - 440.0).abs() < 1.0, "{r}");
    }

    /// Flipping bits at random and asking the decoder agrees with the formula.
    #[test]
    fn the_decoder_agrees() {
        let p = 0.02;
        let frames = [
            Downlink::Telemetry(Telemetry {
                velocity: [12, -300, 45],
                quaternion: [707, 0, 0, 707],
                battery_mv: 12_000,
                ..Telemetry::default()
            }),
            Downlink::Reply(Reply {
                request: Readback::Geometry,
                payload: [0, 110, 0, 110, 0, 55, 0, 60, 0, 0],
            }),
        ];
        let mut rng = Pcg64Mcg::seed_from_u64(9);
        for frame in frames {
            let sent = frame.encode();
            let n = 100_000;
            let mut passed = 0;
            for _ in 0..n {
                let mut bytes = sent.as_slice().to_vec();
                for byte in &mut bytes {
                    for bit in 0..8 {
                        if rng.random_bool(p) {
                            *byte ^= 1 << bit;
                        }
                    }
                }
                if bytes != sent.as_slice() && Downlink::decode(&bytes).is_ok() {
                    passed += 1;
                }
            }
            let want = undetected(&frame, p) * n as f64;
            assert!(
                (passed as f64 - want).abs() < 4.0 * want.sqrt(),
                "{frame:?}: {passed} passed, {want:.0} expected"
            );
        }
    }
}
