//! The acceptance rules: one pure function, [`need`], whose match arms are the rows of the table
//! in the [module docs](super). Each row has its test below.

use super::Lock;

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
    /// Right after a frame found while hunting: a boundary only as sure as that frame, which
    /// may have been a false one among lookalikes (back to back in a payload, each would end
    /// where the next starts).
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
pub enum Class {
    /// Telemetry whose count is one learnt step on from its stream's last.
    Continues,
    /// Telemetry whose count is a few steps on (frames lost).
    Near,
    /// Telemetry whose count continues (or is near) its stream's, but would continue another
    /// stream's too (what a false frame in a damaged frame's tail, ending on that frame's count
    /// byte, looks like when the streams share a counter or a time tick), that starts inside
    /// a frame rejected on a boundary (where a continuing count is no evidence), or whose last
    /// two bytes are a telemetry header (its count a header's second byte). Judged so only
    /// while hunting.
    Ambiguous,
    /// Telemetry of a stream with no count known (its first frame, or after forgetting).
    First,
    /// Telemetry whose count is anything else.
    Far,
    /// The reply the master waits for (its code), with no telemetry header inside its value
    /// (`clean`) or with one (it could be a cut reply with the next frame's start in it).
    Expected {
        /// No `FF FA`..`FF FC` inside its value.
        clean: bool,
    },
    /// A reply the master is not waiting for (or a parser told nothing), or the awaited code
    /// found while hunting inside a frame rejected on a boundary.
    Unexpected,
    /// Telemetry whose count is far and whose last two bytes are a telemetry header: a frame
    /// cut short that runs into the next frame's header, its "count" the header's second byte
    /// (`FA`, `FB`, `FC` are consecutive, so two such cuts in a row look like a count moving on).
    Cut,
    /// Found while hunting (see the module docs, row 14): telemetry whose last bytes are a
    /// frame of another stream that lost or gained a byte, or, inside a frame rejected on a
    /// boundary (its own count not near), a whole one; ending on the same count byte, whose
    /// count fits that stream. Bytes that happen to hold a header, then the real frame: both
    /// cannot be real, and a whole inner one, which starts with its own header, is judged on
    /// its own when the scan reaches it. Or telemetry that is the tail of a frame of another
    /// stream that lost its first byte (its lone second header byte just before). Or telemetry
    /// starting in a reply's value whose tail, from the reply's end, is a whole frame of
    /// another stream (ending on the same count byte, which fits it). Or, inside a frame
    /// rejected on a boundary, telemetry over the header where that frame, a byte short or
    /// long, ends (the next real frame), or telemetry of its kind from its byte 2 (its tail,
    /// had it gained two bytes).
    Nested,
}

/// How a chain of frames after the candidate must vouch for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Chain {
    /// The frames right after it, adjacent, reach one whose count continues or is near its
    /// stream's (counting the candidate and the frames before it in the chain); frames of
    /// streams with no count are passed over. A quiet line right after the candidate also
    /// vouches after a quiet line (Tentative), for an expected reply, and, hunting, for a
    /// count that continues exactly ([`Class::Continues`]).
    Verify,
    /// Only the next frame vouches (a stream's first frame is passed over, a reply is not), and
    /// only if its count continues exactly, or, on a certain boundary (Locked), is near; a quiet
    /// line vouches when the candidate starts on a boundary (Locked or Tentative) and ends on
    /// the quiet.
    Exact,
    /// As `Verify`, but a far count in the chain re-bases its stream instead of failing it (a
    /// damaged count byte on a certain boundary, or a board that restarted its counts).
    Rebase,
    /// Only a later frame of the candidate's own stream, continuing the candidate's count,
    /// vouches: a stream's first frame found while hunting could be any payload's tail, and
    /// frames of other streams after it say nothing of its own count. Right after a quiet line
    /// (Tentative), a candidate that the next quiet line ends exactly (it is the whole burst)
    /// is vouched for too.
    Own,
    /// As `Own`, but always three more frames of the stream, equally spaced: a far count found
    /// while hunting (the board restarted its counts) is taken only when the line shows the
    /// new count moving in step.
    Restart,
}

