//! The 2020 core's requests: reads judged once, by agreement or by plausibility, settings
//! read and restored, a turn cancelled; their frames, replies, timeouts and retries.

use super::DriverCore;
use super::ghosts::Ghost;
use crate::command::{Register, Setting, Turn, Write};
use crate::driver::safety::FrameKind;
use crate::driver::{CoreError, Event, Outcome, Outgoing, Request, TurnState};
use crate::registers::{self, Snapshot};
use crate::telemetry::Reply;

/// How a read's replies are judged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) enum Check {
    /// One reply, taken as it is (a wrong or unfitting one is an error).
    Once,
    /// Two replies that agree.
    Agree,
    /// One reply that can be the answer: the pending angle of a turn being cancelled, which
    /// changes while it is read (so two reads cannot agree) but must lie between 0 and the turn.
    Plausible,
}

/// Where a read is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) enum Phase {
    /// Still to send.
    ToSend,
    /// In the slot: its bytes are going out.
    Sending,
    /// Its last byte left at `sent_ms`; its reply is awaited until `deadline_ms`.
    Waiting { sent_ms: u64, deadline_ms: u64 },
}

/// The read in flight, if any.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Read {
    register: Register,
    check: Check,
    phase: Phase,
    /// Reads sent so far.
    tries: u8,
    /// Values seen so far (verified reads), most recent first.
    seen: [Option<u32>; 2],
}

impl Read {
    const fn new(register: Register, check: Check) -> Self {
        Read {
            register,
            check,
            phase: Phase::ToSend,
            tries: 0,
            seen: [None, None],
        }
    }
}

/// What a request is doing now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) enum Step {
    /// A read (sent or to send).
    Read(Read),
    /// A write to send (restore), then the next step.
    Write(Write),
    /// The opposite turn to send (cancel), in 0.1°.
    CounterTurn(i32),
}

/// The request in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Job {
    pub(super) request: Request,
    step: Step,
    /// Which step of the request's sequence this is.
    index: u8,
    /// Registers read so far (ReadSettings).
    settings: Snapshot,
    /// Started by the core itself (the failsafe's turn cancel): nobody takes its outcome, and
    /// a request the user starts ends it.
    pub(super) background: bool,
}

impl DriverCore {
    /// The register whose reply is awaited, if any.
    #[must_use]
    pub fn waiting_for(&self) -> Option<Register> {
        match self.job {
            Some(Job {
                step:
                    Step::Read(Read {
                        register,
                        phase: Phase::Waiting { .. },
                        ..
                    }),
                ..
            }) => Some(register),
            _ => None,
        }
    }

    /// The last byte of the read in the slot left at `now`: its reply timeout starts.
    pub(super) fn read_sent(&mut self, now: u64) {
        let timeout = self.reply_timeout_ms();
        if let Some(Job {
            step: Step::Read(read),
            ..
        }) = self.job.as_mut()
        {
            if read.phase == Phase::Sending {
                read.phase = Phase::Waiting {
                    sent_ms: now,
                    deadline_ms: now.saturating_add(timeout),
                };
            }
        }
    }

    /// When the request has something to do: its reply's deadline passed, or a held read's
    /// ghost ended.
    pub(super) fn reply_deadline(&self) -> Option<u64> {
        let Some(Job {
            step: Step::Read(read),
            ..
        }) = self.job
        else {
            return None;
        };
        match read.phase {
            Phase::Waiting { deadline_ms, .. } => Some(deadline_ms.saturating_add(1)),
            Phase::ToSend => self
                .ghosts
                .of(read.register)
                .map(|g| g.until_ms.saturating_add(1)),
            Phase::Sending => None,
        }
    }

    /// Puts a frame the user asked for in the slot, once nothing else is to go out before it
    /// ([`ready_for_frame`](Self::ready_for_frame)).
    // Out of line: one copy for the five frames a user sends without a request.
    #[inline(never)]
    pub(super) fn queue_frame(
        &mut self,
        now: u64,
        frame: Outgoing,
        kind: FrameKind,
    ) -> Result<(), CoreError> {
        self.ready_for_frame(now)?;
        self.pump.safety.queue(frame, kind)
    }

