//! Small versions of the noise sweep's stream models never tuned on (`chassis_host_tests::models`:
//! payloads of header bytes only, shared counters, the line delivered in USB packets) and of the
//! cold start (the `cold-start` binary), with the bounds today's parser meets with margin, so a
//! future parser cannot regress on them silently. The figures today (seed 99, 3 000 frames a
//! row) are in each test's comments.

use chassis_host_tests::cold::{Chunking, Model, cold_start};
use chassis_host_tests::models::{DELIVERIES, Delivery, PAYLOADS, run_model};
use chassis_host_tests::usb::Host;
use chassis_host_tests::{CountModel, Payload, Score};

/// The seed of every stream here (none of the sweep's figure seeds).
const SEED: u64 = 99;

/// Frames per row.
const FRAMES: usize = 3_000;

/// Count models every row runs under: those of the sweep, and shared counters stepping by 3,
/// 6 and 7 (steps wider than a stream's first step may be: the frames in step vouch).
fn count_models() -> Vec<(String, CountModel)> {
    let mut models: Vec<(String, CountModel)> = CountModel::ALL
        .iter()
        .map(|(name, model)| (name.to_string(), *model))
        .collect();
    models.push(("shared +3".to_string(), CountModel::SharedStep(3)));
    models.push(("shared +6".to_string(), CountModel::SharedStep(6)));
    models.push(("shared +7".to_string(), CountModel::SharedStep(7)));
    models
}

/// Every payload, count model and delivery through mixed errors at `rate`: (row, delivery,
/// score).
fn rows(rate: f64) -> Vec<(String, Delivery, Score)> {
    let deliveries: Vec<Delivery> = DELIVERIES.iter().map(|(_, d)| *d).collect();
    let mut out = Vec::new();
    for (payload_name, payload) in PAYLOADS {
        for (count_name, counts) in count_models() {
            let scores = run_model(SEED, FRAMES, (payload, counts), &deliveries, &[rate]);
            for ((delivery_name, delivery), row) in DELIVERIES.iter().zip(scores) {
                let name = format!("{payload_name} / {count_name} / {delivery_name}");
                out.extend(
                    row.into_iter()
                        .map(|score| (name.clone(), *delivery, score)),
                );
            }
        }
    }
    out
}

/// Checks every row of a host that reports quiet only from the line's timing against the
/// lowest recall and the most false frames per row, and all rows' false frames per million.
fn check_good_hosts(rate: f64, min_recall: f64, max_false: usize, max_false_per_million: f64) {
    let mut all = Score::default();
    for (name, delivery, s) in rows(rate) {
        if matches!(delivery, Delivery::Usb(_, Host::IdleEveryPacket)) {
            continue;
        }
        assert!(s.recall() >= min_recall, "{name} at {rate:e}: {s:?}");
        assert!(s.false_frames <= max_false, "{name} at {rate:e}: {s:?}");
        all.add(&s);
    }
    let per_million = all.false_per_million();
    assert!(
        per_million <= max_false_per_million,
        "{per_million} at {rate:e}"
    );
}

#[test]
fn on_a_clean_line_every_good_host_gets_every_frame_but_the_first_and_nothing_false() {
    // Today: lowest recall 99.967 % (the first frame, with the quiet reported), 0 false.
    check_good_hosts(0.0, 0.999, 0, 0.0);
}

#[test]
fn at_1e_3_errors_header_bytes_shared_counters_and_usb_packets_hold_their_bounds() {
    // Today: lowest recall 99.797 % (USB 1 ms), 0 false frames in every row.
    check_good_hosts(1e-3, 0.995, 1, 50.0);
}

#[test]
fn at_1e_2_errors_header_bytes_shared_counters_and_usb_packets_hold_their_bounds() {
    // Today: lowest recall 97.703 % (header bytes, bytes without the quiet), at most 1 false
    // frame in a row.
    check_good_hosts(1e-2, 0.97, 2, 150.0);
}

#[test]
fn a_host_that_reports_idle_after_every_usb_packet_loses_frames_not_truth() {
    // Today such a host gets 1.3–1.7 % of the frames through an adapter that sends every
    // 1 ms (nearly every frame spans two packets, and idle() throws the first half away), and
    // 76–79 % through one with a 16 ms latency timer; a few false frames per row (at most 3).
    // No bound on recall: a parser that did better would be welcome. False frames stay rare.
    for rate in [0.0, 1e-3] {
        let mut all = Score::default();
        for (name, delivery, s) in rows(rate) {
            if matches!(delivery, Delivery::Usb(_, Host::IdleEveryPacket)) {
                assert!(s.false_frames <= 6, "{name} at {rate:e}: {s:?}");
                all.add(&s);
            }
        }
        assert!(all.false_per_million() <= 500.0, "{all:?}");
    }
}

