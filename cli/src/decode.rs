//! `chassis decode`: a capture's frames as JSON Lines (or text), a summary on stderr. The
//! capture's firmware generation is found by the decoder ([`chassis_capture`]) unless
//! `--firmware` gives it.

use chassis_capture as capture;
use chassis_protocol::detect::Firmware;
use clap::Args;
use std::io::Write as _;

/// `chassis decode`'s arguments.
#[derive(Debug, Args)]
pub struct DecodeArgs {
    /// The capture file ("-" or nothing: standard input).
    pub file: Option<String>,
    /// The master → board direction.
    #[arg(long)]
    pub uplink: bool,
    /// The master → board side of the same capture (both sides time-stamped: --input
    /// saleae-csv). Its reads tell the board side's parser which reply is awaited, as the
    /// driver does; the frames of both sides come out in time order, each with "from".
    #[arg(long, value_name = "FILE", conflicts_with = "uplink")]
    pub master: Option<String>,
    /// Both sides in one Saleae Logic 2 export: the rows of the analyser named NAME are
    /// the master → board side, the others the board's (as --master FILE).
    #[arg(
        long,
        value_name = "NAME",
        conflicts_with_all = ["uplink", "master"]
    )]
    pub master_analyzer: Option<String>,
    /// How the capture is written.
    #[arg(long, value_enum, default_value = "raw")]
    pub input: capture::Input,
    /// How frames are written.
    #[arg(long, value_enum, default_value = "json")]
    pub format: capture::Format,
    /// A gap in the time stamps longer than MS is a quiet line (a logic analyser's capture:
    /// 2; a `chassis record` capture, stamped when the host read the bytes: 40, as the host
    /// driver judges).
    #[arg(long, value_name = "MS", default_value = "2")]
    pub quiet_ms: f64,
}

/// `chassis decode`.
pub fn run(args: &DecodeArgs, firmware: Option<Firmware>) -> Result<(), String> {
    if !(args.quiet_ms > 0.0 && args.quiet_ms <= 60_000.0) {
        return Err(format!(
            "--quiet-ms: {} is out of range (above 0, up to 60000)",
            args.quiet_ms
        ));
    }
    let quiet = Some(args.quiet_ms / 1000.0);
    let file = args.file.as_deref();
    if args.master.is_some()
        && (args.master.as_deref() == Some("-") || file.is_none_or(|f| f == "-"))
    {
        return Err("--master: give both sides as files (standard input is one stream)".into());
    }
    if args.master_analyzer.is_some() && args.input != capture::Input::SaleaeCsv {
        return Err(
            "--master-analyzer reads a Saleae Logic 2 export: give --input saleae-csv".into(),
        );
    }
    let data = read_input(file)?;
    if let Some(name) = &args.master_analyzer {
        let (mut board, mut master) = capture::parse_saleae_sides(&data, name)?;
        board.quiet_s = quiet;
        master.quiet_s = quiet;
        let decoded = capture::decode_both(&board, &master, firmware)?;
        return write_decoded(&decoded, args.format);
    }
    let mut board = capture::read_capture(&data, args.input)?;
    board.quiet_s = quiet;
    let decoded = match &args.master {
        Some(path) => {
            let mut master = capture::read_capture(&read_input(Some(path))?, args.input)?;
            master.quiet_s = quiet;
            capture::decode_both(&board, &master, firmware)?
        }
        None => capture::decode(&board, args.uplink, firmware),
    };
    write_decoded(&decoded, args.format)
}

/// Writes the frames found, one per line, and the summary on stderr.
fn write_decoded(decoded: &capture::Decoded, format: capture::Format) -> Result<(), String> {
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let mut written = Ok(());
    for found in &decoded.frames {
        let line = match format {
            capture::Format::Json => found.json.to_string(),
            capture::Format::Text => found.text.clone(),
        };
        written = writeln!(out, "{line}");
        if written.is_err() {
            break;
        }
    }
    if written.is_ok() {
        written = out.flush();
    }
    match written {
        // A closed pipe (`| head`): the reader has what it wanted.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(format!("standard output: {e}")),
        Ok(()) => {
            tell!("chassis decode: {}", decoded.summary);
            Ok(())
        }
    }
}

/// The bytes of a capture (`None` or "-": standard input), at most [`crate::input::CAPTURE_MAX`].
fn read_input(file: Option<&str>) -> Result<Vec<u8>, String> {
    crate::input::read(file, crate::input::CAPTURE_MAX, "capture")
}