    /// [`CoreError::FramePending`] while anything is still to go out: the frame in the slot, a
    /// queued stop, or a frame of the request in progress.
    fn ready_for_frame(&self, now: u64) -> Result<(), CoreError> {
        let job_frame = match self.job {
            Some(Job {
                step: Step::Read(read),
                ..
            }) => read.phase == Phase::ToSend && self.ghosts.live(read.register, now).is_none(),
            Some(_) => true,
            None => false,
        };
        if self.pump.safety.output_pending() || job_frame {
            return Err(CoreError::FramePending);
        }
        Ok(())
    }

    /// The request's next frame, if it has one to send now.
    pub(super) fn next_job_frame(&mut self, now: u64) -> Option<(Outgoing, FrameKind)> {
        self.ghosts.expire(now);
        let mut job = self.job?;
        match job.step {
            Step::Read(mut read) if read.phase == Phase::ToSend => {
                if self.ghosts.live(read.register, now).is_some() {
                    // Its reply and the ghost's could not be told apart: wait.
                    return None;
                }
                read.phase = Phase::Sending;
                read.tries = read.tries.saturating_add(1);
                job.step = Step::Read(read);
                self.job = Some(job);
                // The master knows when it asked: the parser takes the awaited reply on less
                // evidence, and any other reply on more.
                self.pump.parser.expect_reply(Some(read.register));
                let frame = Setting::Read(read.register).encode();
                Some((Outgoing::new(&frame), FrameKind::Read))
            }
            Step::Read(_) => None,
            Step::Write(write) => {
                self.advance(None);
                Some((
                    Outgoing::new(&Setting::Write(write).encode()),
                    FrameKind::Settings,
                ))
            }
            Step::CounterTurn(deci_degrees) => {
                // In the slot it will go out whole: the turn is over once it has.
                self.turn = TurnState::Idle;
                self.advance(None);
                Some((
                    Outgoing::new(&Turn::by_deci_degrees(deci_degrees).encode()),
                    FrameKind::Motion,
                ))
            }
        }
    }

    // Out of line: `start`, `stop` and the failsafe's turn cancel share it (`size_driver`: 20 B).
    #[inline(never)]
    pub(super) fn begin(&mut self, request: Request, background: bool) {
        let step = match request {
            Request::Read(register) => Step::Read(Read::new(register, Check::Once)),
            Request::ReadVerified(register) => Step::Read(Read::new(register, Check::Agree)),
            Request::ReadSettings => match Snapshot::REGISTERS.first() {
                Some(register) => Step::Read(Read::new(*register, Check::Agree)),
                None => Step::Read(Read::new(Register::MaxSpeed, Check::Agree)),
            },
            Request::RestoreSettings(_) => {
                Step::Read(Read::new(Register::SystemMode, Check::Agree))
            }
            Request::CancelTurn => Step::Read(Read::new(Register::PendingAngle, Check::Plausible)),
        };
        self.job = Some(Job {
            request,
            step,
            index: 0,
            settings: Snapshot::default(),
            background,
        });
    }

    /// Ends the request in progress with `outcome` (kept for the user unless the core started
    /// it). A read already sent and not answered leaves a ghost.
    pub(super) fn end_job(&mut self, outcome: Result<Outcome, CoreError>) {
        let Some(job) = self.job.take() else {
            return;
        };
        if let Step::Read(read) = job.step {
            self.unanswered(&read);
        }
        if !job.background {
            self.outcome = Some(outcome);
        }
    }

