//! The command line both noise sweeps take (`noise-sweep`, the 2020 parser's, and the example
//! `v1_sweep`, the v1.0.0 board → master parser's): `--seed N` and `--frames N`, `_` allowed
//! between digits.

/// What a sweep was asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Args {
    /// The seed of the streams and the lines (2026 unless given: the one the figures quote).
    pub seed: u64,
    /// Frames per row (1 000 000 unless given).
    pub frames: usize,
}

impl Args {
    /// The process's arguments; on a wrong one, or `--help`, the message (`usage` for `--help`)
    /// is printed after `program` on stderr, and `None` returned.
    pub fn from_env(program: &str, usage: &str) -> Option<Args> {
        Args::from_env_with(program, usage, Args::DEFAULT)
    }

    /// [`from_env`](Self::from_env), with other defaults.
    pub fn from_env_with(program: &str, usage: &str, defaults: Args) -> Option<Args> {
        Args::parse_with(std::env::args().skip(1), usage, defaults)
            .inspect_err(|message| eprintln!("{program}: {message}"))
            .ok()
    }

    /// The defaults: seed 2026, 1 000 000 frames.
    pub const DEFAULT: Args = Args {
        seed: 2026,
        frames: 1_000_000,
    };

    /// `args` (without the program's name); `usage` is the error for `-h` or `--help`.
    pub fn parse(args: impl IntoIterator<Item = String>, usage: &str) -> Result<Args, String> {
        Args::parse_with(args, usage, Args::DEFAULT)
    }

    /// [`parse`](Self::parse), with other defaults.
    pub fn parse_with(
        args: impl IntoIterator<Item = String>,
        usage: &str,
        defaults: Args,
    ) -> Result<Args, String> {
        let mut parsed = defaults;
        let mut it = args.into_iter();
        while let Some(flag) = it.next() {
            let mut value = |name: &str| {
                it.next()
                    .ok_or_else(|| format!("{name} needs a value"))?
                    .replace('_', "")
                    .parse::<u64>()
                    .map_err(|e| format!("{name}: {e}"))
            };
            match flag.as_str() {
                "--seed" => parsed.seed = value("--seed")?,
                "--frames" => {
                    parsed.frames =
                        usize::try_from(value("--frames")?).map_err(|e| e.to_string())?
                }
                "-h" | "--help" => return Err(usage.to_string()),
                other => return Err(format!("unknown argument {other:?}; try --help")),
            }
        }
        if parsed.frames == 0 {
            return Err("--frames must be at least 1".to_string());
        }
        Ok(parsed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(args: &[&str]) -> Result<Args, String> {
        Args::parse(args.iter().map(|a| a.to_string()), "usage")
    }

    #[test]
    fn defaults_flags_in_either_order_and_the_errors() {
        let defaults = Args {
            seed: 2026,
            frames: 1_000_000,
        };
        assert_eq!(parse(&[]), Ok(defaults));
        let asked = Args {
            seed: 7,
            frames: 30_000,
        };
        assert_eq!(parse(&["--frames", "30_000", "--seed", "7"]), Ok(asked));
        assert_eq!(parse(&["--seed", "7", "--frames", "30000"]), Ok(asked));
        assert_eq!(parse(&["--help"]), Err("usage".to_string()));
        assert_eq!(parse(&["--seed"]), Err("--seed needs a value".to_string()));
        assert_eq!(
            parse(&["--frames", "0"]),
            Err("--frames must be at least 1".to_string())
        );
        assert_eq!(
            parse(&["-x"]),
            Err("unknown argument \"-x\"; try --help".to_string())
        );
    }
}
