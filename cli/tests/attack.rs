//! The standing attack on every way a command ends: every command that moves or watches the
//! chassis, on both firmware generations, ended by SIGINT, SIGTERM and SIGHUP, by its terminal
//! closing under it (no SIGHUP: the command is not the session's leader) and by its standard
//! input ending, each at 20 moments from 0 to 2 s after it started (the first ones fall while
//! it is still finding the board's firmware). After each run, from what the simulated board
//! received: if anything moved the chassis, the stop went out after it and nothing moved it
//! after (2020: the stop frame, a turn cancelled; v1.0.0: the forced stop); the process ended
//! within [`EXIT_BOUND`] of the ending, with the ending's exit status and a message that says
//! what happened. A command that had ended, or was failing, on its own before the ending came (a
//! check whose simulated board a loaded machine starved: the board's serving loop stood still
//! for 100 ms or more before the ending) is judged on the chassis alone, and counted apart. The table (command × ending: runs, moved, stopped, exit statuses, the worst
//! time to stop and to exit, at which moment) is printed, and written to
//! `target/attack-table.md`; every run's row to `target/attack-runs.md`.

mod harness;

use chassis_protocol::sim::Motion;
use chassis_protocol::{Command, UplinkParser};
use harness::TestBoard;
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::process::{Child, Command as Process, Stdio};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How long after the ending the process must have ended: the stop's own confirmation (a turn's
/// cancellation reads the pending angle) and the firmware detection it may be in.
const EXIT_BOUND: Duration = Duration::from_secs(3);

/// Runs at once (each a command, a simulated board and a pseudo-terminal or two; a run mostly
/// waits for its moment: four at a time kept a quarter of a 2-core machine busy).
const PARALLEL: usize = 8;

/// How long a process may take to reach `main` on a loaded machine: a signal within it may end
/// the process by itself, before it did anything (then nothing may have been sent; that the
/// handlers are in place from `main`'s first instruction is `endings.rs`'s
/// `a_sigint_in_the_first_moments_is_honoured_even_when_inherited_as_ignored`).
const STARTUP_MS: u64 = 210;

/// Moments of the ending after the start, ms.
fn moments() -> Vec<u64> {
    (0..20).map(|i| i * 2_000 / 19).collect()
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Generation {
    V2020,
    V1,
}

/// A command under attack.
#[derive(Clone, Copy, Debug)]
struct Case {
    /// Its name in the table.
    name: &'static str,
    generation: Generation,
    /// Its arguments (`{out}`: a capture file of its own).
    args: &'static [&'static str],
    /// `monitor --drive`: the key `w` is pressed once the link is up.
    key: bool,
    /// `record`: an ending is how it ends (exit status 0, the file complete).
    records: bool,
    /// `monitor`: refuses to start without a terminal.
    needs_terminal: bool,
}

const CASES: [Case; 11] = [
    case(
        "drive",
        Generation::V2020,
        &["drive", "--y", "300", "--for", "4"],
    ),
    case("turn", Generation::V2020, &["turn", "360"]),
    Case {
        key: true,
        needs_terminal: true,
        ..case(
            "monitor --drive",
            Generation::V2020,
            &["monitor", "--drive"],
        )
    },
    Case {
        needs_terminal: true,
        ..case("monitor", Generation::V2020, &["monitor"])
    },
    case("check", Generation::V2020, &["check", "--yes"]),
    Case {
        records: true,
        ..case("record", Generation::V2020, &["record", "--out", "{out}"])
    },
    case(
        "drive",
        Generation::V1,
        &["drive", "--vy", "0.3", "--for", "4"],
    ),
    Case {
        key: true,
        needs_terminal: true,
        ..case("monitor --drive", Generation::V1, &["monitor", "--drive"])
    },
    Case {
        needs_terminal: true,
        ..case("monitor", Generation::V1, &["monitor"])
    },
    case("check", Generation::V1, &["check", "--yes"]),
    Case {
        records: true,
        ..case("record", Generation::V1, &["record", "--out", "{out}"])
    },
];

