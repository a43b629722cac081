//! The acceptance table: every decision about a whole candidate is a row of [`decide`], read
//! top to bottom, the first that holds deciding. The facts it reads are gathered elsewhere
//! ([`Facts`], in `class.rs`) and decide nothing on their own. Each row has its test below;
//! the table with the reasons is `docs/parser-2020.md`.

use super::counts::Rel;
use super::{Lock, MAX_GAP};

/// Where the candidate starts, as the rules tell places apart: the parser's [`Lock`], with
/// Locked split by how the frame before the candidate was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// Alignment unknown: anywhere.
    Hunting,
    /// Right after a quiet line.
    Tentative,
    /// Right after a frame taken on a boundary.
    Locked,
    /// Right after a frame found while hunting: a boundary only as sure as that frame.
    Resynced,
}

impl From<Lock> for Start {
    fn from(lock: Lock) -> Self {
        match lock {
            Lock::Hunting => Start::Hunting,
            Lock::Tentative => Start::Tentative,
            Lock::Locked => Start::Locked,
        }
    }
}

/// What a whole candidate is, before anything after it is looked at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Seen {
    /// Telemetry, and how its count relates to its stream's ([`Rel`]).
    Telemetry(Rel),
    /// A reply: whether the master awaits its code, and whether its value holds no telemetry
    /// header (`clean`: it cannot be a cut reply with the next frame's start in it).
    Reply {
        /// The master awaits this code.
        awaited: bool,
        /// No `FF FA`..`FF FC` inside its value.
        clean: bool,
    },
}

/// The facts the table reads about a candidate. The suspicions are looked for only where a
/// row reads them (while hunting, at the window's front).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Facts {
    /// What it is.
    pub seen: Seen,
    /// It starts inside a frame rejected on a boundary: there, a continuing count and the
    /// awaited code are no evidence (a damaged frame's payload ends where the next starts).
    /// For a reply found hunting, also: it may be the tail of a telemetry frame whose start was
    /// lost or damaged (it and the bytes thrown away before it fit in one, and the next frame,
    /// of that stream, continues from its last byte read as a count).
    pub shadow: bool,
    /// Its count would continue (or be near) another stream's too.
    pub other_fits: bool,
    /// Its last two bytes are a telemetry header: its count byte is a header's second byte.
    pub cut: bool,
    /// Its bytes hold a real frame it cannot be (a frame of another stream, damaged or
    /// whole, ending on its count byte; the tail of a frame that lost its first byte; a frame
    /// starting in a reply's value; the header where a rejected frame ends): row 14.
    pub nested: bool,
}

/// How a chain of frames after the candidate counts: which links vouch, which fail it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Chain {
    /// The frames right after it reach one whose count continues or is near its stream's
    /// (counting the candidate and the frames before it); streams with no count pass it on; a
    /// far count fails it.
    Verify,
    /// Only the next frame, continuing exactly (on a certain boundary: or near); a stream's
    /// first frame is passed over, a reply is not; past a damaged next frame, the one after.
    Exact,
    /// As `Verify`, but a far count re-bases its stream instead of failing.
    Rebase,
    /// Only a later frame of the candidate's own stream continuing it vouches.
    Own,
    /// As `Own`, but three more frames of the stream, equally spaced (a board that restarted
    /// its counts).
    Restart,
}

/// A chain and what else may vouch for the candidate while it is walked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Walk {
    /// How the links count.
    pub chain: Chain,
    /// A quiet line right after the candidate vouches for it.
    pub quiet: bool,
    /// Junk bytes allowed before the chain's first frame.
    pub gap: usize,
    /// The master asked once: a chain holding another reply with the awaited code fails.
    pub once: bool,
}

impl Walk {
    /// A chain with nothing else vouching.
    pub const fn only(chain: Chain) -> Walk {
        Walk {
            chain,
            quiet: false,
            gap: 0,
            once: false,
        }
    }

