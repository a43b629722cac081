//! The driver under the bring-up, for both generations and both shells.
//!
//! [`Common`] is what both generations' bring-ups need of a driver (the clock, the core,
//! telemetry in, the stop, progress notes); each generation's `Link` adds its own calls
//! ([`v2020::Link`](crate::v2020::Link), [`v1::Link`](crate::v1::Link)).
//!
//! `Blocking` (feature `blocking`) wraps the blocking driver (any HAL with embedded-io 0.7
//! `Read + Write + ReadReady`, or embedded-hal-nb serial through `NbSerial`); `Async`
//! (feature `async`) wraps the async one (embassy's `BufferedUart`). With `blocking`, the
//! links' calls are plain functions and the bring-up is plain blocking code: no executor, no
//! future. Both take the driver's core as a parameter `K`, as the driver does, and implement
//! [`Common`] for either; each generation names them over its own core (`v2020::Blocking`,
//! `v1::Blocking`, `v2020::Async`, `v1::Async`: made with `new`) and implements its `Link` on
//! them.

use crate::Note;
#[cfg(any(feature = "blocking", feature = "async"))]
use chassis_protocol::driver::Clock;
use chassis_protocol::driver::{Config, Core, DriverCore, Error};

/// A driver error with its transport error reduced to its kind, so that one bring-up serves
/// every HAL.
pub type LinkError = Error<embedded_io::ErrorKind>;

#[cfg(any(feature = "blocking", feature = "async"))]
pub(crate) fn kind<E: embedded_io::Error>(e: Error<E>) -> LinkError {
    e.map_transport(|e| e.kind())
}

/// The calls both generations' bring-ups make; each is the driver call of the same name. Each
/// generation's `Link` has these and adds its own.
///
/// `async` (the futures are not `Send`: a bring-up runs on one core, in one task), or plain
/// functions with feature `blocking`.
#[allow(async_fn_in_trait)]
#[maybe_async::maybe_async(AFIT)]
pub trait Common {
    /// The driver's sans-IO core: [`DriverCore`] on 2020, `driver::v1::DriverCore` on v1.0.0.
    type Core;
    /// What the core says it saw (its `Event`: telemetry, a reply nobody awaited…).
    type Event;
    /// Milliseconds since boot (the driver's clock).
    fn now_ms(&mut self) -> u64;
    /// The driver's sans-IO core: latest telemetry, parser counters, failsafe stops.
    fn core(&self) -> &Self::Core;
    /// Takes in what has arrived; the blocking shell returns at once, the async one waits a
    /// little for bytes.
    async fn poll(&mut self) -> Result<Option<Self::Event>, LinkError>;
    /// The generation's stop: on 2020 a stop (and a turn in progress cancelled), on v1.0.0
    /// the forced stop.
    async fn stop(&mut self) -> Result<(), LinkError>;
    /// What the bring-up is doing (a check starts, passes, is skipped): for a program that
    /// shows its progress. Does nothing unless implemented.
    fn note(&mut self, note: Note) {
        let _ = note;
    }
}

/// A firmware generation's driver core, as the wrappers make it from a [`Config`] and as the
/// bring-up reads it: [`DriverCore`] (2020) and `driver::v1::DriverCore` (v1.0.0). Sealed.
pub trait Generation: Core + sealed::Sealed {
    /// A new core with `config` (what the driver's own constructor makes).
    fn with_config(config: Config) -> Self;
    /// How many times the driver's failsafe has stopped the chassis (the core's own
    /// `failsafe_stops`).
    fn failsafe_stops(&self) -> u32;
}

impl Generation for DriverCore {
    fn with_config(config: Config) -> Self {
        DriverCore::new(config)
    }
    fn failsafe_stops(&self) -> u32 {
        DriverCore::failsafe_stops(self)
    }
}

impl Generation for chassis_protocol::driver::v1::DriverCore {
    fn with_config(config: Config) -> Self {
        chassis_protocol::driver::v1::DriverCore::new(config)
    }
    fn failsafe_stops(&self) -> u32 {
        chassis_protocol::driver::v1::DriverCore::failsafe_stops(self)
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for chassis_protocol::driver::DriverCore {}
    impl Sealed for chassis_protocol::driver::v1::DriverCore {}
}

/// The blocking driver under a bring-up (feature `blocking`; the clock is copied: it must be
/// a handle, as a SysTick counter or `embassy_time` are). `K` is the driver's core: each
/// generation names this wrapper over its own ([`v2020::Blocking`](crate::v2020::Blocking),
/// [`v1::Blocking`](crate::v1::Blocking)).
#[cfg(feature = "blocking")]
pub struct Blocking<U, C, K> {
    pub(crate) driver: chassis_protocol::driver::blocking::Driver<U, C, K>,
    pub(crate) clock: C,
}

#[cfg(feature = "blocking")]
impl<U, C, K> Blocking<U, C, K>
where
    U: embedded_io::Read + embedded_io::Write + embedded_io::ReadReady,
    C: Clock + Clone,
    K: Generation,
{
    /// Wraps a new blocking driver for `K`'s generation over `uart` (the v1.0.0 driver's
    /// failsafe at least
    /// [`MIN_FAILSAFE_MS`](chassis_protocol::driver::v1::MIN_FAILSAFE_MS)).
    pub fn new(uart: U, clock: C, config: Config) -> Self {
        let core = K::with_config(config);
        let driver =
            chassis_protocol::driver::blocking::Driver::from_core(uart, clock.clone(), core);
        Blocking { driver, clock }
    }
}

#[cfg(feature = "blocking")]
impl<U, C, K> Blocking<U, C, K> {
    /// Wraps a blocking driver already made (opened on a PC's serial port, say); `clock` is
    /// a copy of its clock.
    pub const fn from_driver(
        driver: chassis_protocol::driver::blocking::Driver<U, C, K>,
        clock: C,
    ) -> Self {
        Blocking { driver, clock }
    }

