//! The parts of the `chassis` tool that other programs on the same board reuse (the
//! `chassis-ros2` node): how a port is opened and which firmware it runs ([`connect`],
//! [`port`]), how a command learns it must end ([`ending`]) and how the chassis is stopped on
//! the way out, saying only what is known ([`stopping`]). The `chassis` binary is built on
//! them; with `default-features = false` this library pulls in none of its terminal
//! dependencies.

/// `println!` that never panics: a closed pipe (`| head`) or a full disk on standard output
/// must not end a command that may be driving the chassis. The command goes on, and its exit
/// status stands.
#[macro_export]
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}

/// `eprintln!` that never panics (as [`say!`]).
#[macro_export]
macro_rules! tell {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($t)*);
    }};
}

/// `eprint!` that never panics, flushed (a question before an answer).
#[macro_export]
macro_rules! tell_partial {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let mut err = std::io::stderr();
        let _ = write!(err, $($t)*);
        let _ = err.flush();
    }};
}

pub mod connect;
pub mod ending;
pub mod newfile;
pub mod port;
pub mod stopping;
