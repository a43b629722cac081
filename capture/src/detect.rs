//! Which generation a capture is of: given by the caller, or found from its frames (each side
//! by its own rule, both sides of one capture together).

use crate::generation;
use crate::read::Capture;
use chassis_protocol::detect::{Detector, Firmware};

/// How the generation of a capture was chosen, and what detection heard.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Detection {
    /// The caller gave it.
    Given(Firmware),
    /// The capture's frames decided it.
    Detected(Firmware),
    /// Nothing decided: decoded as 2020. The frames of each generation heard (both 0: no
    /// frame of either).
    NotRecognised {
        /// 2020 frames found.
        frames_2020: u32,
        /// v1.0.0 frames found (each with its BCC right).
        frames_v1: u32,
    },
    /// The two sides of a capture disagree: decoded as 2020.
    SidesDisagree {
        /// The board side's generation.
        board: Firmware,
        /// The master side's generation.
        master: Firmware,
    },
}

impl Detection {
    /// The generation the capture is decoded as.
    #[must_use]
    pub fn firmware(self) -> Firmware {
        match self {
            Detection::Given(f) | Detection::Detected(f) => f,
            Detection::NotRecognised { .. } | Detection::SidesDisagree { .. } => {
                generation::UNDECIDED
            }
        }
    }

    /// The summary's first words: `firmware v1.0.0 (detected)`, `firmware 2020 (given)`, or why
    /// the generation was not recognised.
    #[must_use]
    pub fn words(self) -> String {
        match self {
            Detection::Given(f) => format!("firmware {} (given)", f.name()),
            Detection::Detected(f) => format!("firmware {} (detected)", f.name()),
            Detection::NotRecognised {
                frames_2020: 0,
                frames_v1: 0,
            } => "firmware not recognised (no frames of either generation), decoded as 2020".into(),
            Detection::NotRecognised {
                frames_2020,
                frames_v1,
            } => format!(
                "firmware not recognised ({frames_2020} frames of 2020, {frames_v1} of v1.0.0: \
                 neither decides), decoded as 2020"
            ),
            Detection::SidesDisagree { board, master } => format!(
                "firmware not recognised (the board side's frames are {}, the master side's {}), \
                 decoded as 2020",
                board.name(),
                master.name()
            ),
        }
    }

    /// The frames of each generation heard, if nothing decided (0 and 0 otherwise).
    fn heard(self) -> (u32, u32) {
        match self {
            Detection::NotRecognised {
                frames_2020,
                frames_v1,
            } => (frames_2020, frames_v1),
            _ => (0, 0),
        }
    }
}

/// The board → master side's generation: [`Detector`] over the whole capture, told of each
/// quiet gap in its time stamps and of the quiet end.
#[must_use]
pub fn detect_downlink(capture: &Capture) -> Detection {
    let mut detector = Detector::new();
    for (i, &byte) in capture.bytes.iter().enumerate() {
        if let Some(ms) = capture.gap_before(i) {
            detector.quiet(ms);
        }
        detector.feed(&[byte]);
    }
    // The end of a capture is a quiet line.
    detector.quiet(1_000);
    let heard = detector.heard();
    match detector.verdict() {
        Some(f) => Detection::Detected(f),
        None => Detection::NotRecognised {
            frames_2020: heard.frames_2020,
            frames_v1: heard.frames_v1,
        },
    }
}

/// The master → board side's generation: the frames each generation's uplink parser finds; the
/// one with at least one and four times as many as the other decides.
#[must_use]
pub fn detect_uplink(capture: &Capture) -> Detection {
    let found = generation::all().map(|(firmware, g)| (firmware, g.uplink_frames(capture)));
    let decides = |&&(firmware, frames): &&(Firmware, u32)| {
        let others = found
            .iter()
            .filter(|(other, _)| *other != firmware)
            .fold(0u32, |sum, (_, n)| sum.saturating_add(*n));
        frames > 0 && frames >= others.saturating_mul(4)
    };
    match found.iter().find(decides) {
        Some(&(firmware, _)) => Detection::Detected(firmware),
        None => {
            let [(_, frames_2020), (_, frames_v1)] = found;
            Detection::NotRecognised {
                frames_2020,
                frames_v1,
            }
        }
    }
}

/// One generation for both sides of a capture: the one either side decides (both, if both do
/// and agree).
pub(crate) fn detect_both(board: &Capture, master: &Capture) -> Detection {
    match (detect_downlink(board), detect_uplink(master)) {
        (Detection::Detected(b), Detection::Detected(m)) if b != m => Detection::SidesDisagree {
            board: b,
            master: m,
        },
        (Detection::Detected(f), _) | (_, Detection::Detected(f)) => Detection::Detected(f),
        (b, m) => {
            let ((b20, b1), (m20, m1)) = (b.heard(), m.heard());
            Detection::NotRecognised {
                frames_2020: b20.saturating_add(m20),
                frames_v1: b1.saturating_add(m1),
            }
        }
    }
}
