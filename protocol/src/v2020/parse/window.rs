//! [`Window`]: the few bytes a streaming parser keeps, from the first byte of the candidate
//! frame it is judging.

/// A fixed buffer of up to `N` bytes (`N` below 256) that drops bytes from its front.
///
/// Rejecting a candidate drops exactly one byte (the candidate's first), so the parser rescans
/// from the byte after it; accepting a frame drops the frame's bytes. Dropping moves an index,
/// not the bytes; they move to the front only when the end is reached. Nothing here can panic.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(C)]
pub(crate) struct Window<const N: usize> {
    bytes: [u8; N],
    start: u8,
    end: u8,
}

impl<const N: usize> Window<N> {
    pub(crate) const fn new() -> Self {
        Window {
            bytes: [0; N],
            start: 0,
            end: 0,
        }
    }

    /// The bytes kept. Out of line: most of its callers are off the path every frame takes,
    /// and each inlined copy costs flash.
    #[inline(never)]
    pub(crate) fn as_slice(&self) -> &[u8] {
        self.kept()
    }

    /// [`as_slice`](Self::as_slice) inlined, for the few places every frame goes through.
    #[inline(always)]
    pub(crate) fn kept(&self) -> &[u8] {
        self.bytes
            .get(..usize::from(self.end))
            .and_then(|kept| kept.get(usize::from(self.start)..))
            .unwrap_or(&[])
    }

    #[inline]
    pub(crate) const fn len(&self) -> usize {
        self.end.saturating_sub(self.start) as usize
    }

    #[inline]
    pub(crate) const fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// No room at the end without a byte dropped from the front first.
    #[inline]
    pub(crate) const fn is_full(&self) -> bool {
        self.len() >= N
    }

    /// Appends one byte if there is room at the end; `false` if not (nothing done).
    #[inline]
    pub(crate) fn push(&mut self, byte: u8) -> bool {
        let end = self.end;
        match self.bytes.get_mut(usize::from(end)) {
            Some(slot) => {
                *slot = byte;
                // (`end` indexes the window: no wrap.)
                self.end = end.wrapping_add(1);
                true
            }
            None => false,
        }
    }

    /// Appends what fits of `bytes`; returns how many.
    #[inline]
    pub(crate) fn extend(&mut self, bytes: &[u8]) -> usize {
        if usize::from(self.end).saturating_add(bytes.len()) > N && self.start > 0 {
            self.compact();
        }
        let end = usize::from(self.end).min(N);
        // (A byte at a time: a frame's few bytes, and no `memcpy` to link in.)
        let mut taken = 0usize;
        for (to, from) in self
            .bytes
            .get_mut(end..)
            .unwrap_or(&mut [])
            .iter_mut()
            .zip(bytes)
        {
            *to = *from;
            taken = taken.wrapping_add(1);
        }
        self.end = u8::try_from(end.saturating_add(taken)).unwrap_or(self.end);
        taken
    }

    /// Moves the bytes kept to the front.
    pub(crate) fn compact(&mut self) {
        // (Byte by byte, forwards: no copy of the whole buffer first.)
        let end = usize::from(self.end).min(N);
        let start = usize::from(self.start).min(end);
        for from in start..end {
            let byte = self.bytes.get(from).copied().unwrap_or(0);
            if let Some(to) = self.bytes.get_mut(from.wrapping_sub(start)) {
                *to = byte;
            }
        }
        self.end = self.end.saturating_sub(self.start);
        self.start = 0;
    }

    /// Hides the last `n` bytes (all of them if there are fewer) from everything but
    /// [`unhide`](Self::unhide); returns where they are. Until then nothing may be added.
    pub(crate) fn hide(&mut self, n: u8) -> u8 {
        let n = n.min(self.end.saturating_sub(self.start));
        self.end = self.end.saturating_sub(n);
        self.end
    }

    /// Puts `n` bytes hidden at `at` back after the bytes kept (moved there if the front was
    /// dropped to the start meanwhile).
    pub(crate) fn unhide(&mut self, at: u8, n: u8) {
        let (at, end) = (usize::from(at), usize::from(self.end));
        if at != end {
            for i in 0..usize::from(n) {
                let byte = self.bytes.get(at.saturating_add(i)).copied().unwrap_or(0);
                if let Some(to) = self.bytes.get_mut(end.saturating_add(i)) {
                    *to = byte;
                }
            }
        }
        self.end = u8::try_from(end.saturating_add(usize::from(n)).min(N)).unwrap_or(self.end);
    }

    /// Forgets every byte kept.
    #[inline]
    pub(crate) fn clear(&mut self) {
        self.start = 0;
        self.end = 0;
    }

    /// Drops the first `n` bytes (all of them if `n` is larger).
    #[inline]
    pub(crate) fn drop_front(&mut self, n: usize) {
        let n = u8::try_from(n.min(self.len())).unwrap_or(0);
        self.start = self.start.saturating_add(n);
        if self.start >= self.end {
            self.start = 0;
            self.end = 0;
        }
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