/// What the candidate needs to be taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Need {
    /// Nothing more: taken on its last byte.
    Now,
    /// A header (or a quiet line) right after it.
    Follow,
    /// A chain of frames after it that vouches for it.
    Chain(Chain),
    /// Never: drop its first byte.
    Never,
}

/// The rules. `start`: how sure the parser is that the candidate starts where a frame starts
/// (Locked: right after a frame taken on good evidence, Resynced if that frame was found while
/// hunting; Tentative: right after a quiet line; Hunting: anywhere).
pub const fn need(start: Start, class: Class) -> Need {
    match (start, class) {
        // 1. Aligned, the count continues: the fast path.
        (
            Start::Locked | Start::Resynced | Start::Tentative,
            Class::Continues | Class::Ambiguous,
        ) => Need::Now,
        // 2. Aligned, the awaited reply, nothing in its value that could be a cut frame.
        (Start::Locked | Start::Resynced | Start::Tentative, Class::Expected { clean: true }) => {
            Need::Now
        }
        // 3. Aligned, the awaited reply that could hide a cut.
        (Start::Locked | Start::Resynced | Start::Tentative, Class::Expected { clean: false }) => {
            Need::Follow
        }
        // 4. On a certain boundary, frames lost or a stream's first frame: a header after it.
        (Start::Locked | Start::Resynced, Class::Near | Class::First) => Need::Follow,
        // 5. On a certain boundary (not right after a frame found while hunting), a far
        //    count: the next frames must vouch (re-basing).
        (Start::Locked, Class::Far) => Need::Chain(Chain::Rebase),
        // 6. After a quiet line, frames lost (the board paused): a header after it.
        (Start::Tentative, Class::Near) => Need::Follow,
        // 7. Right after a quiet line (a boundary, but nothing proved yet), nothing to compare
        //    the count with, or a far one: the chain must vouch, re-basing far counts.
        (Start::Tentative, Class::First | Class::Far) => Need::Chain(Chain::Rebase),
        // 8. Hunting, a plausible count: the next frames must vouch (a count that continues
        //    exactly: or the quiet line right after it).
        (Start::Hunting, Class::Continues | Class::Near) => Need::Chain(Chain::Verify),
        // 9. Hunting, a stream's first frame, a count another stream's could explain, any
        //    count inside a frame rejected on a boundary, or a count that is a header's second
        //    byte: its own stream's next frame must continue it.
        (Start::Hunting, Class::First | Class::Ambiguous) => Need::Chain(Chain::Own),
        // 10. Hunting, the awaited reply (not inside a frame rejected on a boundary): the next
        //     frames (or the quiet line) must vouch, and hold no other reply with its code.
        (Start::Hunting, Class::Expected { .. }) => Need::Chain(Chain::Verify),
        // 11. A reply nobody waits for, on a boundary: the very next frame must continue its
        //     count exactly (Locked: or, past a damaged next frame, the frame after it).
        (Start::Locked | Start::Resynced | Start::Tentative, Class::Unexpected) => {
            Need::Chain(Chain::Exact)
        }
        // 12. A reply nobody waits for (or the awaited code inside a frame rejected on a
        //     boundary), hunting: never (the tail of a damaged frame, `23` and a code in its
        //     payload, ends right where the next real frame starts).
        (Start::Hunting, Class::Unexpected) => Need::Never,
        // 13. Hunting, or right after a frame found while hunting, a far count: its own
        //     stream's next three frames must move on from it in step (a board that restarted
        //     its counts).
        (Start::Hunting | Start::Resynced, Class::Far) => Need::Chain(Chain::Restart),
        // 14. Hunting, a frame of another stream that lost or gained a byte (or, inside a
        //     frame rejected on a boundary, a whole one) fills the candidate's tail, its count
        //     fitting; or the candidate is the tail of a frame that lost its first byte; or it
        //     starts in a reply's value and a whole frame fills it from the reply's end: never
        //     (a whole inner frame: the scan reaches it next). Only ever found while hunting.
        (_, Class::Nested) => Need::Never,
        // 15. A far count that is a header's second byte (the frame ends with a header): never.
        (_, Class::Cut) => Need::Never,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Start::{Hunting, Locked, Resynced, Tentative};

    #[test]
    fn row1_aligned_and_continuing_is_taken_at_once() {
        for lock in [Locked, Resynced, Tentative] {
            assert_eq!(need(lock, Class::Continues), Need::Now);
            assert_eq!(need(lock, Class::Ambiguous), Need::Now);
        }
    }

    #[test]
    fn row2_the_awaited_reply_on_a_boundary_is_taken_at_once() {
        assert_eq!(need(Locked, Class::Expected { clean: true }), Need::Now);
        assert_eq!(need(Tentative, Class::Expected { clean: true }), Need::Now);
    }

    #[test]
    fn row3_an_awaited_reply_that_could_hide_a_cut_waits_for_a_header() {
        assert_eq!(need(Locked, Class::Expected { clean: false }), Need::Follow);
        assert_eq!(
            need(Tentative, Class::Expected { clean: false }),
            Need::Follow
        );
    }

    #[test]
    fn row4_lost_frames_or_a_first_frame_on_a_boundary_wait_for_a_header() {
        for lock in [Locked, Resynced] {
            assert_eq!(need(lock, Class::Near), Need::Follow);
            assert_eq!(need(lock, Class::First), Need::Follow);
        }
    }

    #[test]
    fn row5_a_far_count_on_a_boundary_needs_the_chain_to_rebase() {
        assert_eq!(need(Locked, Class::Far), Need::Chain(Chain::Rebase));
    }

    #[test]
    fn row6_frames_lost_over_a_quiet_line_wait_for_a_header() {
        assert_eq!(need(Tentative, Class::Near), Need::Follow);
    }

    #[test]
    fn row7_after_a_quiet_line_no_count_to_go_by_needs_the_chain() {
        assert_eq!(need(Tentative, Class::First), Need::Chain(Chain::Rebase));
        assert_eq!(need(Tentative, Class::Far), Need::Chain(Chain::Rebase));
    }

    #[test]
    fn row8_hunting_a_plausible_count_needs_the_chain() {
        for class in [Class::Continues, Class::Near] {
            assert_eq!(need(Hunting, class), Need::Chain(Chain::Verify));
        }
    }

    #[test]
    fn row9_hunting_a_first_frame_or_an_ambiguous_count_needs_its_own_stream() {
        assert_eq!(need(Hunting, Class::First), Need::Chain(Chain::Own));
        assert_eq!(need(Hunting, Class::Ambiguous), Need::Chain(Chain::Own));
    }

    #[test]
    fn row10_hunting_the_awaited_reply_needs_the_chain_or_the_quiet() {
        assert_eq!(
            need(Hunting, Class::Expected { clean: true }),
            Need::Chain(Chain::Verify)
        );
    }

    #[test]
    fn row11_a_reply_nobody_waits_for_on_a_boundary_needs_an_exact_count_after_it() {
        for lock in [Tentative, Locked, Resynced] {
            assert_eq!(need(lock, Class::Unexpected), Need::Chain(Chain::Exact));
        }
    }

    #[test]
    fn row12_hunting_never_takes_a_reply_nobody_waits_for() {
        assert_eq!(need(Hunting, Class::Unexpected), Need::Never);
    }

    #[test]
    fn row14_a_frame_whose_tail_is_another_streams_frame_inside_a_rejected_one_is_never_taken() {
        assert_eq!(need(Hunting, Class::Nested), Need::Never);
    }

    #[test]
    fn row15_a_far_count_that_is_the_next_headers_second_byte_is_never_taken() {
        for lock in [Hunting, Tentative, Locked, Resynced] {
            assert_eq!(need(lock, Class::Cut), Need::Never);
        }
    }

    #[test]
    fn row13_hunting_or_right_after_a_frame_found_hunting_a_far_count_needs_its_stream_in_step() {
        assert_eq!(need(Hunting, Class::Far), Need::Chain(Chain::Restart));
        assert_eq!(need(Resynced, Class::Far), Need::Chain(Chain::Restart));
    }
}