    /// A chain, or the quiet line right after the candidate.
    const fn or_quiet(chain: Chain) -> Walk {
        Walk {
            quiet: true,
            ..Walk::only(chain)
        }
    }
}

/// What the candidate needs to be taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Need {
    /// Nothing more: taken on its last byte.
    Now,
    /// A header (or a quiet line) right after it.
    Follow,
    /// The quiet line right after it, and nothing else.
    Quiet,
    /// A chain of frames after it that vouches for it.
    Chain(Walk),
    /// Never: drop its first byte.
    Never,
}

/// What the rows ask: a chain re-basing far counts, or the quiet line right after it.
const REBASE: Need = Need::Chain(Walk::or_quiet(Chain::Rebase));
/// Its own stream's next three frames, in step.
const RESTART: Need = Need::Chain(Walk::only(Chain::Restart));
/// Its own stream's next frame.
const OWN: Need = Need::Chain(Walk::only(Chain::Own));
/// A chain, up to two junk bytes before it, or the quiet line right after it.
const VERIFY_CONTINUING: Need = Need::Chain(Walk {
    gap: MAX_GAP,
    ..Walk::or_quiet(Chain::Verify)
});
/// A chain.
const VERIFY: Need = Need::Chain(Walk::only(Chain::Verify));
/// The next frame's count, exactly, or the quiet line right after it.
const EXACT: Need = Need::Chain(Walk::or_quiet(Chain::Exact));
/// A chain or the quiet line, holding no other reply with the awaited code.
const VERIFY_ONCE: Need = Need::Chain(Walk {
    once: true,
    ..Walk::or_quiet(Chain::Verify)
});

