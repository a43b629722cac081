//! Feeding bytes in: what `push` does past its fast path (judging the window as each byte
//! completes what was missing), and the loop that judges the candidate at the front of the
//! window until it needs more bytes.

use super::DownlinkParser;
use super::judge::Verdict;
use crate::telemetry::{Downlink, Kind};

impl DownlinkParser {
    /// [`push`](Self::push) when a decision may fall: a frame's last byte and junk with nothing
    /// before it take short ways here, a frame's first two bytes in
    /// [`push_decide`](Self::push_decide); anything else goes through
    /// [`push_general`](Self::push_general).
    #[inline(never)]
    pub(super) fn push_slow(&mut self, byte: u8) -> Option<Downlink> {
        if !self.drain {
            if self.missing == 1 {
                // This byte completes what was missing: a frame's header right after a frame
                // row 1 took, or the frame at the front of the window.
                if self.buf.len() == 1 {
                    return self.push_header(byte);
                }
                if self.buf.push(byte) {
                    return self.complete();
                }
            } else if self.missing == 0 && self.buf.is_empty() && !Kind::may_start(byte) {
                // A byte that starts no frame, with nothing before it: thrown away at once
                // (most bytes while hunting through noise: kept apart so that it costs little).
                self.discard_run(&[byte]);
                return None;
            }
        }
        self.push_decide(byte)
    }

    /// [`push_slow`](Self::push_slow) for a byte that may end a frame's header, its first byte
    /// alone in the window (right after a frame row 1 took): a whole header waits for the rest
    /// of its frame, as the judgement would; anything else goes to
    /// [`push_decide`](Self::push_decide).
    #[inline(never)]
    fn push_header(&mut self, byte: u8) -> Option<Downlink> {
        if let [first] = *self.buf.as_slice() {
            if let Some(wait) = Kind::from_header(first, byte).and_then(header_wait) {
                if self.buf.push(byte) {
                    self.missing = wait;
                    return None;
                }
            }
        }
        self.push_decide(byte)
    }

    /// [`push_slow`](Self::push_slow) for the bytes its short ways leave.
    #[inline(never)]
    pub(super) fn push_decide(&mut self, byte: u8) -> Option<Downlink> {
        if self.missing > 1 || self.drain {
            // The window's end is full (the general path makes room), or a frame is ready.
        } else if self.missing == 0 {
            // A frame's first two bytes: with the first, nothing can be decided; with the
            // second, the header gives the length to wait for.
            // (A byte that starts no frame went the short way.)
            let wait = match self.buf.as_slice() {
                [] => Some(0),
                &[first] => Kind::from_header(first, byte).map(|kind| kind.len().saturating_sub(2)),
                _ => None,
            };
            if let Some(wait) = wait {
                if self.buf.push(byte) {
                    self.missing = u8::try_from(wait).unwrap_or(0);
                    return None;
                }
            }
        }
        self.push_general(byte)
    }

    /// [`push`](Self::push) through the general judgement.
    #[inline(never)]
    pub(super) fn push_general(&mut self, byte: u8) -> Option<Downlink> {
        let ready = if self.drain { self.poll() } else { None };
        self.append(&[byte]);
        match ready {
            Some(frame) => {
                // (The window is not empty now: `missing` of 2 is for an empty one.)
                self.missing = 0;
                Some(frame)
            }
            None => self.poll(),
        }
    }

    pub(super) fn run(&mut self, quiet: bool) -> Option<Downlink> {
        self.missing = 0;
        loop {
            match self.judge(quiet) {
                Verdict::NeedMore(n) => {
                    self.wait_for(n);
                    return None;
                }
                Verdict::Reject => self.reject(),
                Verdict::Accept(frame, len, seen) => {
                    self.accept(&frame, len, seen);
                    // Another frame can be ready at once only if bytes are left.
                    self.drain = !self.buf.is_empty();
                    return Some(frame);
                }
            }
        }
    }

    /// Nothing can be decided before `n` more bytes: until then they are only stored.
    #[inline]
    pub(super) fn wait_for(&mut self, n: usize) {
        self.drain = false;
        // Only a wait of two bytes or more is worth the shortcut: with one, the next byte is
        // judged anyway (and a lone junk byte is dropped at once).
        self.missing = if n > 1 {
            u8::try_from(n).unwrap_or(u8::MAX)
        } else {
            0
        };
    }

    /// Appends bytes; if the window is ever full, its first byte is rejected rather than a new
    /// byte lost.
    pub(super) fn append(&mut self, mut bytes: &[u8]) {
        while !bytes.is_empty() {
            if self.buf.is_full() {
                self.reject();
            }
            let taken = self.buf.extend(bytes);
            bytes = bytes.get(taken..).unwrap_or(&[]);
        }
    }
}

/// What a frame of `kind` whose two header bytes alone are in the window leaves
/// [`missing`](DownlinkParser::missing): the bytes up to its last, as the judgement would wait
/// for them ([`DownlinkParser::wait_for`]). `None` for a frame that a wait of one byte would
/// leave to the judgement (none does: every frame is longer than three bytes).
#[inline]
fn header_wait(kind: Kind) -> Option<u8> {
    u8::try_from(kind.len().checked_sub(2)?)
        .ok()
        .filter(|n| *n > 1)
}
