//! The window: the bytes kept, from the first byte of the candidate being judged.

use super::WINDOW;

/// The bytes kept, from the first byte of the candidate being judged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Buf {
    pub(super) bytes: [u8; WINDOW],
    pub(super) start: u8,
    pub(super) end: u8,
}

impl Buf {
    pub(super) const fn new() -> Self {
        Buf {
            bytes: [0; WINDOW],
            start: 0,
            end: 0,
        }
    }

    #[inline]
    pub(super) fn as_slice(&self) -> &[u8] {
        self.bytes
            .get(usize::from(self.start)..usize::from(self.end))
            .unwrap_or(&[])
    }

    #[inline]
    pub(super) const fn len(&self) -> usize {
        self.end.saturating_sub(self.start) as usize
    }

    #[inline]
    pub(super) const fn is_full(&self) -> bool {
        self.len() >= WINDOW
    }

    /// Appends one byte if there is room at the end; `false` if not (nothing done).
    #[inline]
    pub(super) fn push(&mut self, byte: u8) -> bool {
        match self.bytes.get_mut(usize::from(self.end)) {
            Some(slot) => {
                *slot = byte;
                // (`end` indexes the window: no wrap.)
                self.end = self.end.wrapping_add(1);
                true
            }
            None => false,
        }
    }

    /// Appends what fits of `bytes`; returns how many.
    #[inline]
    pub(super) fn extend(&mut self, bytes: &[u8]) -> usize {
        if usize::from(self.end).saturating_add(bytes.len()) > WINDOW && self.start > 0 {
            self.compact();
        }
        let end = usize::from(self.end);
        let taken = bytes.len().min(WINDOW.saturating_sub(end));
        let to = end.saturating_add(taken);
        match (self.bytes.get_mut(end..to), bytes.get(..taken)) {
            (Some(dst), Some(src)) => dst.copy_from_slice(src),
            _ => return 0,
        }
        self.end = u8::try_from(to).unwrap_or(self.end);
        taken
    }

    /// Moves the bytes kept to the front.
    pub(super) fn compact(&mut self) {
        let (start, end) = (usize::from(self.start), usize::from(self.end));
        let old = self.bytes;
        if let Some(src) = old.get(start..end) {
            if let Some(dst) = self.bytes.get_mut(..src.len()) {
                dst.copy_from_slice(src);
            }
        }
        self.end = self.end.saturating_sub(self.start);
        self.start = 0;
    }

    /// Forgets every byte kept.
    #[inline]
    pub(super) fn clear(&mut self) {
        self.start = 0;
        self.end = 0;
    }

    #[inline]
    pub(super) fn drop_front(&mut self, n: usize) {
        let n = u8::try_from(n.min(self.len())).unwrap_or(0);
        self.start = self.start.saturating_add(n);
        if self.start >= self.end {
            self.start = 0;
            self.end = 0;
        }
    }
}
