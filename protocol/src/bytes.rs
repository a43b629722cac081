//! [`FrameBytes`]: the bytes of a frame whose length depends on its type, without allocation.

use crate::wire;

/// The encoded bytes of a frame of up to `N` bytes: a fixed buffer and the used length.
///
/// Returned by [`Command::encode`](crate::Command::encode) and
/// [`Downlink::encode`](crate::Downlink::encode), whose frame types differ in length. It
/// dereferences to `&[u8]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameBytes<const N: usize> {
    bytes: [u8; N],
    len: u8,
}

impl<const N: usize> FrameBytes<N> {
    /// Copies `frame` (at most `N` bytes; a longer one is cut at `N`).
    pub(crate) fn new(frame: &[u8]) -> Self {
        let mut bytes = [0u8; N];
        let len = frame.len().min(N);
        wire::put(&mut bytes, 0, frame.get(..len).unwrap_or(&[]));
        FrameBytes {
            bytes,
            len: u8::try_from(len).unwrap_or(0),
        }
    }

    /// The frame's bytes.
    #[must_use]
    pub fn as_slice(&self) -> &[u8] {
        self.bytes.get(..usize::from(self.len)).unwrap_or(&[])
    }

    /// The frame's length.
    #[must_use]
    pub const fn len(&self) -> usize {
        self.len as usize
    }

    /// `true` only for a zero-length frame, which no encoder returns.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl<const N: usize> AsRef<[u8]> for FrameBytes<N> {
    fn as_ref(&self) -> &[u8] {
        self.as_slice()
    }
}

impl<const N: usize> core::ops::Deref for FrameBytes<N> {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        self.as_slice()
    }
}
