//! What a driver core keeps of the telemetry it hears: each value with its time, and each
//! stream's count and rate.

/// A value and the time the driver received it.
///
/// The time is when the bytes reached the core, on the core's clock
/// ([`DriverCore::now_ms`](super::DriverCore::now_ms): your clock's readings while it runs
/// forward, and monotonic whatever it does): the arrival
/// time when a runner or an interrupt feeds the core as bytes come, the time of the read when a
/// slow loop reads a batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stamped<T> {
    /// The value.
    pub value: T,
    /// When it was received, in ms.
    pub at_ms: u64,
}

/// What the driver knows of one telemetry stream.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StreamInfo {
    /// Frames received.
    pub frames: u32,
    /// Frames missing according to the count bytes.
    pub missed: u32,
    /// Frames per second over the last window of at least [`StreamInfo::WINDOW_MS`], in
    /// thousandths (0 until a window has closed).
    pub rate_millihertz: u32,
    window_start_ms: Option<u64>,
    window_frames: u32,
}

impl StreamInfo {
    /// The rate is counted over windows at least this long, so that frames read in batches (a
    /// slow loop, a USB-UART) still give the stream's real rate.
    pub const WINDOW_MS: u64 = 1_000;

    /// Frames per second (rounded down; 0 until a window has closed).
    #[must_use]
    pub const fn rate_hz(&self) -> u32 {
        self.rate_millihertz / 1_000
    }

    /// Nothing received yet.
    pub(crate) const fn new() -> Self {
        StreamInfo {
            frames: 0,
            missed: 0,
            rate_millihertz: 0,
            window_start_ms: None,
            window_frames: 0,
        }
    }

    pub(crate) fn arrived(&mut self, at_ms: u64, missed: u32) {
        self.frames = self.frames.wrapping_add(1);
        self.missed = missed;
        let Some(start) = self.window_start_ms else {
            self.window_start_ms = Some(at_ms);
            return;
        };
        self.window_frames = self.window_frames.saturating_add(1);
        let span = at_ms.saturating_sub(start);
        if span >= Self::WINDOW_MS {
            // In 32 bits (a Cortex-M divides those in hardware; 64-bit division is a library
            // routine): a window closes at its first frame after a second, so it never holds
            // the 4 295 frames that would saturate.
            let span = u32::try_from(span).unwrap_or(u32::MAX);
            self.rate_millihertz = self
                .window_frames
                .saturating_mul(1_000_000)
                .checked_div(span)
                .unwrap_or(0);
            self.window_start_ms = Some(at_ms);
            self.window_frames = 0;
        }
    }
}
