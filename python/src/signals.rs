//! The signal guard: every open chassis stopped when the process is told to end (SIGTERM:
//! `systemctl stop`, `docker stop`, `kill`; SIGHUP: the terminal or the session closed), without
//! taking the program's own handlers away.
//!
//! `open()` puts a handler of this package in front of what each of the two signals does at
//! that moment, in C (`sigaction`), so it works whatever thread opens the chassis and whatever
//! the main thread is doing (asleep, blocked in another library's native call):
//!
//! * **the default action** (the program set nothing): the handler wakes the guard's own
//!   thread, which stops every open chassis (the stop frame at once; a turn's cancel waited for
//!   at most [`STOP_WAIT`](crate::driver::STOP_WAIT)), refuses anything else from then on,
//!   writes one line to standard error, and ends the process with the signal's own default
//!   action: its exit status is the signal's, as without this package.
//! * **a handler of the program** (a Python handler set with `signal.signal` before `open()`,
//!   or one installed in C by another library, such as rclpy): the guard's thread writes the
//!   stop of every open chassis, then sends the signal again, and this time the handler passes
//!   it to the program's, as if this package were not there (a turn's cancel is waited for
//!   meanwhile). What the program's handler does then (end, drive on, reload) is the program's
//!   to decide; it finds every chassis stopped. A handler the program sets after `open()`
//!   replaces this package's (Python's `signal.signal` does that): the program's then runs
//!   alone; the next `open()` puts the stop in front of it again.
//! * **ignored** (`nohup` ignores SIGHUP; a program may ignore SIGTERM): left ignored. The
//!   program asked to outlive that signal, and the chassis goes on too.
//!
//! A child process made by `fork` inherits the handler, which there does what the signal did
//! before (the chassis are the parent's); it sets up its own guard when it opens a chassis.

use std::sync::atomic::{AtomicBool, AtomicPtr, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::time::Instant;

/// Why a stop could not be written.
pub enum StopFailed {
    /// The chassis was already closed.
    Closed,
    /// The port refused the bytes: what it said.
    Port(String),
}

/// An open chassis, as the guard stops it.
pub trait Stoppable: Send + Sync {
    /// The port's path.
    fn port(&self) -> &str;
    /// Writes the stop now, ahead of anything not yet begun; the request it started (2020: the
    /// cancel of a turn outstanding), if any. With `ending` (the signal's name), nothing but
    /// stops goes out afterwards: the process is ending.
    fn send_stop(&self, ending: Option<&'static str>) -> Result<Option<u64>, StopFailed>;
    /// Waits until `until` at most for request `id`, which [`send_stop`](Self::send_stop)
    /// started.
    fn wait_stop(&self, id: u64, until: Instant);
}

/// The signals guarded, with their names.
const SIGNALS: [(libc::c_int, &str); 2] = [(libc::SIGTERM, "SIGTERM"), (libc::SIGHUP, "SIGHUP")];

/// The guard of one process (a child made by fork sets up its own).
struct Guard {
    pid: libc::pid_t,
    /// The handler writes the index of the signal here (non-blocking); the guard's thread
    /// reads the other end.
    write_fd: libc::c_int,
    /// The chassis this process opened.
    chassis: Mutex<Vec<Weak<dyn Stoppable>>>,
}

/// This process's guard (a parent's, inherited by fork, is told by its pid and left alone).
static GUARD: AtomicPtr<Guard> = AtomicPtr::new(std::ptr::null_mut());

/// What each signal of [`SIGNALS`] did before this package's handler (null: not installed).
static PREVIOUS: [AtomicPtr<libc::sigaction>; 2] = [
    AtomicPtr::new(std::ptr::null_mut()),
    AtomicPtr::new(std::ptr::null_mut()),
];

/// Set by the guard's thread before it sends a signal again, once the chassis are stopped: that
/// delivery is the program's handler's.
static AGAIN: [AtomicBool; 2] = [AtomicBool::new(false), AtomicBool::new(false)];

/// Blocks SIGINT, SIGTERM and SIGHUP in the calling thread (one of this package's own), so that
/// the kernel hands them to the program's threads: the main thread's waits end on them, as
/// Python expects.
pub fn keep_signals_off_this_thread() {
    // SAFETY: a signal set on the stack, filled before use; the mask of this thread only.
    unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        for s in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            libc::sigaddset(&mut set, s);
        }
        libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut());
    }
}

