//! The bring-up's sequence, written once for both generations: the checks in their order, the
//! start and end of each noted (where a check is one step: link, settings, turn, battery,
//! control loop), the telemetry listened to for the link check, the checks that move skipped
//! without motion, the stop after a failure, and the verdict. What a check does on each
//! generation is its plan's [`Sequence`] (in `v2020/checks.rs`, `v1/checks.rs`).

use crate::link::{Common, Generation, listen};
use crate::{Check, Failure, LinkError, Note, Skip, Timing};

/// What the bring-up's log shows: with feature `defmt`, what defmt formats.
#[cfg(feature = "defmt")]
pub(crate) trait Logged: defmt::Format {}

#[cfg(feature = "defmt")]
impl<T: defmt::Format> Logged for T {}

/// What the bring-up's log shows: without feature `defmt` nothing is logged, so anything.
#[cfg(not(feature = "defmt"))]
pub(crate) trait Logged {}

#[cfg(not(feature = "defmt"))]
impl<T> Logged for T {}

/// A generation's bring-up as [`bring_up`] runs it, implemented by its `Plan` over its `Link`:
/// what its checks do. Each function is one check (or, where it says so, the checks it notes
/// itself) on a [`Run`]; the sequence notes the start and end of the others.
#[maybe_async::maybe_async(AFIT)]
pub(crate) trait Sequence<L: Common>: Sized {
    /// What a passed bring-up measured.
    type Report: Default + Logged;
    /// Why a check failed (a driver error is one).
    type Why: From<LinkError> + Logged;
    /// What the link check counts while it listens.
    type Counts: Default;
    /// What the log says after "bring-up" and "passed" to name the generation (nothing on
    /// 2020, " (v1.0.0)" on v1.0.0).
    const NAMED: &'static str;
    /// What the log calls [`Common::stop`].
    const STOP: &'static str;
    /// The checks that move, in order, noted as skipped when the plan has no motion (the
    /// control loop is not among them: it is skipped after the battery, where it would run).
    const MOVING: &'static [Check];