/// The table: the row that decides, and what the candidate needs. One principle: **a frame
/// is taken on evidence that does not rest on the bytes it could be hiding in** (its place,
/// its count against the line's, what follows it), and the less sure its place, the more of
/// what follows must vouch.
pub const fn decide(start: Start, f: Facts) -> (u8, Need) {
    use Need::{Follow, Never, Now, Quiet};
    use Rel::{Continues, Far, Near, Unknown};
    use Start::{Hunting, Locked, Resynced, Tentative};
    let hunting = matches!(start, Hunting);
    let certain = matches!(start, Locked | Resynced);
    match f.seen {
        // 14. Hunting, its bytes hold a real frame it cannot be (the scan reaches that next).
        Seen::Telemetry(_) if hunting && f.nested => (14, Never),
        // 15. A far count that is a header's second byte: a cut frame running into the next,
        //     unless, on a boundary not found hunting, the line goes quiet right after it (a
        //     cut frame would have the rest of the next frame after it, not the quiet).
        Seen::Telemetry(Far) if f.cut && matches!(start, Locked | Tentative) => (15, Quiet),
        Seen::Telemetry(Far) if f.cut => (15, Never),
        //     Hunting, with no count to go by, the same: nothing tells that byte from a
        //     payload's `FF FA`..`FF FC` (a lookalike ending there while the line's counter
        //     passes that value has the real frames after it in step from it).
        Seen::Telemetry(Unknown) if f.cut && hunting => (15, Never),
        // 1. On a boundary, the count continues: taken on its last byte.
        Seen::Telemetry(Continues) if !hunting => (1, Now),
        // 4. On a certain boundary, frames lost or the stream's first: a header after it.
        Seen::Telemetry(Near | Unknown) if certain => (4, Follow),
        // 5. On a certain boundary (not found while hunting), a far count.
        Seen::Telemetry(Far) if matches!(start, Locked) => (5, REBASE),
        // 6. After a quiet line, frames lost (the board paused): a header after it.
        Seen::Telemetry(Near) if matches!(start, Tentative) => (6, Follow),
        // 7. After a quiet line, no count to go by or a far one.
        Seen::Telemetry(Unknown | Far) if matches!(start, Tentative) => (7, REBASE),
        // 13. Hunting or Resynced, a far count: a board that restarted its counts, or not.
        Seen::Telemetry(Far) => (13, RESTART),
        // 9. Hunting, the stream's first, or a count that proves nothing (inside a rejected
        //    frame, another stream's too, a header's second byte).
        Seen::Telemetry(Unknown) => (9, OWN),
        Seen::Telemetry(_) if f.shadow || f.other_fits || f.cut => (9, OWN),
        // 8. Hunting, the count continues, or frames lost.
        Seen::Telemetry(Continues) => (8, VERIFY_CONTINUING),
        Seen::Telemetry(Near) => (8, VERIFY),
        // 2. On a boundary, the awaited reply, nothing in its value that could be a cut frame.
        Seen::Reply {
            awaited: true,
            clean: true,
        } if !hunting => (2, Now),
        // 3. On a boundary, the awaited reply that could hide a cut: a header after it.
        Seen::Reply { awaited: true, .. } if !hunting => (3, Follow),
        // 11. On a boundary, a reply nobody awaits.
        Seen::Reply { awaited: false, .. } if !hunting => (11, EXACT),
        // 10. Hunting, the awaited reply, not inside a rejected frame or a frame's tail.
        Seen::Reply { awaited: true, .. } if !f.shadow => (10, VERIFY_ONCE),
        // 12. Hunting, any other reply (`23` and a code in a damaged frame's payload ends
        //     where the next frame starts).
        Seen::Reply { .. } => (12, Never),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Rel::{Continues, Far, Near, Unknown};
    use Start::{Hunting, Locked, Resynced, Tentative};

    const ALIGNED: [Start; 3] = [Locked, Resynced, Tentative];

    fn telemetry(rel: Rel) -> Facts {
        Facts {
            seen: Seen::Telemetry(rel),
            shadow: false,
            other_fits: false,
            cut: false,
            nested: false,
        }
    }

    fn reply(awaited: bool, clean: bool) -> Facts {
        Facts {
            seen: Seen::Reply { awaited, clean },
            ..telemetry(Unknown)
        }
    }

    fn row(start: Start, facts: Facts) -> u8 {
        decide(start, facts).0
    }

    #[test]
    fn row1_aligned_and_continuing_is_taken_at_once() {
        for start in ALIGNED {
            assert_eq!(decide(start, telemetry(Continues)), (1, Need::Now));
            // What only hunting reads changes nothing on a boundary.
            let suspect = Facts {
                shadow: true,
                other_fits: true,
                cut: true,
                nested: true,
                ..telemetry(Continues)
            };
            assert_eq!(row(start, suspect), 1);
        }
    }

    #[test]
    fn row2_the_awaited_reply_on_a_boundary_is_taken_at_once() {
        for start in ALIGNED {
            assert_eq!(decide(start, reply(true, true)), (2, Need::Now));
        }
    }

    #[test]
    fn row3_an_awaited_reply_that_could_hide_a_cut_waits_for_a_header() {
        for start in ALIGNED {
            assert_eq!(decide(start, reply(true, false)), (3, Need::Follow));
        }
    }

    #[test]
    fn row4_lost_frames_or_a_first_frame_on_a_boundary_wait_for_a_header() {
        for start in [Locked, Resynced] {
            assert_eq!(decide(start, telemetry(Near)), (4, Need::Follow));
            assert_eq!(decide(start, telemetry(Unknown)), (4, Need::Follow));
        }
    }

    #[test]
    fn row5_a_far_count_on_a_boundary_needs_the_chain_to_rebase() {
        let need = Need::Chain(Walk::or_quiet(Chain::Rebase));
        assert_eq!(decide(Locked, telemetry(Far)), (5, need));
    }

    #[test]
    fn row6_frames_lost_over_a_quiet_line_wait_for_a_header() {
        assert_eq!(decide(Tentative, telemetry(Near)), (6, Need::Follow));
    }

    #[test]
    fn row7_after_a_quiet_line_no_count_to_go_by_needs_the_chain() {
        let need = Need::Chain(Walk::or_quiet(Chain::Rebase));
        assert_eq!(decide(Tentative, telemetry(Unknown)), (7, need));
        assert_eq!(decide(Tentative, telemetry(Far)), (7, need));
    }

    #[test]
    fn row8_hunting_a_plausible_count_needs_the_chain() {
        let continues = Walk {
            gap: MAX_GAP,
            ..Walk::or_quiet(Chain::Verify)
        };
        assert_eq!(
            decide(Hunting, telemetry(Continues)),
            (8, Need::Chain(continues))
        );
        let near = Need::Chain(Walk::only(Chain::Verify));
        assert_eq!(decide(Hunting, telemetry(Near)), (8, near));
    }

    #[test]
    fn row9_hunting_a_first_frame_or_a_count_that_proves_nothing_needs_its_own_stream() {
        let own = Need::Chain(Walk::only(Chain::Own));
        assert_eq!(decide(Hunting, telemetry(Unknown)), (9, own));
        for rel in [Continues, Near] {
            let shadow = Facts {
                shadow: true,
                ..telemetry(rel)
            };
            let other = Facts {
                other_fits: true,
                ..telemetry(rel)
            };
            let cut = Facts {
                cut: true,
                ..telemetry(rel)
            };
            for facts in [shadow, other, cut] {
                assert_eq!(decide(Hunting, facts), (9, own));
            }
        }
    }

    #[test]
    fn row10_hunting_the_awaited_reply_needs_the_chain_or_the_quiet() {
        let need = Need::Chain(Walk {
            once: true,
            ..Walk::or_quiet(Chain::Verify)
        });
        assert_eq!(decide(Hunting, reply(true, true)), (10, need));
        assert_eq!(decide(Hunting, reply(true, false)), (10, need));
    }

    #[test]
    fn row11_a_reply_nobody_waits_for_on_a_boundary_needs_an_exact_count_after_it() {
        for start in ALIGNED {
            let need = Need::Chain(Walk::or_quiet(Chain::Exact));
            assert_eq!(decide(start, reply(false, true)), (11, need));
        }
    }

    #[test]
    fn row12_hunting_never_takes_a_reply_nobody_waits_for() {
        assert_eq!(decide(Hunting, reply(false, true)), (12, Need::Never));
        let in_shadow = Facts {
            shadow: true,
            ..reply(true, true)
        };
        assert_eq!(decide(Hunting, in_shadow), (12, Need::Never));
    }

    #[test]
    fn row13_hunting_or_right_after_a_frame_found_hunting_a_far_count_needs_its_stream_in_step() {
        let need = Need::Chain(Walk::only(Chain::Restart));
        assert_eq!(decide(Hunting, telemetry(Far)), (13, need));
        assert_eq!(decide(Resynced, telemetry(Far)), (13, need));
    }

    #[test]
    fn row14_a_frame_holding_a_real_frame_it_cannot_be_is_never_taken_while_hunting() {
        for rel in [Continues, Near, Unknown, Far] {
            let nested = Facts {
                nested: true,
                ..telemetry(rel)
            };
            assert_eq!(decide(Hunting, nested), (14, Need::Never));
        }
    }

    #[test]
    fn row15_a_far_count_that_is_the_next_headers_second_byte_needs_the_quiet_line() {
        let cut = Facts {
            cut: true,
            ..telemetry(Far)
        };
        for start in [Hunting, Resynced] {
            assert_eq!(decide(start, cut), (15, Need::Never));
        }
        for start in [Tentative, Locked] {
            assert_eq!(decide(start, cut), (15, Need::Quiet));
        }
        // Hunting, a stream's first frame whose count byte is a header's second: never; on a
        // certain boundary or after a quiet line, as any stream's first.
        let first = Facts {
            cut: true,
            ..telemetry(Unknown)
        };
        assert_eq!(decide(Hunting, first), (15, Need::Never));
        assert_eq!(row(Resynced, first), 4);
        assert_eq!(row(Locked, first), 4);
        assert_eq!(row(Tentative, first), 7);
    }
}