const fn case(name: &'static str, generation: Generation, args: &'static [&'static str]) -> Case {
    Case {
        name,
        generation,
        args,
        key: false,
        records: false,
        needs_terminal: false,
    }
}

/// How a run ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Ending {
    Signal(&'static str, i32),
    TerminalClosed,
    InputEnded,
}

const ENDINGS: [Ending; 5] = [
    Ending::Signal("INT", 2),
    Ending::Signal("TERM", 15),
    Ending::Signal("HUP", 1),
    Ending::TerminalClosed,
    Ending::InputEnded,
];

impl Ending {
    fn name(self) -> String {
        match self {
            Ending::Signal(name, _) => format!("SIG{name}"),
            Ending::TerminalClosed => "terminal closed".into(),
            Ending::InputEnded => "stdin ended".into(),
        }
    }
}

/// What one run came to.
#[derive(Clone, Debug)]
struct Outcome {
    case: usize,
    ending: Ending,
    moment_ms: u64,
    /// Something moved the chassis.
    moved: bool,
    /// The chassis ended stopped (what the board was last told, and no turn left).
    stopped: bool,
    /// The exit status: "130", or "sig 2" for a process the signal itself ended.
    exit: String,
    /// From the ending to the last stop frame's arrival, ms (0: it was stopped before).
    to_stop_ms: Option<u64>,
    /// From the ending to the process's end, ms.
    to_exit_ms: u64,
    /// The command had ended by itself before the ending came (a check failed, on a machine so
    /// loaded that the simulated board starved): the ending is not what it answered.
    ended_first: bool,
    /// What is wrong, if anything.
    problem: Option<String>,
}

/// The board under attack, of either generation.
enum Board {
    V2020(TestBoard),
    V1(TestBoard<chassis_protocol::sim::v1::Board>),
}

impl Board {
    fn start(generation: Generation) -> Board {
        match generation {
            Generation::V2020 => Board::V2020(TestBoard::start()),
            Generation::V1 => Board::V1(TestBoard::serving(chassis_protocol::sim::v1::Board::new(
                chassis_protocol::sim::v1::SimConfig::default(),
            ))),
        }
    }

    fn path(&self) -> String {
        match self {
            Board::V2020(b) => b.path.clone(),
            Board::V1(b) => b.path.clone(),
        }
    }

    fn heard(&self) -> Vec<u8> {
        match self {
            Board::V2020(b) => b.heard(),
            Board::V1(b) => b.heard(),
        }
    }

    fn stalled_before(&self, at: Instant) -> bool {
        match self {
            Board::V2020(b) => b.stalled_before(at),
            Board::V1(b) => b.stalled_before(at),
        }
    }

    fn heard_by(&self, len: usize) -> Option<Instant> {
        match self {
            Board::V2020(b) => b.heard_by(len),
            Board::V1(b) => b.heard_by(len),
        }
    }

    /// Stops serving: whether anything moved the chassis, and whether it ended stopped.
    fn finish(self) -> Verdict {
        match self {
            Board::V2020(b) => {
                let (board, heard) = b.finish();
                let frames = frames_2020(&heard);
                let moved = frames.iter().any(|(c, _)| harness::moves(c));
                let stop = frames
                    .iter()
                    .rposition(|(c, _)| *c == Command::Velocity(chassis_protocol::Velocity::STOP));
                let after_stop = stop.map_or(&frames[..], |i| &frames[i + 1..]);
                let driven_after = after_stop.iter().any(|(c, _)| {
                    matches!(c, Command::Velocity(_) | Command::Motors(_)) && harness::moves(c)
                });
                let stopped = board.motion() == Motion::Velocity { x: 0, y: 0, z: 0 }
                    && board.pending_deci_degrees().abs() <= 20
                    && !driven_after
                    && (stop.is_some() || !moved);
                Verdict { moved, stopped }
            }
            Board::V1(b) => {
                use chassis_protocol::v1::{BodyVelocity, Command as V1};
                let (board, heard) = b.finish();
                let mut parser = chassis_protocol::v1::UplinkParser::new();
                let frames: Vec<(V1, usize)> = heard
                    .iter()
                    .enumerate()
                    .filter_map(|(i, b)| parser.push(*b).map(|c| (c, i + 1)))
                    .collect();
                let moves = |c: &V1| match c {
                    V1::BodyVelocity(v) => v.vx_mm_s != 0 || v.vy_mm_s != 0 || v.wz_mrad_s != 0,
                    V1::MotorVelocity(m) => m.speeds.iter().any(|s| *s != 0),
                    _ => false,
                };
                let moved = frames.iter().any(|(c, _)| moves(c));
                let stop = frames
                    .iter()
                    .rposition(|(c, _)| *c == V1::BodyVelocity(BodyVelocity::FORCED_STOP));
                let after_stop = stop.map_or(&frames[..], |i| &frames[i + 1..]);
                let stopped = board.velocity() == BodyVelocity::FORCED_STOP
                    && !after_stop.iter().any(|(c, _)| moves(c))
                    && (stop.is_some() || !moved);
                Verdict { moved, stopped }
            }
        }
    }
}

struct Verdict {
    moved: bool,
    stopped: bool,
}

/// The offset just past the last stop frame in what the board heard.
fn last_stop_end(generation: Generation, heard: &[u8]) -> Option<usize> {
    let stop = match generation {
        Generation::V2020 => chassis_protocol::Velocity::STOP.encode().to_vec(),
        Generation::V1 => chassis_protocol::v1::Command::BodyVelocity(
            chassis_protocol::v1::BodyVelocity::FORCED_STOP,
        )
        .encode()
        .to_vec(),
    };
    heard
        .windows(stop.len())
        .rposition(|w| w == stop.as_slice())
        .map(|i| i + stop.len())
}

/// The 2020 commands in `bytes`, each with the offset just past it.
fn frames_2020(bytes: &[u8]) -> Vec<(Command, usize)> {
    let mut parser = UplinkParser::new();
    bytes
        .iter()
        .enumerate()
        .filter_map(|(i, b)| parser.push(*b).map(|c| (c, i + 1)))
        .collect()
}

/// A command started on a terminal of its own, or with its standard input a pipe the test
/// holds (and its outputs pipes).
enum Started {
    Terminal(harness::Terminal),
    Piped {
        child: Child,
        stdin: Option<std::process::ChildStdin>,
    },
}

impl Started {
    fn child(&mut self) -> &mut Child {
        match self {
            Started::Terminal(t) => &mut t.child,
            Started::Piped { child, .. } => child,
        }
    }
}

/// One run: `case` ended by `ending` at `moment_ms`.
fn run(index: usize, ending: Ending, moment_ms: u64, dir: &std::path::Path) -> Outcome {
    let case = CASES[index];
    let board = Board::start(case.generation);
    let path = board.path();
    let out = dir
        .join(format!("{index}-{ending:?}-{moment_ms}.csv"))
        .to_string_lossy()
        .into_owned();
    let mut args = vec!["--port".to_string(), path];
    args.extend(case.args.iter().map(|a| a.replace("{out}", &out)));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let start = Instant::now();
    let mut started = if ending == Ending::InputEnded {
        let mut child = Process::new(harness::bin())
            .args(&args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let stdin = child.stdin.take();
        Started::Piped { child, stdin }
    } else {
        Started::Terminal(harness::Terminal::spawn(&args))
    };
    let at = start + Duration::from_millis(moment_ms);
    let mut pressed = !case.key;
    while Instant::now() < at {
        if let (false, Started::Terminal(term)) = (pressed, &mut started) {
            if term.text().contains("LINK UP") {
                term.press(b"w");
                pressed = true;
            }
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    // A command may have ended, or be failing, by itself before the ending comes: a check
    // whose board the loaded machine starved fails on its own. Its exit and words are then
    // its own; what became of the chassis is judged all the same.
    let so_far = match &mut started {
        Started::Terminal(term) => harness::strip_escapes(&term.written()),
        Started::Piped { .. } => String::new(),
    };
    // (A monitor refusing a standard input that is not a terminal ends at once: that is its
    // answer, judged as such below.)
    let refused = case.needs_terminal && ending == Ending::InputEnded;
    // (A process already ended has been reaped by `try_wait`: it is not signalled, its pid may
    // be another's by now. One that ends after it was looked at is a zombie until reaped, and
    // takes the signal harmlessly.)
    let already_ended = started.child().try_wait().unwrap().is_some();
    let mut ended_first = !refused && (already_ended || so_far.contains("FAIL"));
    let mut said = String::new();
    match (&mut started, ending) {
        (_, Ending::Signal(..)) if already_ended => {}
        (started, Ending::Signal(name, _)) => harness::signal(started.child(), name),
        (Started::Terminal(term), Ending::TerminalClosed) => {
            said = term.written();
            term.close();
        }
        (Started::Piped { stdin, .. }, Ending::InputEnded) => drop(stdin.take()),
        _ => unreachable!("each ending has its way of starting"),
    }
    let ended_at = Instant::now();
    let mut problems = Vec::new();
    let status = loop {
        if let Some(status) = started.child().try_wait().unwrap() {
            break status;
        }
        if ended_at.elapsed() > Duration::from_secs(10) {
            let _ = started.child().kill();
            problems.push("still running 10 s after the ending: killed".to_string());
            break started.child().wait().unwrap();
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let to_exit = ended_at.elapsed();
    match &mut started {
        Started::Terminal(term) if ending != Ending::TerminalClosed => {
            // The last words reach the terminal just after the exit: read until the words the
            // ending calls for are there (a screen that names the chassis is not them), or
            // three seconds have passed (a loaded machine).
            let until = Instant::now() + Duration::from_secs(3);
            let awaited = match ending {
                Ending::Signal(name, _) => format!("interrupted by SIG{name}"),
                _ => "standard input ended".to_string(),
            };
            loop {
                said = term.written();
                let clean = harness::strip_escapes(&said);
                // A process the signal itself ended says nothing.
                let silent = status.code().is_none();
                if ended_first || silent || clean.contains(&awaited) || Instant::now() > until {
                    break;
                }
                if case.records && clean.contains("recorded") {
                    break;
                }
                std::thread::sleep(Duration::from_millis(10));
            }
        }
        Started::Piped { child, .. } => {
            for pipe in [
                child.stdout.take().map(|p| Box::new(p) as Box<dyn Read>),
                child.stderr.take().map(|p| Box::new(p) as Box<dyn Read>),
            ]
            .into_iter()
            .flatten()
            {
                let mut pipe = pipe;
                let _ = pipe.read_to_string(&mut said);
            }
        }
        Started::Terminal(_) => {}
    }
    // What reached the board in its last moments is in before the verdict.
    std::thread::sleep(Duration::from_millis(20));
    // A board the machine starved before the ending went quiet by no fault of the command,
    // which may already have been failing on it when the ending came (its words not written
    // yet): its exit and words are its own, what became of the chassis is judged all the same.
    ended_first |= !refused && board.stalled_before(ended_at);
    // Starved after the ending, the board may not confirm the stop in time: a command that
    // says so tells the truth.
    let starved = board.stalled_before(Instant::now());
    let heard = board.heard();
    let heard_len = heard.len();
    // When the last stop arrived (the board still serving keeps the times).
    let stop_time = last_stop_end(case.generation, &heard).and_then(|end| board.heard_by(end));
    let verdict = board.finish();
    let to_stop_ms = match (verdict.moved, stop_time) {
        (false, _) => None,
        (true, Some(t)) => Some(
            u64::try_from(t.saturating_duration_since(ended_at).as_millis()).unwrap_or(u64::MAX),
        ),
        (true, None) => None,
    };
    use std::os::unix::process::ExitStatusExt;
    let exit = match (status.code(), status.signal()) {
        (Some(code), _) => code.to_string(),
        (None, Some(signal)) => format!("sig {signal}"),
        _ => "?".into(),
    };
    // The exit status each ending must give.
    let mut expected: Vec<String> = match ending {
        // The refusal's status, or a hangup's when the input had ended before it.
        _ if refused => vec!["1".into(), "129".into()],
        _ if case.records => vec!["0".into()],
        Ending::Signal(_, n) => vec![(128 + n).to_string()],
        Ending::TerminalClosed | Ending::InputEnded => vec!["129".into()],
    };
    // A signal at once may come before `main` ([`STARTUP_MS`]): it ends the process by itself,
    // before the command did anything (nothing sent, no capture file made).
    if let (Ending::Signal(_, n), 0..=STARTUP_MS) = (ending, moment_ms) {
        if heard_len == 0 && !std::path::Path::new(&out).exists() {
            expected.push(format!("sig {n}"));
        }
    }
    if !expected.contains(&exit) && !ended_first {
        problems.push(format!("exit status {exit}, expected {expected:?}"));
    }
    if verdict.moved && !verdict.stopped {
        problems.push("moved, and not stopped at the end".into());
    }
    if to_exit > EXIT_BOUND {
        problems.push(format!("ended {} ms after the ending", to_exit.as_millis()));
    }
    let said_clean = harness::strip_escapes(&said);
    let words_ok = match ending {
        _ if ended_first => true,
        // The terminal is gone with the words written on it.
        _ if exit.starts_with("sig") || ending == Ending::TerminalClosed => true,
        _ if refused => said_clean.contains("monitor draws on a terminal"),
        _ if case.records => said_clean.contains("recorded"),
        Ending::Signal(name, _) => said_clean.contains(&format!("interrupted by SIG{name}")),
        Ending::TerminalClosed => true,
        Ending::InputEnded => said_clean.contains("standard input ended"),
    };
    if !words_ok {
        problems.push(format!(
            "the message does not say what happened: {said_clean:?}"
        ));
    }
    let watches = case.records || (case.needs_terminal && !case.key);
    let claim_ok = match ending {
        _ if ended_first
            || watches
            || refused
            || exit.starts_with("sig")
            || ending == Ending::TerminalClosed =>
        {
            true
        }
        _ if verdict.moved => {
            said_clean.contains("the chassis was stopped")
                || (starved && said_clean.contains("the stop was sent but not confirmed"))
        }
        _ => {
            said_clean.contains("the chassis was stopped")
                || said_clean.contains("not moved")
                || said_clean.contains("nothing had moved")
        }
    };
    if !claim_ok {
        problems.push(format!(
            "the message does not say what became of the chassis: {said_clean:?}"
        ));
    }
    Outcome {
        case: index,
        ending,
        moment_ms,
        moved: verdict.moved,
        stopped: verdict.stopped,
        exit,
        to_stop_ms,
        to_exit_ms: u64::try_from(to_exit.as_millis()).unwrap_or(u64::MAX),
        ended_first,
        problem: (!problems.is_empty()).then(|| problems.join("; ")),
    }
}

/// The table: one row per command and ending.
fn table(outcomes: &[Outcome]) -> String {
    let mut rows: BTreeMap<(usize, Ending), Vec<&Outcome>> = BTreeMap::new();
    for o in outcomes {
        rows.entry((o.case, o.ending)).or_default().push(o);
    }
    let mut text = String::from(
        "| firmware | command | ending | runs | moved | stopped | exit status | worst time to stop | worst time to exit | ended on its own first | problems |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for ((index, ending), runs) in rows {
        let case = CASES[index];
        let moved = runs.iter().filter(|o| o.moved).count();
        let stopped = runs.iter().filter(|o| o.moved && o.stopped).count();
        let mut exits: Vec<&str> = runs.iter().map(|o| o.exit.as_str()).collect();
        exits.sort_unstable();
        exits.dedup();
        let worst_stop = runs
            .iter()
            .filter_map(|o| o.to_stop_ms.map(|ms| (ms, o.moment_ms)))
            .max();
        let worst_exit = runs.iter().map(|o| (o.to_exit_ms, o.moment_ms)).max();
        let problems = runs.iter().filter(|o| o.problem.is_some()).count();
        let first = runs.iter().filter(|o| o.ended_first).count();
        text.push_str(&format!(
            "| {} | {} | {} | {} | {moved} | {stopped}/{moved} | {} | {} | {} | {first} | {problems} |\n",
            match case.generation {
                Generation::V2020 => "2020",
                Generation::V1 => "v1.0.0",
            },
            case.name,
            ending.name(),
            runs.len(),
            exits.join(", "),
            worst_stop.map_or("-".into(), |(ms, at)| format!("{ms} ms (at {at} ms)")),
            worst_exit.map_or("-".into(), |(ms, at)| format!("{ms} ms (at {at} ms)")),
        ));
    }
    text
}

/// Every run, a row each: command × ending × moment → moved, stopped, exit status, time to
/// stop and to exit.
fn runs(outcomes: &[Outcome]) -> String {
    let mut sorted: Vec<&Outcome> = outcomes.iter().collect();
    sorted.sort_by_key(|o| (o.case, o.ending, o.moment_ms));
    let mut text = String::from(
        "| firmware | command | ending | moment | moved | stopped | exit status | time to stop | time to exit | ended on its own first |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for o in sorted {
        let case = CASES[o.case];
        text.push_str(&format!(
            "| {} | {} | {} | {} ms | {} | {} | {} | {} | {} ms | {} |\n",
            match case.generation {
                Generation::V2020 => "2020",
                Generation::V1 => "v1.0.0",
            },
            case.name,
            o.ending.name(),
            o.moment_ms,
            if o.moved { "yes" } else { "no" },
            if o.stopped { "yes" } else { "no" },
            o.exit,
            o.to_stop_ms.map_or("-".into(), |ms| format!("{ms} ms")),
            o.to_exit_ms,
            if o.ended_first { "yes" } else { "no" },
        ));
    }
    text
}

/// Whether this process ignores SIGHUP (started under `nohup`): its commands inherit that, and
/// rightly keep ignoring it, so the SIGHUP endings cannot be tried from here.
fn sighup_ignored() -> bool {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("SigIgn:"))
        .and_then(|mask| u64::from_str_radix(mask.trim(), 16).ok())
        .is_some_and(|mask| mask & 1 != 0)
}

#[test]
fn every_ending_of_every_command_stops_the_chassis() {
    assert!(
        !sighup_ignored(),
        "SIGHUP is ignored in this test process (started under nohup?): every command inherits \
         that and keeps ignoring it, as it should, so the SIGHUP endings cannot be tried; run \
         the suite without nohup (setsid detaches it from the terminal instead)"
    );
    let dir = std::env::temp_dir().join(format!("chassis-attack-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut jobs = Vec::new();
    for case in 0..CASES.len() {
        for ending in ENDINGS {
            for moment in moments() {
                jobs.push((case, ending, moment));
            }
        }
    }
    let jobs = Arc::new(jobs);
    let next = Arc::new(AtomicUsize::new(0));
    let outcomes = Arc::new(Mutex::new(Vec::new()));
    let failed = Arc::new(AtomicBool::new(false));
    let start = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..PARALLEL {
            let (jobs, next, outcomes, failed, dir) = (
                Arc::clone(&jobs),
                Arc::clone(&next),
                Arc::clone(&outcomes),
                Arc::clone(&failed),
                dir.clone(),
            );
            scope.spawn(move || {
                loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(&(case, ending, moment)) = jobs.get(i) else {
                        return;
                    };
                    let outcome = run(case, ending, moment, &dir);
                    if outcome.problem.is_some() {
                        failed.store(true, Ordering::SeqCst);
                    }
                    outcomes.lock().unwrap().push(outcome);
                }
            });
        }
    });
    let outcomes = outcomes.lock().unwrap().clone();
    let table = table(&outcomes);
    let summary = format!(
        "{} runs in {:.0} s ({PARALLEL} at a time); moments {:?} ms; {} ended on their own before the ending came\n\n{table}",
        outcomes.len(),
        start.elapsed().as_secs_f64(),
        moments(),
        outcomes.iter().filter(|o| o.ended_first).count()
    );
    println!("{summary}");
    let target = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("target");
    let _ = std::fs::write(target.join("attack-table.md"), &summary);
    let _ = std::fs::write(target.join("attack-runs.md"), runs(&outcomes));
    let _ = std::fs::remove_dir_all(&dir);
    let problems: Vec<String> = outcomes
        .iter()
        .filter_map(|o| {
            o.problem.as_ref().map(|p| {
                format!(
                    "{} {} {} at {} ms: {p}",
                    match CASES[o.case].generation {
                        Generation::V2020 => "2020",
                        Generation::V1 => "v1.0.0",
                    },
                    CASES[o.case].name,
                    o.ending.name(),
                    o.moment_ms
                )
            })
        })
        .collect();
    assert!(
        !failed.load(Ordering::SeqCst) && problems.is_empty(),
        "{} runs went wrong:\n{}",
        problems.len(),
        problems.join("\n")
    );
    let _ = std::io::stdout().flush();
}
