//! Output files that are either complete or untouched: every command that writes a file
//! (`check`, `build`, `render`, `quilt`, `eval --plot`, `simulate --trace`, `man`) writes
//! through [`write_file`].

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Writes `path` with `write`: into a temporary file beside it, flushed and synced, then
/// renamed onto `path`. On any error (or a panic) the temporary file is removed and `path`
/// keeps what it held before. A symbolic link is followed (the file it points to is
/// replaced, keeping its permissions); a `path` that exists and is not a regular file (a
/// device such as `/dev/stdout`, a FIFO) is written directly: it cannot be replaced.
///
/// # Errors
/// The error of `write`, or of creating, writing, syncing or renaming the file, naming it.
pub fn write_file(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), String>,
) -> Result<(), String> {
    let shown = path.display();
    if path.metadata().is_ok_and(|m| !m.is_file()) {
        let mut out = BufWriter::new(File::create(path).map_err(|e| format!("{shown}: {e}"))?);
        write(&mut out)?;
        return out.flush().map_err(|e| format!("{shown}: {e}"));
    }
    let resolved;
    let path = if path.symlink_metadata().is_ok_and(|m| m.file_type().is_symlink()) {
        resolved = std::fs::canonicalize(path).map_err(|e| format!("{shown}: {e}"))?;
        resolved.as_path()
    } else {
        path
    };
    let temp = Temporary::create(path)?;
    if let Ok(m) = path.metadata() {
        temp.file.set_permissions(m.permissions()).map_err(|e| format!("{shown}: {e}"))?;
    }
    let mut out = BufWriter::with_capacity(
        1 << 16,
        temp.file.try_clone().map_err(|e| format!("{shown}: {e}"))?,
    );
    write(&mut out)?;
    out.flush().map_err(|e| format!("{shown}: {e}"))?;
    drop(out);
    temp.file.sync_all().map_err(|e| format!("{shown}: {e}"))?;
    temp.rename_onto(path)
}

/// A temporary file beside the target, removed when dropped unless renamed.
struct Temporary {
    path: PathBuf,
    file: File,
    keep: bool,
}

impl Temporary {
    fn create(target: &Path) -> Result<Temporary, String> {
        let name =
            target.file_name().ok_or_else(|| format!("{}: not a file name", target.display()))?;
        let dir = target.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let mut last = None;
        for attempt in 0..100u32 {
            let mut temp_name = std::ffi::OsString::from(".");
            temp_name.push(name);
            temp_name.push(format!(".partial-{}-{attempt}", std::process::id()));
            let path = dir.join(temp_name);
            match File::options().write(true).create_new(true).open(&path) {
                Ok(file) => return Ok(Temporary { path, file, keep: false }),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last = Some(e),
                Err(e) => {
                    return Err(format!(
                        "{}: cannot create a file beside it: {e}",
                        target.display()
                    ))
                }
            }
        }
        Err(format!("{}: no free temporary name beside it ({last:?})", target.display()))
    }

    fn rename_onto(mut self, target: &Path) -> Result<(), String> {
        std::fs::rename(&self.path, target).map_err(|e| format!("{}: {e}", target.display()))?;
        self.keep = true;
        Ok(())
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if !self.keep {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("dc-files-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(d: &Path) -> Vec<String> {
        let mut n: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        n.sort();
        n
    }

    #[test]
    fn an_error_leaves_the_old_file_and_no_temporary() {
        let d = dir("error");
        let target = d.join("out.csv");
        std::fs::write(&target, "old").unwrap();
        let r = write_file(&target, |w| {
            w.write_all(b"half of the new").unwrap();
            Err("row 3 is bad".into())
        });
        assert_eq!(r, Err("row 3 is bad".to_string()));
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old");
        assert_eq!(names(&d), ["out.csv"]);
        write_file(&target, |w| w.write_all(b"new").map_err(|e| e.to_string())).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        assert_eq!(names(&d), ["out.csv"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_stays_a_link_to_the_new_file() {
        let d = dir("link");
        let (real, link) = (d.join("real.dct"), d.join("link.dct"));
        std::fs::write(&real, "old").unwrap();
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_file(&link, |w| w.write_all(b"new").map_err(|e| e.to_string())).unwrap();
        assert!(link.symlink_metadata().unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        assert_eq!(names(&d), ["link.dct", "real.dct"]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