/// The guard of this process, set up if there is none yet (the GIL held: one caller at a time,
/// also in a child made by fork, where CPython makes the GIL anew).
fn guard(_py: pyo3::Python<'_>) -> Result<&'static Guard, String> {
    let pid = unsafe { libc::getpid() };
    let current = GUARD.load(Ordering::Acquire);
    // SAFETY: a guard, once stored, is never freed.
    if let Some(g) = unsafe { current.as_ref() } {
        if g.pid == pid {
            return Ok(g);
        }
    }
    let mut fds = [0 as libc::c_int; 2];
    // SAFETY: `fds` has room for the two descriptors.
    if unsafe { libc::pipe(fds.as_mut_ptr()) } != 0 {
        return Err(format!("pipe: {}", std::io::Error::last_os_error()));
    }
    let [read_fd, write_fd] = fds;
    // SAFETY: plain descriptor flags on the two descriptors just made.
    unsafe {
        libc::fcntl(read_fd, libc::F_SETFD, libc::FD_CLOEXEC);
        libc::fcntl(write_fd, libc::F_SETFD, libc::FD_CLOEXEC);
        let flags = libc::fcntl(write_fd, libc::F_GETFL);
        libc::fcntl(write_fd, libc::F_SETFL, flags | libc::O_NONBLOCK);
    }
    std::thread::Builder::new()
        .name("chassis-signals".into())
        .spawn(move || {
            keep_signals_off_this_thread();
            watch(read_fd);
        })
        .map_err(|e| format!("cannot start the signal guard: {e}"))?;
    // Leaked on purpose: the handler may read it at any time; a parent's, in a child, is not
    // freed either (its lock may have been held at the fork).
    let new: &'static Guard = Box::leak(Box::new(Guard {
        pid,
        write_fd,
        chassis: Mutex::new(Vec::new()),
    }));
    GUARD.store(std::ptr::from_ref(new).cast_mut(), Ordering::Release);
    Ok(new)
}

/// Puts this package's handler in front of what SIGTERM and SIGHUP do now (see the module's
/// docs); called by `open()` before the port is opened. Nothing changes for a signal ignored,
/// or already handled by this package.
pub fn install(py: pyo3::Python<'_>) -> Result<(), String> {
    guard(py)?;
    for (index, (signal, _)) in SIGNALS.iter().enumerate() {
        // SAFETY: `sigaction` with a zeroed struct to fill, then one filled in full.
        unsafe {
            let mut current: libc::sigaction = std::mem::zeroed();
            if libc::sigaction(*signal, std::ptr::null(), &mut current) != 0 {
                continue;
            }
            if current.sa_sigaction == handler as *const () as usize
                || current.sa_sigaction == libc::SIG_IGN
            {
                continue;
            }
            let keep = current.sa_flags & libc::SA_RESTART;
            // Leaked on purpose: the handler may be reading the one before.
            let previous = Box::into_raw(Box::new(current));
            if let Some(slot) = PREVIOUS.get(index) {
                slot.store(previous, Ordering::Release);
            }
            let mut ours: libc::sigaction = std::mem::zeroed();
            ours.sa_sigaction = handler as *const () as usize;
            ours.sa_flags = libc::SA_SIGINFO | libc::SA_ONSTACK | keep;
            libc::sigemptyset(&mut ours.sa_mask);
            libc::sigaction(*signal, &ours, std::ptr::null_mut());
        }
    }
    Ok(())
}

/// Puts an open chassis under the guard of this process (after [`install`]).
pub fn register(py: pyo3::Python<'_>, chassis: Weak<dyn Stoppable>) {
    let Ok(g) = guard(py) else { return };
    let mut list = g
        .chassis
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    list.retain(|c| c.strong_count() > 0);
    list.push(chassis);
}

/// Where `errno` is, to keep it across the handler.
#[cfg(any(target_os = "linux", target_os = "android"))]
fn errno() -> *mut libc::c_int {
    // SAFETY: the C library's own errno location of this thread.
    unsafe { libc::__errno_location() }
}

/// Where `errno` is, to keep it across the handler.
#[cfg(any(target_os = "macos", target_os = "ios", target_os = "freebsd"))]
fn errno() -> *mut libc::c_int {
    // SAFETY: the C library's own errno location of this thread.
    unsafe { libc::__error() }
}

/// The handler: async-signal-safe calls only (`getpid`, `write`, `signal`, `raise`, the
/// previous handler). It never waits: the guard's thread does the stopping.
extern "C" fn handler(signal: libc::c_int, info: *mut libc::siginfo_t, context: *mut libc::c_void) {
    let Some(index) = SIGNALS.iter().position(|(s, _)| *s == signal) else {
        return;
    };
    let saved = errno();
    // SAFETY: errno is this thread's; the guard, once stored, is never freed; `write` of one
    // byte from the stack; the previous action as `sigaction` gave it.
    unsafe {
        let kept = *saved;
        let guard = GUARD.load(Ordering::Acquire).as_ref();
        let ours = guard.is_some_and(|g| g.pid == libc::getpid());
        let again = AGAIN
            .get(index)
            .is_some_and(|a| a.swap(false, Ordering::AcqRel));
        if let Some(g) = guard.filter(|_| ours && !again) {
            // The guard's thread stops the chassis, then sends the signal again (or, with no
            // handler of the program's, ends the process by it).
            let byte = index as u8;
            libc::write(g.write_fd, std::ptr::from_ref(&byte).cast(), 1);
            *saved = kept;
            return;
        }
        // The chassis stopped (`again`), or a child made by fork (the chassis are the
        // parent's): the signal does what it did before this package.
        if let Some(previous) = previous(index) {
            match previous.sa_sigaction {
                libc::SIG_DFL => {
                    libc::signal(signal, libc::SIG_DFL);
                    libc::raise(signal);
                }
                libc::SIG_IGN => {}
                f if previous.sa_flags & libc::SA_SIGINFO != 0 => {
                    let f: extern "C" fn(libc::c_int, *mut libc::siginfo_t, *mut libc::c_void) =
                        std::mem::transmute(f);
                    f(signal, info, context);
                }
                f => {
                    let f: extern "C" fn(libc::c_int) = std::mem::transmute(f);
                    f(signal);
                }
            }
        }
        *saved = kept;
    }
}