    /// The timing the plan holds.
    fn timing(&self) -> &Timing;
    /// [`Check::Link`]: what `event` adds to `counts` while listening.
    fn count(counts: &mut Self::Counts, event: L::Event);
    /// [`Check::Link`]: the verdict on `counts`, taken in `elapsed_ms`.
    fn link(
        run: &mut Run<'_, L, Self>,
        counts: Self::Counts,
        elapsed_ms: u64,
    ) -> Result<(), Failure<Self::Why>>;
    /// [`Check::Settings`].
    async fn settings(run: &mut Run<'_, L, Self>) -> Result<(), Failure<Self::Why>>;
    /// What comes before the first motion, with the checks it notes itself (2020: a turn left
    /// pending cancelled, [`Check::DriveType`]); nothing by default.
    async fn before_motion(run: &mut Run<'_, L, Self>) -> Result<(), Failure<Self::Why>> {
        let _ = run;
        Ok(())
    }
    /// [`Check::Forward`] and [`Check::Strafe`], noted by it (either may be skipped).
    async fn straight(run: &mut Run<'_, L, Self>) -> Result<(), Failure<Self::Why>>;
    /// [`Check::Turn`].
    async fn turn(run: &mut Run<'_, L, Self>) -> Result<(), Failure<Self::Why>>;
    /// [`Check::Stop`], noted by it (it may be skipped).
    async fn stop(run: &mut Run<'_, L, Self>) -> Result<(), Failure<Self::Why>>;
    /// [`Check::Battery`].
    async fn battery(run: &mut Run<'_, L, Self>) -> Result<(), Failure<Self::Why>>;
    /// [`Check::ControlLoop`].
    async fn control_loop(run: &mut Run<'_, L, Self>) -> Result<(), Failure<Self::Why>>;
    /// What the report says of the whole bring-up once every check passed.
    fn tally(run: &mut Run<'_, L, Self>);
}

/// What every check works on: the link, the plan, the report it fills in, and the failsafe
/// stops the driver had counted once the settings were read (the checks that move must end
/// with no more).
pub(crate) struct Run<'a, L: Common, P: Sequence<L>> {
    /// The driver.
    pub(crate) link: &'a mut L,
    /// What to do.
    pub(crate) plan: &'a P,
    /// What was measured so far.
    pub(crate) report: P::Report,
    /// The failsafe stops before the first motion.
    pub(crate) failsafe_before: u32,
}

/// Writes a generation's public `bring_up` (its documentation given) and `bring_up_and_park`
/// in its module, over its `Link`, `Plan`, `Report` and `Failure`: both are the sequence's.
macro_rules! entry_points {
    ($(#[$bring_up_doc:meta])*) => {
        $(#[$bring_up_doc])*
        #[maybe_async::maybe_async]
        pub async fn bring_up<L: Link>(link: &mut L, plan: &Plan) -> Result<Report, Failure> {
            crate::sequence::bring_up(link, plan).await
        }

        /// What a board on real hardware does: runs the bring-up, logs its verdict, then keeps
        /// reading telemetry for ever (the chassis stopped, so the failsafe has nothing to do).
        #[maybe_async::maybe_async]
        pub async fn bring_up_and_park<L: Link>(link: &mut L, plan: &Plan) -> ! {
            crate::sequence::bring_up_and_park(link, plan).await
        }
    };
}
pub(crate) use entry_points;

/// Runs the whole bring-up of `plan`'s generation on `link`. On a failure the chassis is
/// stopped (best effort, if the plan moves it) and the failed check returned.
#[maybe_async::maybe_async]
pub(crate) async fn bring_up<L, P>(link: &mut L, plan: &P) -> Result<P::Report, Failure<P::Why>>
where
    L: Common<Core: Generation>,
    P: Sequence<L>,
{
    let result = steps(link, plan).await;
    if let Err(failure) = &result {
        log!(
            error,
            "bring-up{=str}: {} failed: {}",
            P::NAMED,
            failure.check,
            failure.why
        );
        // Without motion nothing was set moving: nothing but reads is sent.
        if plan.timing().motion {
            if let Err(e) = link.stop().await {
                log!(error, "{=str} after the failure: {}", P::STOP, e);
            }
        }
    }
    result
}

/// Runs the bring-up, logs its verdict, then keeps reading telemetry for ever.
#[maybe_async::maybe_async]
pub(crate) async fn bring_up_and_park<L, P>(link: &mut L, plan: &P) -> !
where
    L: Common<Core: Generation>,
    P: Sequence<L>,
{
    match bring_up(link, plan).await {
        Ok(report) => log!(info, "PASS: every check passed{=str}: {}", P::NAMED, report),
        Err(failure) => log!(error, "FAIL: {} ({})", failure.check, failure.why),
    }
    crate::link::park(link).await
}

/// The checks in their order; without motion, those that move are skipped.
#[maybe_async::maybe_async]
async fn steps<L, P>(link: &mut L, plan: &P) -> Result<P::Report, Failure<P::Why>>
where
    L: Common<Core: Generation>,
    P: Sequence<L>,
{
    let mut run = Run {
        link,
        plan,
        report: P::Report::default(),
        failsafe_before: 0,
    };
    run.link.note(Note::Start(Check::Link));
    listen_to_link(&mut run).await?;
    run.link.note(Note::Passed(Check::Link));
    run.link.note(Note::Start(Check::Settings));
    P::settings(&mut run).await?;
    run.link.note(Note::Passed(Check::Settings));
    run.failsafe_before = run.link.core().failsafe_stops();
    let motion = plan.timing().motion;
    if motion {
        P::before_motion(&mut run).await?;
        P::straight(&mut run).await?;
        run.link.note(Note::Start(Check::Turn));
        P::turn(&mut run).await?;
        run.link.note(Note::Passed(Check::Turn));
        P::stop(&mut run).await?;
    } else {
        for check in P::MOVING {
            run.link.note(Note::Skipped(*check, Skip::NoMotion));
        }
    }
    run.link.note(Note::Start(Check::Battery));
    P::battery(&mut run).await?;
    run.link.note(Note::Passed(Check::Battery));
    if motion {
        run.link.note(Note::Start(Check::ControlLoop));
        P::control_loop(&mut run).await?;
        run.link.note(Note::Passed(Check::ControlLoop));
    } else {
        run.link
            .note(Note::Skipped(Check::ControlLoop, Skip::NoMotion));
    }
    P::tally(&mut run);
    Ok(run.report)
}

/// [`Check::Link`]: telemetry taken in for the plan's listening time, each event counted, then
/// the generation's verdict.
#[maybe_async::maybe_async]
async fn listen_to_link<L, P>(run: &mut Run<'_, L, P>) -> Result<(), Failure<P::Why>>
where
    L: Common,
    P: Sequence<L>,
{
    let listen_ms = run.plan.timing().listen_ms;
    log!(info, "[link] listening to telemetry for {} ms", listen_ms);
    let mut counts = P::Counts::default();
    let elapsed = listen(run.link, listen_ms, |event| P::count(&mut counts, event)).await;
    let elapsed = elapsed.map_err(Failure::<P::Why>::driver(Check::Link))?;
    P::link(run, counts, elapsed)
}