    /// The driver, for what the bring-up does not use.
    pub fn driver(&mut self) -> &mut chassis_protocol::driver::blocking::Driver<U, C, K> {
        &mut self.driver
    }

    /// The driver back.
    pub fn into_driver(self) -> chassis_protocol::driver::blocking::Driver<U, C, K> {
        self.driver
    }
}

/// The async driver under a bring-up (feature `async`). `K` is the driver's core: each
/// generation names this wrapper over its own ([`v2020::Async`](crate::v2020::Async),
/// [`v1::Async`](crate::v1::Async)).
#[cfg(feature = "async")]
pub struct Async<U, C, D, K> {
    pub(crate) driver: chassis_protocol::driver::asynch::Driver<U, C, D, K>,
    pub(crate) clock: C,
}

#[cfg(feature = "async")]
impl<U, C, D, K> Async<U, C, D, K>
where
    U: embedded_io_async::Read + embedded_io_async::Write,
    C: Clock + Clone,
    D: embedded_hal_async::delay::DelayNs,
    K: Generation,
{
    /// Wraps a new async driver for `K`'s generation over `uart` (the v1.0.0 driver's
    /// failsafe at least
    /// [`MIN_FAILSAFE_MS`](chassis_protocol::driver::v1::MIN_FAILSAFE_MS)).
    pub fn new(uart: U, clock: C, delay: D, config: Config) -> Self {
        let core = K::with_config(config);
        let driver =
            chassis_protocol::driver::asynch::Driver::from_core(uart, clock.clone(), delay, core);
        Async { driver, clock }
    }
}

#[cfg(feature = "async")]
impl<U, C, D, K> Async<U, C, D, K> {
    /// The driver, for what the bring-up does not use.
    pub fn driver(&mut self) -> &mut chassis_protocol::driver::asynch::Driver<U, C, D, K> {
        &mut self.driver
    }
}

/// Implements a trait on each shell the build has, over the driver core `$core`, from one
/// text: on `Blocking` (feature `blocking`), where `maybe-async` makes the text blocking (no
/// `async`, no `.await`), and on `Async` (feature `async`), as written. `<K: Bound>` first
/// makes the core a parameter. The implementations reach the driver as `self.driver` and its
/// errors through `kind`.
macro_rules! impl_on_shells {
    ($(<$k:ident: $bound:path>)? $tr:path, core $core:ty, { $($body:tt)* }) => {
        #[cfg(feature = "blocking")]
        #[maybe_async::maybe_async(AFIT)]
        impl<U, C $(, $k)?> $tr for $crate::link::Blocking<U, C, $core>
        where
            U: embedded_io::Read + embedded_io::Write + embedded_io::ReadReady,
            C: chassis_protocol::driver::Clock + Clone,
            $($k: $bound,)?
        {
            $($body)*
        }

        #[cfg(feature = "async")]
        #[maybe_async::maybe_async(AFIT)]
        impl<U, C, D $(, $k)?> $tr for $crate::link::Async<U, C, D, $core>
        where
            U: embedded_io_async::Read + embedded_io_async::Write,
            C: chassis_protocol::driver::Clock + Clone,
            D: embedded_hal_async::delay::DelayNs,
            $($k: $bound,)?
        {
            $($body)*
        }
    };
}
#[cfg(any(feature = "blocking", feature = "async"))]
pub(crate) use impl_on_shells;

impl_on_shells!(<K: Core> Common, core K, {
    type Core = K;
    type Event = K::Event;
    fn now_ms(&mut self) -> u64 {
        self.clock.now_ms()
    }
    fn core(&self) -> &K {
        self.driver.core()
    }
    async fn poll(&mut self) -> Result<Option<K::Event>, LinkError> {
        self.driver.poll().await.map_err(kind)
    }
    async fn stop(&mut self) -> Result<(), LinkError> {
        self.driver.stop().await.map_err(kind)
    }
});

/// Takes telemetry in for `ms`, every event to `take`; how long that took, ms.
#[maybe_async::maybe_async]
pub(crate) async fn listen<L: Common>(
    link: &mut L,
    ms: u64,
    mut take: impl FnMut(L::Event),
) -> Result<u64, LinkError> {
    let start = link.now_ms();
    while link.now_ms().saturating_sub(start) < ms {
        if let Some(event) = link.poll().await? {
            take(event);
        }
    }
    Ok(link.now_ms().saturating_sub(start))
}

/// What a board on real hardware does once its bring-up is over: reads telemetry for ever
/// (the chassis stopped, so the failsafe has nothing to do).
#[maybe_async::maybe_async]
pub(crate) async fn park<L: Common>(link: &mut L) -> ! {
    loop {
        if let Err(e) = link.poll().await {
            log!(warn, "link: {}", e);
        }
    }
}
