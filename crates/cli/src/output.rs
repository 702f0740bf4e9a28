//! Writing results: to stdout, or atomically to a file.

use std::io::Write;
use std::path::Path;

/// Writes `text` to `path` through a temporary file in the same folder and a
/// rename, so a reader never sees a half-written file.
pub fn write_atomic(path: &Path, text: &str) -> Result<(), String> {
    write_atomic_bytes(path, text.as_bytes())
}

/// [`write_atomic`] for bytes (e.g. PNG images).
pub fn write_atomic_bytes(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or_else(|| Path::new("."));
    let name = path
        .file_name()
        .ok_or_else(|| format!("{}: not a file path", path.display()))?;
    regular_target(path, dir)?;
    let tmp = dir.join(format!(
        ".{}.tmp{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: cannot write: {e}", path.display())
    })
}

/// Refuses to replace anything but a regular file (or a link to one in
/// the same folder): the rename that makes a write atomic would put a
/// regular file in place of a device node, a FIFO or a socket, and a link
/// out of the folder says the file lives elsewhere.
fn regular_target(path: &Path, dir: &Path) -> Result<(), String> {
    let Ok(meta) = std::fs::symlink_metadata(path) else {
        return Ok(());
    };
    let kind = meta.file_type();
    if kind.is_file() {
        return Ok(());
    }
    if kind.is_symlink() {
        let inside = match (std::fs::canonicalize(path), std::fs::canonicalize(dir)) {
            (Ok(target), Ok(dir)) => target.parent() == Some(dir.as_path()) && target.is_file(),
            _ => false,
        };
        if inside {
            return Ok(());
        }
        return Err(format!(
            "{}: a link that leads out of its folder (or to no file); give a plain file path",
            path.display()
        ));
    }
    let what = if kind.is_dir() {
        "a directory"
    } else {
        "not a regular file (a device, FIFO or socket)"
    };
    Err(format!(
        "{}: {what}; give a plain file path",
        path.display()
    ))
}

/// Writes `files` (name, contents) into the directory `dir` as one set: all
/// into a staging directory first (inside `dir` if it exists, so that the
/// moves stay on its file system; else beside it, and it becomes `dir`),
/// then moved in, replacing nothing but those names. A failure while
/// writing leaves `dir` as it was, never a mix of old and new files.
pub fn write_dir_atomic(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<(), String> {
    // A link to a directory is followed: the directory is the target.
    let exists = match std::fs::metadata(dir) {
        Ok(meta) if meta.is_dir() => true,
        Ok(_) => {
            return Err(format!(
                "{}: exists and is not a directory; give a directory path for --out",
                dir.display()
            ))
        }
        Err(_) => false,
    };
    let name = dir
        .file_name()
        .ok_or_else(|| format!("{}: not a directory path", dir.display()))?;
    let parent = dir
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or_else(|| Path::new("."));
    if !exists {
        std::fs::create_dir_all(parent)
            .map_err(|e| format!("{}: cannot create: {e}", parent.display()))?;
    }
    let staging_name = format!(".{}.tmp{}", name.to_string_lossy(), std::process::id());
    let staging = if exists {
        dir.join(staging_name)
    } else {
        parent.join(staging_name)
    };
    let _ = std::fs::remove_dir_all(&staging);
    let written = (|| -> Result<(), String> {
        std::fs::create_dir(&staging)
            .map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
        for (file, bytes) in files {
            // Names come from the program, never from the user.
            let target = dir.join(file);
            regular_target(&target, dir)?;
            let mut f = std::fs::File::create(staging.join(file))
                .map_err(|e| format!("{}: cannot write: {e}", target.display()))?;
            f.write_all(bytes)
                .and_then(|_| f.sync_all())
                .map_err(|e| format!("{}: cannot write: {e}", target.display()))?;
        }
        Ok(())
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_dir_all(&staging);
        return Err(e);
    }
    if !exists {
        return std::fs::rename(&staging, dir).map_err(|e| {
            let _ = std::fs::remove_dir_all(&staging);
            format!("{}: cannot create: {e}", dir.display())
        });
    }
    // Renames inside one file system: each replaces its file at once.
    for (file, _) in files {
        std::fs::rename(staging.join(file), dir.join(file)).map_err(|e| {
            let _ = std::fs::remove_dir_all(&staging);
            format!("{}: cannot write: {e}", dir.join(file).display())
        })?;
    }
    let _ = std::fs::remove_dir(&staging);
    Ok(())
}

/// Prints a report a command returned for stdout; `None` when it wrote its
/// report into an output directory instead.
pub fn emit_report(report: Option<String>) -> Result<(), String> {
    match report {
        Some(text) => emit(None, &text),
        None => Ok(()),
    }
}

/// Prints to stdout, or writes the file when `out` is given.
pub fn emit(out: Option<&Path>, text: &str) -> Result<(), String> {
    match out {
        Some(p) => write_atomic(p, text),
        None => {
            let mut so = std::io::stdout().lock();
            // A closed pipe (e.g. `| head`) is not an error worth reporting.
            match so.write_all(text.as_bytes()).and_then(|_| so.flush()) {
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
                r => r.map_err(|e| format!("stdout: {e}")),
            }
        }
    }
}
