//! A file written beside its final path and moved there once complete: a command that fails
//! (a port that does not open, a board that never answers) leaves what was at the path as it
//! was. A path that is no regular file (`/dev/stdout`, a pipe) is written directly.

use std::fs::File;
use std::path::{Path, PathBuf};

/// A file being written; [`commit`](NewFile::commit) puts it in place, dropping it without
/// throws the partial file away.
#[derive(Debug)]
pub struct NewFile {
    file: File,
    path: String,
    /// Where it is written until it is complete (`None`: written in place).
    partial: Option<PathBuf>,
}

impl NewFile {
    /// The path it will have.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Starts writing `path`: fails at once if it cannot be written (a missing folder).
    pub fn create(path: &str) -> Result<NewFile, String> {
        let cannot = |e: std::io::Error| format!("cannot write {path}: {e}");
        let special = std::fs::metadata(path).is_ok_and(|m| !m.is_file());
        if special {
            return Ok(NewFile {
                file: File::create(path).map_err(cannot)?,
                path: path.to_string(),
                partial: None,
            });
        }
        let target = Path::new(path);
        let name = target
            .file_name()
            .ok_or_else(|| format!("cannot write {path}: it names no file"))?;
        let mut partial_name = std::ffi::OsString::from(".");
        partial_name.push(name);
        partial_name.push(".partial");
        let partial = target.with_file_name(partial_name);
        Ok(NewFile {
            file: File::create(&partial).map_err(cannot)?,
            path: path.to_string(),
            partial: Some(partial),
        })
    }

    /// Puts the complete file at its path (replacing what was there).
    pub fn commit(mut self) -> Result<(), String> {
        let Some(partial) = self.partial.take() else {
            return Ok(());
        };
        let result = self
            .file
            .sync_all()
            .and_then(|()| std::fs::rename(&partial, &self.path));
        if result.is_err() {
            let _ = std::fs::remove_file(&partial);
        }
        result.map_err(|e| format!("cannot write {}: {e}", self.path))
    }
}

impl std::io::Write for NewFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.file.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

impl Drop for NewFile {
    fn drop(&mut self) {
        if let Some(partial) = self.partial.take() {
            let _ = std::fs::remove_file(partial);
        }
    }
}

/// `json` written to `out` (then put in place; "saved to PATH" on stderr), or to stdout.
pub fn put_json(out: Option<NewFile>, json: &str) -> Result<(), String> {
    match out {
        Some(mut file) => {
            use std::io::Write as _;
            let path = file.path().to_string();
            writeln!(file, "{json}").map_err(|e| format!("cannot write {path}: {e}"))?;
            file.commit()?;
            tell!("saved to {path}");
        }
        None => say!("{json}"),
    }
    Ok(())
}
