//! How a command that talks to the board learns that it must end early, and what it says then.
//!
//! - **Signals**: SIGINT (Ctrl-C), SIGTERM (`kill`, `systemctl stop`, `docker stop`) and SIGHUP
//!   are caught from `main`'s first instruction ([`catch_from_start`]), so a signal at any
//!   moment has its documented effect, also one inherited as ignored (a background job of a
//!   script ignores SIGINT). SIGHUP inherited as ignored stays ignored: `nohup` asks for a
//!   command that outlives its terminal. A command that talks to no board (`decode`, `encode`,
//!   `sim`) gets each signal's default effect back ([`for_command`]).
//! - **The session gone**, for the commands that last ([`Kind::Lasting`]: they move or watch
//!   the chassis for a while): the terminal the command runs on hung up (a closed window, a
//!   dropped ssh session, a killed tmux server; no SIGHUP need come: the command is not always
//!   the session's leader), or its standard input, a pipe, ended (`ssh host chassis …` without
//!   a terminal, whose connection dropped), also one already at its end when the command
//!   started: nobody is there to stop it. Standard input that is a file or `/dev/null` (a
//!   script, a systemd service: `</dev/null` in a crontab) never ends a command.
//!
//! A command that moves or watches the chassis checks [`ended`] in its loop (the port's waits
//! check it too: [`crate::port::Port`]), stops the chassis (cancelling a turn), says what
//! happened and exits with [`Ending::exit_status`]. SIGKILL cannot be caught: then the driver's
//! failsafe is gone with the process, and only the board's own watchdog (if any) stops the
//! chassis.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Why a command ended before its time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ending {
    /// A signal (its number) came.
    Signal(i32),
    /// The terminal the command runs on hung up.
    TerminalClosed,
    /// Standard input (a pipe) ended.
    InputEnded,
}

impl Ending {
    /// What happened, as the start of a sentence: "interrupted by SIGINT", "the terminal
    /// closed", "standard input ended".
    pub fn words(self) -> String {
        match self {
            Ending::Signal(signal) => format!("interrupted by {}", name(signal)),
            Ending::TerminalClosed => "the terminal closed".into(),
            Ending::InputEnded => {
                "standard input ended (the session that started the command is gone; give it </dev/null to run without one)".into()
            }
        }
    }

    /// The exit status: 128 + the signal's number, as a shell reports a process a signal
    /// ended; a terminal or an input that went away is a hangup (129, SIGHUP's).
    pub fn exit_status(self) -> u8 {
        match self {
            Ending::Signal(signal) => u8::try_from(128 + signal).unwrap_or(1),
            Ending::TerminalClosed | Ending::InputEnded => 129,
        }
    }
}

#[cfg(unix)]
const SIGNALS: [(i32, &str); 3] = [
    (signal_hook::consts::SIGINT, "SIGINT"),
    (signal_hook::consts::SIGTERM, "SIGTERM"),
    (signal_hook::consts::SIGHUP, "SIGHUP"),
];
#[cfg(not(unix))]
const SIGNALS: [(i32, &str); 2] = [
    (signal_hook::consts::SIGINT, "SIGINT"),
    (signal_hook::consts::SIGTERM, "SIGTERM"),
];

/// What the handlers share with the command.
struct Caught {
    /// The signal caught (0: none).
    signal: Arc<AtomicUsize>,
    /// A signal now has its default effect (the command talks to no board).
    default: Arc<AtomicBool>,
    /// The session's end, once seen (it is not looked for again).
    session: Mutex<Option<Ending>>,
    /// The terminal and standard input watched for their end.
    watched: AtomicBool,
}

/// What a command does, for its endings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Talks to no board (`decode`, `encode`, `sim`): each signal has its default effect.
    NoBoard,
    /// Talks to the board briefly (`get`, `set`, `stop`…): the signals are caught, the command
    /// ends at its next wait and says so.
    Brief,
    /// Moves or watches the chassis for a while (`drive`, `turn`, `monitor`, `check`,
    /// `record`, `calibrate-gyro`): the signals are caught and the session watched.
    Lasting,
}

static CAUGHT: OnceLock<Caught> = OnceLock::new();

/// Catches SIGINT, SIGTERM and SIGHUP (unless SIGHUP was inherited as ignored) from now on:
/// call it first thing in `main`. A handler that cannot be installed is said on stderr; the
/// command goes on with that signal's default effect.
pub fn catch_from_start() {
    let caught = CAUGHT.get_or_init(|| Caught {
        signal: Arc::new(AtomicUsize::new(0)),
        default: Arc::new(AtomicBool::new(false)),
        session: Mutex::new(None),
        watched: AtomicBool::new(false),
    });
    for (signal, name) in SIGNALS {
        if inherited_ignored(signal) && Some(signal) == hangup() {
            continue;
        }
        let value = usize::try_from(signal).unwrap_or(usize::MAX);
        // The default effect first: when armed, it ends the process before the flag is set.
        let installed =
            signal_hook::flag::register_conditional_default(signal, Arc::clone(&caught.default))
                .and_then(|_| {
                    signal_hook::flag::register_usize(signal, Arc::clone(&caught.signal), value)
                });
        if let Err(e) = installed {
            tell!("chassis: cannot handle {name}: {e}");
        }
    }
}

