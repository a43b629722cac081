//! Feeding bytes in: what `push` does past its fast path (judging the window as each byte
//! completes what was missing), and the loop that judges the candidate at the front of the
//! window until it needs more bytes.

use super::judge::Verdict;
use super::{DownlinkParser, RESUME_DRAIN, WINDOW, short_ways};
use crate::telemetry::{Downlink, Kind};

impl DownlinkParser {
    /// [`push`](Self::push) when a decision may fall: a frame's last byte and junk with nothing
    /// before it take short ways here, a frame's first two bytes in
    /// [`push_decide`](Self::push_decide); anything else goes through
    /// [`push_general`](Self::push_general).
    #[inline(never)]
    pub(super) fn push_slow(&mut self, byte: u8) -> Option<Downlink> {
        if !short_ways() {
            return self.push_general(byte);
        }
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
        if let [first] = *self.buf.kept() {
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

    /// [`push`](Self::push) through the general judgement. A frame already decided comes out
    /// first (the byte is stored behind it, judged at the next call); else the byte is stored,
    /// and the window judged only if the last judgement waits for no more than this byte (or
    /// the window was full and its first byte went): judgements fall at the same bytes however
    /// the bytes are fed and polled.
    #[inline(never)]
    pub(super) fn push_general(&mut self, byte: u8) -> Option<Downlink> {
        let ready = if self.drain {
            self.complete_behind()
        } else {
            None
        };
        let full = self.buf.is_full();
        if full || !self.buf.push(byte) {
            self.append(&[byte]);
        }
        if ready.is_some() {
            if self.behind.len == 0 && !self.drain && !full && self.missing > 1 && short_ways() {
                // The frame left a wait that this byte does not end: polled first, the byte
                // would only have been stored (`push`'s fast path), and it is.
                self.missing = self.missing.wrapping_sub(1);
                return ready;
            }
            // The byte waits behind what is left of the window (if anything): judged after
            // it, at the next call, as if the frame had been polled out before the byte came.
            if self.behind.len == 0 {
                self.hold_behind();
            }
            self.behind.len = self.behind.len.saturating_add(1);
        } else if self.missing > 1 && !full {
            self.missing = self.missing.wrapping_sub(1);
        } else {
            return self.complete();
        }
        ready
    }

    /// [`complete`](Self::complete) while bytes wait [`behind`](Self::behind): the window is
    /// judged without them first, then they are taken one at a time, each as
    /// [`push_general`](Self::push_general) takes a byte, until a frame comes out. Whichever
    /// way the bytes were fed, each judgement sees the bytes it sees when every byte is pushed
    /// alone and polled after.
    #[inline(never)]
    pub(super) fn complete_behind(&mut self) -> Option<Downlink> {
        let behind = self.behind.len;
        if behind == 0 && (self.drain || self.missing == 0) {
            // Nothing behind: the window judged as it is (the loop below, in short).
            let frame = self.complete();
            if !self.drain {
                self.expect_pending();
            }
            return frame;
        }
        let mut left = behind;
        let mut at = self.buf.hide(left);
        if behind > 0 && self.behind.resume != RESUME_DRAIN {
            // The frame before them left nothing ready: the state it left, back.
            self.drain = false;
            self.missing = self.behind.resume;
        }
        // The window without them first (as a `poll` would judge it), then at each byte behind
        // that ends a wait.
        let mut judge = self.drain || self.missing == 0;
        let frame = loop {
            if judge {
                if let Some(frame) = self.complete() {
                    break Some(frame);
                }
            }
            if left == 0 {
                break None;
            }
            let taken = behind.wrapping_sub(left);
            if self.expect.next.is_some_and(|(_, at)| at == taken) {
                self.expect_pending();
            }
            self.buf.unhide(at, 1);
            at = at.wrapping_add(1);
            left = left.wrapping_sub(1);
            judge = self.missing <= 1;
            if !judge {
                self.missing = self.missing.wrapping_sub(1);
            }
        };
        self.buf.unhide(at, left);
        if let Some((_, at)) = &mut self.expect.next {
            *at = at.saturating_sub(behind.wrapping_sub(left));
        }
        self.behind.len = left;
        if left > 0 {
            self.hold_behind();
        } else if !self.drain {
            self.expect_pending();
        }
        frame
    }

    /// Bytes wait [`behind`](Self::behind) a frame that just came out: the state that frame
    /// left is kept for [`complete_behind`](Self::complete_behind), and every call goes there
    /// first (`drain`, with `missing` 0 as `drain` wants it).
    fn hold_behind(&mut self) {
        self.behind.resume = if self.drain {
            RESUME_DRAIN
        } else {
            self.missing
        };
        self.drain = true;
        self.missing = 0;
    }

    /// What [`expect_reply`](Self::expect_reply) said while frames were still to come out, now
    /// that they are out.
    fn expect_pending(&mut self) {
        if let Some((code, _)) = self.expect.next.take() {
            self.expect_now(code);
        }
    }

    /// [`expect_reply`](Self::expect_reply) from now on. A candidate waiting in the window may
    /// be judged differently now: it is judged at the next byte, not only once the bytes it
    /// was waiting for are in (and not at a `poll` before it: whether the caller polls in
    /// between changes nothing).
    pub(super) fn expect_now(&mut self, code: Option<u8>) {
        self.expect.code = code;
        self.header_at = 0;
        self.missing = self.missing.min(self.front_missing()).max(1);
    }

    pub(super) fn run(&mut self, quiet: bool) -> Option<Downlink> {
        self.missing = 0;
        self.header_at = 0;
        loop {
            match self.judge(quiet) {
                Verdict::NeedMore(n) => {
                    self.wait_for(n);
                    return None;
                }
                Verdict::NeedHeader => {
                    self.wait_for_header();
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

    /// Nothing can be decided before the chain's next header, two bytes from the window's end
    /// ([`Verdict::NeedHeader`]): they are only stored, then [`chain_header_wait`](Self::chain_header_wait)
    /// looks at them.
    pub(super) fn wait_for_header(&mut self) {
        self.wait_for(2);
        self.header_at = u8::try_from(self.buf.len()).unwrap_or(0);
    }

    /// At the first judgement after [`wait_for_header`](Self::wait_for_header) (it applies to
    /// that one only), with those two bytes in: a header there whose frame fits the window
    /// makes the judgement wait for the rest of that frame (the chain's walk reaches it as it
    /// left it, nothing before it having changed, and its frame is incomplete): how many more
    /// bytes. `None`: the judgement decides.
    #[inline]
    pub(super) fn chain_header_wait(&mut self) -> Option<usize> {
        let at = usize::from(core::mem::take(&mut self.header_at));
        if at == 0 || !short_ways() {
            return None;
        }
        let [first, second] = *self.buf.as_slice().get(at..)? else {
            return None;
        };
        let len = Kind::from_header(first, second)?.len();
        (at.checked_add(len)? <= WINDOW).then(|| len.saturating_sub(2))
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
