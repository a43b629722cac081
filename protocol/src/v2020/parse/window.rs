//! [`Window`]: the few bytes a streaming parser keeps, from the first byte of the candidate
//! frame it is judging.

/// A fixed buffer of up to `N` bytes that drops bytes from its front.
///
/// Rejecting a candidate drops exactly one byte (the candidate's first), so the parser rescans
/// from the byte after it; accepting a frame drops the frame's bytes. Nothing here can panic.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Window<const N: usize> {
    bytes: [u8; N],
    len: u8,
}

impl<const N: usize> Window<N> {
    pub(crate) const fn new() -> Self {
        Window {
            bytes: [0; N],
            len: 0,
        }
    }

    /// The bytes held, oldest first.
    #[inline]
    pub(crate) fn as_slice(&self) -> &[u8] {
        self.bytes
            .get(..usize::from(self.len))
            .unwrap_or(&self.bytes)
    }

    #[inline]
    pub(crate) const fn len(&self) -> usize {
        self.len as usize
    }

    #[inline]
    pub(crate) const fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Room for `push` without a drop first.
    #[inline]
    pub(crate) const fn is_full(&self) -> bool {
        self.len as usize >= N
    }

    /// Appends `bytes`; returns how many fit.
    #[inline]
    pub(crate) fn extend(&mut self, bytes: &[u8]) -> usize {
        let start = self.len();
        let mut taken: usize = 0;
        if let Some(dst) = self.bytes.get_mut(start..) {
            for (d, s) in dst.iter_mut().zip(bytes) {
                *d = *s;
                taken = taken.saturating_add(1);
            }
        }
        self.len = u8::try_from(start.saturating_add(taken)).unwrap_or(self.len);
        taken
    }

    /// Drops the first `n` bytes (all of them if `n` is larger).
    #[inline]
    pub(crate) fn drop_front(&mut self, n: usize) {
        let len = self.len();
        let n = n.min(len);
        // A new array of N (17) bytes, each taken from `n` further on: a fixed-size copy, so no
        // call to `memmove` (whose general version is 1.5 KB of flash on a Cortex-M), and unlike
        // `copy_within`, no panic path to reason about.
        let old = self.bytes;
        self.bytes = core::array::from_fn(|i| old.get(i.saturating_add(n)).copied().unwrap_or(0));
        self.len = u8::try_from(len.saturating_sub(n)).unwrap_or(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extend_and_drop() {
        let mut w = Window::<4>::new();
        assert_eq!(w.extend(&[1, 2, 3]), 3);
        assert_eq!(w.extend(&[4, 5]), 1);
        assert!(w.is_full());
        assert_eq!(w.as_slice(), &[1, 2, 3, 4]);
        w.drop_front(1);
        assert_eq!(w.as_slice(), &[2, 3, 4]);
        w.drop_front(10);
        assert!(w.is_empty());
    }
}
