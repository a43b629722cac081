//! The shape of a chassis class, written once: [`chassis_class!`] makes a generation's class,
//! a [`Link`](super::Link) over its core, with one `#[pymethods]` block holding the methods
//! every chassis has (each a call into the link, in the words the generation gives for it)
//! and then the generation's own methods. PyO3 classes share no methods by inheritance, and a
//! class has one `#[pymethods]` block: so the macro writes that block.

/// Makes a chassis class: the struct (its `link`, which it is made `From`) and its
/// `#[pymethods]`. Given: the class's
/// docs and name, the core its link drives and its firmware's name; the words of the shared
/// methods that differ by generation (`frame`: what iterating yields, in the singular;
/// `stops`: what `close` does first; the whole docs of `stop`, `poll`, `moving`,
/// `failsafe_stops`, `streams` and `counters`); then the generation's own methods.
macro_rules! chassis_class {
    (
        $(#[$doc:meta])*
        pub struct $class:ident(Link<$core:ty>) = $firmware:literal;
        words {
            frame: $frame:literal,
            stops: $stops:literal,
            stop: $stop:literal,
            poll: $poll:literal,
            moving: $moving:literal,
            failsafe_stops: $failsafe_stops:literal,
            streams: $streams:literal,
            counters: $counters:literal $(,)?
        }
        $($own:tt)*
    ) => {
        $(#[$doc])*
        #[pyclass(module = "chassis", weakref)]
        pub struct $class {
            link: $crate::driver::Link<$core>,
        }

        impl From<$crate::driver::Link<$core>> for $class {
            fn from(link: $crate::driver::Link<$core>) -> Self {
                $class { link }
            }
        }

        #[pymethods]
        impl $class {
            #[doc = concat!("`\"", $firmware, "\"`.")]
            #[getter]
            fn firmware(&self) -> &'static str {
                $firmware
            }

            /// The serial port's path.
            #[getter]
            fn port(&self) -> &str {
                &self.link.port
            }

            #[doc = $stop]
            fn stop(&self, py: Python<'_>) -> PyResult<()> {
                self.link.stop(py)
            }

            #[doc = $poll]
            fn poll(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
                self.link.poll(py)
            }

            #[doc = concat!(
                "Waits up to `timeout` seconds (`None` or `math.inf`: for ever; negative or NaN:\n",
                "`ValueError`) for the next ", $frame, "; `None` if none came."
            )]
            #[pyo3(signature = (timeout = None))]
            fn wait_frame(
                &self,
                py: Python<'_>,
                timeout: Option<$crate::args::Real>,
            ) -> PyResult<Option<Py<PyAny>>> {
                self.link.wait_frame(py, timeout)
            }

            #[doc = concat!(
                "Iterating a chassis yields its ", $frame, "s as they come (blocking; Ctrl-C raises\n",
                "`KeyboardInterrupt`); it ends when the chassis is closed."
            )]
            fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
                slf
            }

            #[doc = concat!("The next ", $frame, " (waits for it).")]
            fn __next__(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
                self.link.next_frame(py)
            }

            /// Whether the board was heard within the failsafe time.
            #[getter]
            fn link_alive(&self) -> PyResult<bool> {
                self.link.link_alive()
            }

            #[doc = $moving]
            #[getter]
            fn moving(&self) -> PyResult<bool> {
                self.link.core(|c| $crate::driver::PyCore::moving(c))
            }

            #[doc = $failsafe_stops]
            #[getter]
            fn failsafe_stops(&self) -> PyResult<u32> {
                self.link.core(|c| $crate::driver::PyCore::failsafe_stops(c))
            }

            #[doc = $streams]
            #[getter]
            fn streams<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                self.link.streams(py)
            }

            #[doc = $counters]
            #[getter]
            fn counters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                self.link.counters(py)
            }

            #[doc = concat!($stops, " and closes the port (again: nothing).")]
            fn close(&self, py: Python<'_>) -> PyResult<()> {
                self.link.close(py)
            }

            fn __enter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
                slf
            }

            #[doc = concat!($stops, " and closes the port; an exception in the block goes on.")]
            fn __exit__(
                &self,
                py: Python<'_>,
                exc_type: Option<Bound<'_, PyAny>>,
                exc_value: Option<Bound<'_, PyAny>>,
                traceback: Option<Bound<'_, PyAny>>,
            ) -> PyResult<bool> {
                let _ = (exc_type, traceback);
                self.link.exit(py, exc_value)
            }

            fn __repr__(&self) -> String {
                format!(
                    concat!(stringify!($class), "(port={:?}, firmware=\"", $firmware, "\")"),
                    self.link.port
                )
            }

            $($own)*
        }
    };
}

pub(crate) use chassis_class;
