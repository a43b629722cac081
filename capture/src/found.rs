//! The frames a decode finds, each placed in its input: its JSON object (with `"offset"` and
//! `"t"`) and its line of text.

use crate::read::Capture;
use serde_json::{Value, json};

/// How frames are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Format {
    /// One JSON object per line.
    Json,
    /// One line of text per frame.
    Text,
}

/// One decoded frame and where it starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// Byte offset of its first byte in the input.
    pub offset: usize,
    /// The frame as JSON (offset and time included).
    pub json: Value,
    /// One line of text.
    pub text: String,
}

/// One side of a capture decoded: its frames and the summary of what its parser counted.
pub(crate) struct Side {
    /// The frames, in stream order.
    pub(crate) frames: Vec<Found>,
    /// What the parser counted, in words.
    pub(crate) summary: String,
}

/// The frames a parser lets out of `capture`, each placed in the input: the frame's bytes,
/// searched from where the previous frame ended up to the byte that let it out (the parsers
/// emit frames in order and never two from the same bytes).
pub(crate) struct Placed<'a> {
    capture: &'a Capture,
    search_from: usize,
    frames: Vec<Found>,
}

impl<'a> Placed<'a> {
    /// None yet.
    pub(crate) fn new(capture: &'a Capture) -> Self {
        Placed {
            capture,
            search_from: 0,
            frames: Vec::new(),
        }
    }

    /// Adds the frame whose bytes are `wire`, let out by the bytes before `upto`, described as
    /// `(json, text)`: `"offset"` (and `"t"`) added to its JSON, the offset in front of its text.
    pub(crate) fn add(&mut self, wire: &[u8], upto: usize, (mut json, text): (Value, String)) {
        let offset = self.place(wire, upto);
        if let Some(map) = json.as_object_mut() {
            map.insert("offset".into(), json!(offset));
            if let Some(t) = self.capture.time_of(offset) {
                map.insert("t".into(), json!(t));
            }
        }
        self.frames.push(Found {
            offset,
            json,
            text: format!("{offset:>8}  {text}"),
        });
    }

    /// The side: the frames placed, and `summary`.
    pub(crate) fn side(self, summary: String) -> Side {
        Side {
            frames: self.frames,
            summary,
        }
    }

    /// Where `wire` starts in the input, searched before `upto`.
    fn place(&mut self, wire: &[u8], upto: usize) -> usize {
        let bytes = &self.capture.bytes;
        let end = upto.min(bytes.len());
        let found = bytes
            .get(self.search_from..end)
            .and_then(|hay| hay.windows(wire.len()).position(|w| w == wire))
            .map(|p| p + self.search_from)
            .unwrap_or(self.search_from);
        self.search_from = found + wire.len();
        found
    }
}