    /// A read sent and not answered: remember it until its reply can no longer come.
    fn unanswered(&mut self, read: &Read) {
        let now = self.pump.safety.now();
        let sent_ms = match read.phase {
            Phase::ToSend => return,
            Phase::Sending => now,
            Phase::Waiting { sent_ms, .. } => sent_ms,
        };
        let until_ms = now
            .max(sent_ms.saturating_add(self.reply_timeout_ms()))
            .saturating_add(u64::from(self.pump.config.late_reply_ms));
        self.ghosts
            .remember(Ghost::new(read.register, sent_ms, until_ms));
    }

    /// The current step is done (`value`: what a read gave): the request's next step, or its
    /// outcome.
    fn advance(&mut self, value: Option<u32>) {
        let Some(mut job) = self.job else {
            return;
        };
        if let (Some(raw), Step::Read(read)) = (value, job.step) {
            if read.register == Register::PendingAngle {
                self.pending_angle_read(raw as i32);
            }
        }
        job.index = job.index.saturating_add(1);
        let next = match (job.request, value) {
            (Request::Read(_) | Request::ReadVerified(_), Some(raw)) => {
                return self.finish(Ok(Outcome::Value(raw)));
            }
            (Request::ReadSettings, Some(raw)) => {
                if let Step::Read(read) = job.step {
                    if let Some(write) = Write::from_value(read.register, raw) {
                        job.settings.set(write);
                    }
                }
                match Snapshot::REGISTERS.get(usize::from(job.index)) {
                    Some(register) => Step::Read(Read::new(*register, Check::Agree)),
                    None => return self.finish(Ok(Outcome::Snapshot(job.settings))),
                }
            }
            (Request::RestoreSettings(mut settings), value) => {
                if let Some(raw) = value {
                    // The board's own compensation bit goes back unchanged.
                    let live = crate::command::SystemMode::from_bits(raw).gyro_compensation();
                    settings.system_mode = settings.system_mode.with_gyro_compensation(live);
                    job.request = Request::RestoreSettings(settings);
                }
                let writes = settings.writes();
                match writes.get(usize::from(job.index).saturating_sub(1)) {
                    Some(write) => Step::Write(*write),
                    None => return self.finish(Ok(Outcome::Done)),
                }
            }
            (Request::CancelTurn, Some(raw)) => {
                let pending = raw as i32;
                if pending.unsigned_abs() <= u32::from(self.pump.config.turn_done_deci_degrees) {
                    return self.finish(Ok(Outcome::Done));
                }
                Step::CounterTurn(pending.saturating_neg())
            }
            (Request::CancelTurn, None) => return self.finish(Ok(Outcome::Done)),
            (Request::Read(_) | Request::ReadVerified(_) | Request::ReadSettings, None) => {
                return self.finish(Ok(Outcome::Done));
            }
        };
        job.step = next;
        self.job = Some(job);
    }

    /// A reply to a read of the pending angle: the turn guard learns from it.
    fn pending_angle_read(&mut self, pending: i32) {
        if pending.unsigned_abs() <= u32::from(self.pump.config.turn_done_deci_degrees) {
            self.turn = TurnState::Idle;
        } else if self.turn == TurnState::Unknown {
            self.turn = TurnState::Turning {
                deci_degrees: pending,
            };
        }
    }

    /// The request ended (a read answered for the last time, an error).
    // Out of line: ten callers, each copying an outcome that may hold a whole snapshot
    // (`size_driver`: 112 B).
    #[inline(never)]
    fn finish(&mut self, outcome: Result<Outcome, CoreError>) {
        if let Some(job) = self.job.take() {
            if !job.background {
                self.outcome = Some(outcome);
            }
        }
        self.pump.safety.reset_stall();
    }