/// SIGHUP, where there is one.
fn hangup() -> Option<i32> {
    #[cfg(unix)]
    {
        Some(signal_hook::consts::SIGHUP)
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// Whether `signal` was ignored when the process started (Linux: `SigIgn` in
/// `/proc/self/status`; elsewhere taken as not).
fn inherited_ignored(signal: i32) -> bool {
    let Ok(status) = std::fs::read_to_string("/proc/self/status") else {
        return false;
    };
    let Some(mask) = status
        .lines()
        .find_map(|l| l.strip_prefix("SigIgn:"))
        .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
    else {
        return false;
    };
    (1..=64).contains(&signal) && mask & (1 << (signal - 1)) != 0
}

/// After the arguments are read, what the command is ([`Kind`]): a command that talks to no
/// board gets each signal's default effect back (one that came already ends it now, as it
/// would have); one that lasts has its terminal and input watched from now on.
pub fn for_command(kind: Kind) {
    let Some(caught) = CAUGHT.get() else {
        return;
    };
    match kind {
        Kind::NoBoard => {
            caught.default.store(true, Ordering::SeqCst);
            if let Some(Ending::Signal(signal)) = signal() {
                let _ = signal_hook::low_level::emulate_default_handler(signal);
            }
        }
        Kind::Brief => {}
        Kind::Lasting => caught.watched.store(true, Ordering::SeqCst),
    }
}

fn signal() -> Option<Ending> {
    let value = CAUGHT.get()?.signal.load(Ordering::SeqCst);
    match value {
        0 => None,
        v => i32::try_from(v).ok().map(Ending::Signal),
    }
}

/// Why the command must end now, if it must: a signal came, or its terminal or input went away.
pub fn ended() -> Option<Ending> {
    if let Some(signal) = signal() {
        return Some(signal);
    }
    let caught = CAUGHT.get()?;
    if !caught.watched.load(Ordering::SeqCst) {
        return None;
    }
    let mut session = caught
        .session
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if session.is_none() {
        *session = session_gone();
    }
    *session
}

/// The terminal hung up, or standard input (a pipe) ended: looked for without reading
/// anything, by `poll(2)` on the three standard streams.
#[cfg(unix)]
fn session_gone() -> Option<Ending> {
    use rustix::event::{PollFd, PollFlags, poll};
    use std::io::IsTerminal;
    use std::os::fd::AsFd;
    let (stdin, stdout, stderr) = (std::io::stdin(), std::io::stdout(), std::io::stderr());
    let gone = PollFlags::HUP | PollFlags::ERR;
    // Standard input whatever it is (a file or /dev/null never hangs up); the outputs only
    // when they are a terminal (a closed pipe on stdout, `| head`, is no reason to stop).
    let mut fds = [
        PollFd::new(&stdin, PollFlags::empty()),
        PollFd::new(&stdout, PollFlags::empty()),
        PollFd::new(&stderr, PollFlags::empty()),
    ];
    if poll(&mut fds, Some(&rustix::event::Timespec::default())).is_err() {
        return None;
    }
    let terminal = [
        stdin.as_fd().is_terminal(),
        stdout.as_fd().is_terminal(),
        stderr.as_fd().is_terminal(),
    ];
    let hung = |i: usize| fds.get(i).is_some_and(|fd| fd.revents().intersects(gone));
    if (0..3).any(|i| hung(i) && terminal.get(i).copied().unwrap_or(false)) {
        return Some(Ending::TerminalClosed);
    }
    if hung(0) && (hung(1) || hung(2)) {
        // A terminal that hung up may no longer say it is one.
        return Some(Ending::TerminalClosed);
    }
    hung(0).then_some(Ending::InputEnded)
}

#[cfg(not(unix))]
fn session_gone() -> Option<Ending> {
    None
}

/// A signal's name ("SIGINT").
pub fn name(signal: i32) -> &'static str {
    SIGNALS
        .iter()
        .find(|(s, _)| *s == signal)
        .map_or("a signal", |(_, n)| n)
}

/// `Err` when the command must end before anything that moves the chassis is sent: nothing was.
pub fn before_motion() -> Result<(), String> {
    match ended() {
        Some(end) => Err(format!(
            "{}: the chassis was not moved (nothing that moves it was sent)",
            end.words()
        )),
        None => Ok(()),
    }
}
