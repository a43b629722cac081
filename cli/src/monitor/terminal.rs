//! The monitor's terminal, kept away from the loop that owns the driver: the keys are read on
//! a thread of their own, and the screen is drawn on another. That loop never waits on the
//! terminal, so neither a terminal that hung up (whose reads then never block again: crossterm
//! reads it for ever) nor one that stopped taking output (a stalled ssh link, a full
//! pseudo-terminal) keeps it from judging the failsafe, stopping the chassis and ending.

use ratatui::Frame;
use ratatui::crossterm::event::{self, Event};
use std::sync::mpsc::{self, Receiver, SyncSender, TryRecvError, TrySendError};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long the monitor waits, on its way out, for the terminal to be given back.
const GIVE_BACK: Duration = Duration::from_millis(500);

/// The terminal's events, read on a thread of their own.
pub struct Keys {
    events: Receiver<Result<Event, String>>,
}

impl Keys {
    /// Starts reading. An error reading the terminal is the last thing passed on.
    pub fn start() -> Keys {
        let (send, events) = mpsc::channel();
        std::thread::spawn(move || {
            loop {
                let event = event::read().map_err(|e| format!("terminal: {e}"));
                let failed = event.is_err();
                if send.send(event).is_err() || failed {
                    return;
                }
            }
        });
        Keys { events }
    }

    /// The next event read, if one is waiting; `Err` once the terminal can no longer be read.
    pub fn next(&self) -> Result<Option<Event>, String> {
        match self.events.try_recv() {
            Ok(event) => event.map(Some),
            Err(TryRecvError::Empty) => Ok(None),
            Err(TryRecvError::Disconnected) => {
                Err("terminal: its keys can no longer be read".into())
            }
        }
    }
}

/// The screen, drawn on a thread of its own from the latest view handed to it.
pub struct Screen<V> {
    views: SyncSender<Option<V>>,
    failed: Arc<Mutex<Option<String>>>,
    thread: JoinHandle<()>,
}

impl<V: Send + 'static> Screen<V> {
    /// Starts drawing on `terminal` with `render`.
    pub fn start(
        mut terminal: ratatui::DefaultTerminal,
        render: fn(&mut Frame<'_>, &V),
    ) -> Screen<V> {
        let (views, inbox) = mpsc::sync_channel::<Option<V>>(1);
        let failed = Arc::new(Mutex::new(None));
        let failure = Arc::clone(&failed);
        let thread = std::thread::spawn(move || {
            while let Ok(Some(view)) = inbox.recv() {
                if let Err(e) = terminal.draw(|f| render(f, &view)) {
                    if let Ok(mut slot) = failure.lock() {
                        *slot = Some(format!("terminal: {e}"));
                    }
                    break;
                }
            }
            give_back(terminal);
        });
        Screen {
            views,
            failed,
            thread,
        }
    }

    /// Hands `view` over to be drawn; skipped when the terminal has not taken the last one.
    pub fn show(&self, view: V) {
        let _ = self.views.try_send(Some(view));
    }

    /// Why the screen can no longer be drawn, if it cannot.
    pub fn failed(&self) -> Option<String> {
        self.failed.lock().ok().and_then(|f| f.clone())
    }

    /// Gives the terminal back as it was, waiting at most [`GIVE_BACK`] (a terminal that takes
    /// no output is left as it is: the process ends all the same).
    pub fn give_back(self) {
        let until = Instant::now() + GIVE_BACK;
        loop {
            match self.views.try_send(None) {
                Ok(()) | Err(TrySendError::Disconnected(_)) => break,
                Err(TrySendError::Full(_)) if Instant::now() >= until => return,
                Err(TrySendError::Full(_)) => std::thread::sleep(Duration::from_millis(5)),
            }
        }
        while !self.thread.is_finished() && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

/// Gives the terminal back as it was (raw mode off, the main screen, the cursor shown). A
/// terminal that hung up takes none of it, and nothing is said of that (ratatui's own restore
/// would print, and printing to a terminal gone panics).
fn give_back(mut terminal: ratatui::DefaultTerminal) {
    let _ = ratatui::try_restore();
    if terminal.show_cursor().is_err() {
        // Its drop would try again and print the failure.
        std::mem::forget(terminal);
    }
}