    /// A reply came: does the read in flight take it?
    pub(super) fn reply(&mut self, reply: Reply, now: u64) -> Event {
        self.ghosts.expire(now);
        let read = match self.job {
            Some(Job {
                step: Step::Read(read),
                ..
            }) if matches!(read.phase, Phase::Waiting { .. }) => read,
            _ => {
                let _ = self.ghosts.take(reply.code, now);
                return Event::StrayReply(reply);
            }
        };
        let matches = read.register.reply_code() == reply.code;
        if matches {
            // Answered in time: the learnt round trip moves back towards what the board does.
            if let Phase::Waiting { sent_ms, .. } = read.phase {
                let rtt = u32::try_from(now.saturating_sub(sent_ms)).unwrap_or(u32::MAX);
                self.ghosts.answered(rtt);
            }
        }
        if !matches && self.ghosts.take(reply.code, now) {
            // The late reply to an earlier read: the read in flight waits on.
            return Event::StrayReply(reply);
        }
        self.judge(read, reply, matches);
        if matches {
            Event::Reply(reply)
        } else {
            Event::StrayReply(reply)
        }
    }

    /// The read in flight judges a reply (`matches`: of its register): the request's next
    /// step, a retry or its end.
    fn judge(&mut self, mut read: Read, reply: Reply, matches: bool) {
        let fits = registers::fits(read.register, reply.value);
        match read.check {
            Check::Once if !matches => {
                self.unanswered(&read);
                self.finish(Err(CoreError::WrongReply {
                    expected: read.register,
                    got: reply.code,
                }));
            }
            Check::Once if !fits => self.finish(Err(CoreError::Invalid {
                register: read.register,
                value: reply.value,
            })),
            Check::Once => self.advance(Some(reply.value)),
            Check::Agree if matches && fits && read.seen.contains(&Some(reply.value)) => {
                self.advance(Some(reply.value));
            }
            Check::Plausible if matches && self.within_turn(reply.value) => {
                self.advance(Some(reply.value));
            }
            Check::Agree | Check::Plausible => {
                if !matches {
                    self.unanswered(&read);
                } else if fits && read.check == Check::Agree {
                    let [latest, _] = read.seen;
                    read.seen = [Some(reply.value), latest];
                }
                self.retry(read);
            }
        }
    }

    /// Whether a pending angle can be what is left of the outstanding turn: between 0 and the
    /// turn's angle (give or take the tolerance). With no turn known, any angle can be.
    fn within_turn(&self, raw: u32) -> bool {
        let TurnState::Turning { deci_degrees } = self.turn else {
            return true;
        };
        let pending = i64::from(raw as i32);
        let turn = i64::from(deci_degrees);
        let slack = i64::from(self.pump.config.turn_done_deci_degrees);
        let (low, high) = if turn >= 0 { (0, turn) } else { (turn, 0) };
        (low.saturating_sub(slack)..=high.saturating_add(slack)).contains(&pending)
    }

    /// The read in flight gave nothing usable: send it again, or give up.
    fn retry(&mut self, mut read: Read) {
        if read.tries >= self.pump.config.read_tries {
            let error = match read.check {
                Check::Once => CoreError::Timeout(read.register),
                Check::Agree | Check::Plausible => CoreError::Unconfirmed(read.register),
            };
            return self.finish(Err(error));
        }
        read.phase = Phase::ToSend;
        if let Some(job) = self.job.as_mut() {
            job.step = Step::Read(read);
        }
    }

    pub(super) fn check_reply_timeout(&mut self, now: u64) {
        let Some(Job {
            step: Step::Read(read),
            ..
        }) = self.job
        else {
            return;
        };
        match read.phase {
            Phase::Waiting {
                sent_ms,
                deadline_ms,
            } if now > deadline_ms => {
                // No answer in the time given: the board may be slower than that.
                let waited = u32::try_from(deadline_ms.saturating_sub(sent_ms)).unwrap_or(u32::MAX);
                self.ghosts.timed_out(waited);
                self.unanswered(&read);
                // A board that answers nothing is silent, not paused.
                self.pump.safety.read_unanswered();
                match read.check {
                    Check::Once => self.finish(Err(CoreError::Timeout(read.register))),
                    Check::Agree | Check::Plausible => self.retry(read),
                }
            }
            _ => {}
        }
    }
}
