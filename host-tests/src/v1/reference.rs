//! A deliberately simple reference for the v1.0.0 parsers (`chassis_protocol::v1`): the rules
//! of `DownlinkParser` and `UplinkParser` written as plainly as they can be, with a `Vec` for
//! the bytes held and no fast path, so that the crate's parsers (whose fast paths are anything
//! but plain) can be checked against it frame for frame and counter for counter.
//!
//! The rules: a frame starts with `7B`; its code (byte 1) gives its length; once that many
//! bytes are held it is judged (end `7D`, then the BCC, then whether its content is a frame of
//! this direction). A frame taken leaves the bytes after it; anything else drops the first byte
//! held, and the next `7B` among the rest is tried. A byte that cannot start a frame is
//! discarded at once; at a quiet line the start of a frame cut short is dropped a byte at a
//! time (a frame whole among the bytes held still comes out).

use chassis_protocol::v1::{COMMAND_LEN, Command, Downlink, END, START, Stats, bcc};

/// What a reference parser needs of its direction.
pub trait Direction {
    /// What it finds.
    type Frame;
    /// The length of a frame whose code is `code`, if it has one.
    fn len_of(code: u8) -> Option<usize>;
    /// The frame of `bytes`, whose start, end and BCC are right, if it is one of this
    /// direction's.
    fn decode(bytes: &[u8]) -> Option<Self::Frame>;
}

/// Board → master: telemetry and replies.
#[derive(Debug)]
pub struct BoardToMaster;

impl Direction for BoardToMaster {
    type Frame = Downlink;
    fn len_of(code: u8) -> Option<usize> {
        Downlink::len_of(code)
    }
    fn decode(bytes: &[u8]) -> Option<Downlink> {
        Downlink::decode(bytes).ok()
    }
}

/// Master → board: commands.
#[derive(Debug)]
pub struct MasterToBoard;

impl Direction for MasterToBoard {
    type Frame = Command;
    fn len_of(code: u8) -> Option<usize> {
        Command::is_code(code).then_some(COMMAND_LEN)
    }
    fn decode(bytes: &[u8]) -> Option<Command> {
        Command::decode(bytes).ok()
    }
}

/// The reference parser of direction `D`.
#[derive(Debug)]
pub struct Reference<D> {
    held: Vec<u8>,
    stats: Stats,
    direction: core::marker::PhantomData<D>,
}

impl<D: Direction> Default for Reference<D> {
    fn default() -> Self {
        Reference {
            held: Vec::new(),
            stats: Stats::default(),
            direction: core::marker::PhantomData,
        }
    }
}

impl<D: Direction> Reference<D> {
    /// Takes one byte; the frame it completes, if any (then [`poll`](Self::poll) until
    /// `None`).
    pub fn push(&mut self, byte: u8) -> Option<D::Frame> {
        self.held.push(byte);
        self.poll()
    }

    /// The next frame among the bytes held, if any.
    pub fn poll(&mut self) -> Option<D::Frame> {
        loop {
            let skip = self
                .held
                .iter()
                .position(|b| *b == START)
                .unwrap_or(self.held.len());
            self.drop_front(skip);
            let &code = self.held.get(1)?;
            let Some(need) = D::len_of(code) else {
                self.drop_front(1);
                continue;
            };
            if self.held.len() < need {
                return None;
            }
            let frame = &self.held[..need];
            let (body, tail) = frame.split_at(need - 2);
            if tail[1] != END {
                self.stats.bad_end += 1;
            } else if tail[0] != bcc(body) {
                self.stats.bad_checksum += 1;
            } else if let Some(found) = D::decode(frame) {
                self.stats.frames += 1;
                self.held.drain(..need);
                return Some(found);
            } else {
                self.stats.refused += 1;
            }
            self.drop_front(1);
        }
    }

    /// The line has been quiet: nothing that comes next completes what is held. A frame among
    /// the bytes held comes out (call again until `None`); the start of a frame cut short is
    /// dropped a byte at a time, so that a frame that began inside it is still found. At `None`
    /// nothing is held.
    #[must_use = "a frame found among the bytes held comes out here: call it until None"]
    pub fn quiet(&mut self) -> Option<D::Frame> {
        loop {
            if let Some(frame) = self.poll() {
                return Some(frame);
            }
            if self.held.is_empty() {
                return None;
            }
            self.drop_front(1);
        }
    }

    /// What it has seen.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Bytes held.
    pub fn buffered(&self) -> usize {
        self.held.len()
    }

    fn drop_front(&mut self, n: usize) {
        self.held.drain(..n);
        self.stats.discarded += u32::try_from(n).expect("a few bytes");
    }
}