/// The worst start's frames missed and the false frames of every offset 0..200 of a stream of
/// 300 frames (payloads at rest), every chunking, the quiet line reported or not.
fn cold(counts: CountModel, quiet: bool) -> (usize, usize) {
    let model = Model {
        seed: SEED,
        payload: Payload::Rest,
        counts,
        frames: 300,
    };
    let mut worst = (0, 0);
    for (_, chunking) in Chunking::ALL {
        let c = cold_start(model, 0..200, quiet, chunking);
        worst = (worst.0.max(c.worst.0), worst.1 + c.false_frames);
    }
    worst
}

#[test]
fn a_cold_start_misses_no_more_frames_than_today_and_emits_none_false() {
    for (name, counts) in count_models() {
        // Counts per stream or a tick miss at most the first whole frame without the quiet
        // line, a shared counter at any step at most 2 on this seed (a first IMU frame whose
        // tail reads as a whole frame of another stream, or that the line's first encoder frame
        // follows straight, is not vouched for by the shared steps: 4 at one start on seed
        // 424 242); 2 with the quiet line (at offset 45: a first burst that the quiet line ends).
        let shared = matches!(counts, CountModel::Shared | CountModel::SharedStep(_));
        for (quiet, ceiling) in [(false, if shared { 2 } else { 1 }), (true, 2)] {
            let (missed, false_frames) = cold(counts, quiet);
            assert!(missed <= ceiling, "{name}, quiet {quiet}: {missed} missed");
            assert_eq!(false_frames, 0, "{name}, quiet {quiet}");
        }
    }
}

#[test]
fn a_cold_start_on_payloads_written_to_fool_it_emits_no_false_frame() {
    // One byte at a time, every start 0..200 of 300 frames, the quiet line reported or not: the
    // sweep's adversarial payloads, payloads of header bytes only, and payloads whose every
    // value reads -6..-4 (under a shared counter whose counts pass `FA`..`FC` the last still
    // makes some at a few starts: `cold-start`'s last table, docs/parser.md). Frames missed at
    // the worst start today: 1 under counts per stream or a tick, 2 to 4 under a shared counter
    // (the quiet reported: 2).
    for payload in [Payload::Adversarial, Payload::Headers, Payload::Lookalikes] {
        for (name, counts) in count_models() {
            let shared = matches!(counts, CountModel::Shared | CountModel::SharedStep(_));
            for quiet in [false, true] {
                let model = Model {
                    seed: SEED,
                    payload,
                    counts,
                    frames: 300,
                };
                let c = cold_start(model, 0..200, quiet, Chunking::Bytes);
                assert_eq!(c.false_frames, 0, "{payload:?}, {name}, quiet {quiet}");
                let ceiling = if shared && !quiet { 4 } else { 2 };
                assert!(
                    c.worst.0 <= ceiling,
                    "{payload:?}, {name}, quiet {quiet}: {} missed",
                    c.worst.0
                );
            }
        }
    }
}

#[test]
fn a_cold_start_on_lookalikes_whose_shared_counter_passes_their_header_bytes_emits_no_false_frame()
{
    // Payloads whose every value reads -6..-4, under one counter shared by all streams stepping
    // by 2 or 3: on these streams the counter passes `FA`..`FC`, so an IMU lookalike hiding in
    // the payloads ends on a byte equal to the line's count, and the real frames after it are
    // in step from there (each was a start with false frames: seed 7051, +3, starts 1 to 23;
    // 7215, +3, 83 to 120; 2141, +2, 143). Found while hunting, with no count to go by, a
    // candidate whose count byte is a header's second is never taken (row 15).
    for (seed, step) in [(7051, 3), (7215, 3), (2141, 2)] {
        let model = Model {
            seed,
            payload: Payload::Lookalikes,
            counts: CountModel::SharedStep(step),
            frames: 60,
        };
        for quiet in [false, true] {
            let c = cold_start(model, 0..200, quiet, Chunking::Bytes);
            assert_eq!(
                (c.starts_false, c.false_frames),
                (0, 0),
                "seed {seed}, +{step}, quiet {quiet}"
            );
        }
    }
}

#[test]
#[ignore = "the parser misses 1 or 2 frames at some cold starts under every count model: the first whole frame, or a first burst that the quiet line ends, before any count has been seen to continue (a frame of a stream not yet seen, or a reply nobody awaits, found while hunting, can be any payload's tail)"]
fn a_cold_start_is_exact_from_the_first_whole_frame_under_every_shared_counter() {
    for step in 1..=7 {
        for quiet in [false, true] {
            let (missed, false_frames) = cold(CountModel::SharedStep(step), quiet);
            assert_eq!((missed, false_frames), (0, 0), "+{step}, quiet {quiet}");
        }
    }
}