/// The guard's thread: waits for a signal's index on the pipe, then stops every chassis.
fn watch(read_fd: libc::c_int) {
    loop {
        let mut byte = 0u8;
        // SAFETY: one byte into a byte on the stack.
        let n = unsafe { libc::read(read_fd, std::ptr::from_mut(&mut byte).cast(), 1) };
        match n {
            1 => on_signal(usize::from(byte)),
            _ if std::io::Error::last_os_error().kind() == std::io::ErrorKind::Interrupted => {}
            _ => return,
        }
    }
}

/// What signal `index` of [`SIGNALS`] did before this package's handler, if the handler is
/// installed.
fn previous(index: usize) -> Option<&'static libc::sigaction> {
    let previous = PREVIOUS.get(index)?.load(Ordering::Acquire);
    // SAFETY: a previous action, once stored, is never freed.
    unsafe { previous.as_ref() }
}

/// The chassis this process opened that are still open.
fn open_chassis(guard: &Guard) -> Vec<Arc<dyn Stoppable>> {
    guard
        .chassis
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .iter()
        .filter_map(Weak::upgrade)
        .collect()
}

/// A signal came: every chassis of this process stopped; then, if the signal's action is the
/// default one, the process ended by it, else the signal passed on to the program's handler.
fn on_signal(index: usize) {
    let Some(&(signal, name)) = SIGNALS.get(index) else {
        return;
    };
    // SAFETY: the guard, once stored, is never freed.
    let Some(guard) = (unsafe { GUARD.load(Ordering::Acquire).as_ref() }) else {
        return;
    };
    let ends = previous(index).is_some_and(|p| p.sa_sigaction == libc::SIG_DFL);
    let chassis = open_chassis(guard);
    // Every stop frame first; then the program's handler; then the cancels of turns, all within
    // one bound.
    let sent: Vec<_> = chassis
        .iter()
        .map(|c| c.send_stop(ends.then_some(name)))
        .collect();
    if !ends {
        if let Some(again) = AGAIN.get(index) {
            again.store(true, Ordering::Release);
            // SAFETY: the signal sent again to this process: the handler passes it on.
            unsafe {
                libc::kill(libc::getpid(), signal);
            }
        }
    }
    let said = settle(&chassis, sent);
    if ends {
        end_process(signal, name, &said);
    }
}

/// Waits (within one bound) for what each stop started (2020: the cancel of a turn); what
/// happened to each chassis, in words.
fn settle(
    chassis: &[Arc<dyn Stoppable>],
    sent: Vec<Result<Option<u64>, StopFailed>>,
) -> Vec<String> {
    let until = Instant::now() + crate::driver::STOP_WAIT;
    let mut said = Vec::new();
    for (c, sent) in chassis.iter().zip(sent) {
        match sent {
            Ok(started) => {
                if let Some(id) = started {
                    c.wait_stop(id, until);
                }
                said.push(format!("the chassis on {} was stopped", c.port()));
            }
            Err(StopFailed::Closed) => {}
            Err(StopFailed::Port(text)) => said.push(format!(
                "the stop could not be written to {}: {text}",
                c.port()
            )),
        }
    }
    said
}

/// Ends the process by `signal` (its default action), after one line to standard error that
/// says what became of each chassis (`said`).
fn end_process(signal: libc::c_int, name: &str, said: &[String]) {
    let said = if said.is_empty() {
        "no chassis open".to_string()
    } else {
        said.join("; ")
    };
    let line = format!("chassis: {name}: {said}; the process ends as {name} asks\n");
    // SAFETY: a write of the line to standard error (its result does not matter: the
    // terminal may be gone), then the signal's default action restored and the signal sent
    // again: the process ends with its status.
    unsafe {
        libc::write(2, line.as_ptr().cast(), line.len());
        libc::signal(signal, libc::SIG_DFL);
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        libc::sigaddset(&mut set, signal);
        libc::pthread_sigmask(libc::SIG_UNBLOCK, &set, std::ptr::null_mut());
        libc::kill(libc::getpid(), signal);
        // Not reached unless the signal was blocked or set otherwise meanwhile.
        std::thread::sleep(std::time::Duration::from_secs(1));
        libc::_exit(128 + signal);
    }
}
