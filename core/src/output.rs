//! Every file lensview writes (PNG renders, plots and screenshots, CSV
//! tables, saved scenes) goes through [`write_with`] / [`write_file`]:
//!
//! - the bytes go to a temporary file with a unique random name
//!   (`.NAME.XXXXXX.tmp`), created exclusively (`O_EXCL`) in the target's
//!   directory, so no existing file or symbolic link at any name is followed
//!   or overwritten on the way;
//! - it is flushed to disk and renamed over the target only when complete,
//!   so the target holds either its old content or the whole new one;
//! - it is removed on every failure, on unwinding, and on Ctrl-C, SIGTERM
//!   or SIGHUP (when the command installed [`remove_temp_files_on_interrupt`]);
//! - only a regular file (or nothing) is replaced: a directory, a device, a
//!   FIFO or a socket at the path is refused with an error naming it.
//!   A symbolic link whose final target is a regular file writes that
//!   target (the link stays a link, as editors do); a link to anything else,
//!   or to nothing, is refused;
//! - a file with more than one hard link is refused: renaming over one name
//!   would leave the others with the old content (the link silently split),
//!   and writing in place instead would lose the guarantee that the target
//!   holds its old or its whole new content (a crash half-way would corrupt
//!   every name). Removing the other links, or writing to a new name, is the
//!   user's choice to make;
//! - [`write_all`] writes several files as one: all are filled and flushed
//!   before the first is renamed, so a failure in any leaves every target
//!   as it was.
//!
//! A replaced file keeps its permissions; a new one gets 0666 less the umask,
//! as a plain create would.

use crate::files::kind;
use std::fs::Permissions;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// Temporary files being written now, for the Ctrl-C handler.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Why a write failed: one line naming the path. Nothing was left behind and
/// the target (if any) is as it was.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {err}", path.display())]
pub struct WriteError {
    pub path: PathBuf,
    pub err: io::Error,
}

/// Writes `bytes` to `path` atomically (see the module documentation).
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    write_with(path, |w| w.write_all(bytes))
}

/// Writes what `fill` produces to `path` atomically (see the module
/// documentation). `fill` gets a buffered writer.
pub fn write_with(path: &Path, fill: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> Result<(), WriteError> {
    commit(vec![stage(path, fill)?])
}

/// Writes each `(path, bytes)` atomically, and all of them as one: every
/// temporary file is complete on disk before the first is renamed over its
/// target, so a failure while writing any leaves every target as it was
/// and no temporary file.
pub fn write_all(files: &[(&Path, &[u8])]) -> Result<(), WriteError> {
    let mut staged = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        match stage(path, |w| w.write_all(bytes)) {
            Ok(s) => staged.push(s),
            Err(e) => {
                staged.into_iter().for_each(discard);
                return Err(e);
            }
        }
    }
    commit(staged)
}

/// A complete temporary file, flushed to disk, waiting to be renamed over
/// `target` (what `path` names).
struct Staged {
    path: PathBuf,
    target: PathBuf,
    tmp: tempfile::NamedTempFile,
}

/// Fills a temporary file for `path` (listed for the signal handler while
/// it exists); on failure it is removed.
fn stage(path: &Path, fill: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> Result<Staged, WriteError> {
    let fail = |err| WriteError {
        path: path.to_path_buf(),
        err,
    };
    let (target, perms) = target(path).map_err(fail)?;
    let tmp = {
        // Created and listed under one lock: a signal between the two would
        // find the file made but not listed, and leave it behind.
        let mut list = pending();
        let tmp = temp_beside(&target, perms).map_err(fail)?;
        list.push(tmp.path().to_path_buf());
        tmp
    };
    let filled = (|| {
        let mut w = BufWriter::new(tmp.as_file());
        fill(&mut w)?;
        w.flush()?;
        drop(w);
        tmp.as_file().sync_all()
    })();
    let staged = Staged {
        path: path.to_path_buf(),
        target,
        tmp,
    };
    match filled {
        Ok(()) => Ok(staged),
        Err(e) => {
            discard(staged);
            Err(fail(e))
        }
    }
}

/// Removes a staged temporary file and its entry in the list, under the
/// lock, so the signal handler sees it either still there or gone.
fn discard(s: Staged) {
    let mut list = pending();
    list.retain(|p| p != s.tmp.path());
    drop(s.tmp);
}

/// Renames each staged file over its target, under the lock (as
/// [`discard`]); after a failed rename the rest are removed, not renamed.
fn commit(staged: Vec<Staged>) -> Result<(), WriteError> {
    let mut list = pending();
    let mut result = Ok(());
    for s in staged {
        let tmp_path = s.tmp.path().to_path_buf();
        if result.is_ok() {
            // On failure `persist` hands the file back; dropping it removes it.
            result = s.tmp.persist(&s.target).map(drop).map_err(|e| WriteError {
                path: s.path,
                err: e.error,
            });
        }
        list.retain(|p| *p != tmp_path);
    }
    result
}

/// A new, empty temporary file in `target`'s directory, named after it.
fn temp_beside(target: &Path, perms: Option<Permissions>) -> io::Result<tempfile::NamedTempFile> {
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = target.file_name().unwrap_or_default().to_string_lossy();
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    if let Some(p) = perms.or_else(new_file_permissions) {
        builder.permissions(p);
    }
    builder.tempfile_in(dir).map_err(|e| {
        // The OS error alone: tempfile adds the random name, which means nothing to the user.
        let why = e
            .raw_os_error()
            .map_or_else(|| e.to_string(), |c| io::Error::from_raw_os_error(c).to_string());
        io::Error::new(
            e.kind(),
            format!("cannot create a temporary file in {}: {why}", dir.display()),
        )
    })
}

/// Checks, before long work, that [`write_with`] could write `path`: it is
/// a regular file or nothing (see [`check_regular`]) and a temporary file
/// can be created (and is at once removed) in its directory.
pub fn check_target(path: &Path) -> Result<(), WriteError> {
    let fail = |err| WriteError {
        path: path.to_path_buf(),
        err,
    };
    let (target, _) = target(path).map_err(fail)?;
    // Made and removed under the lock: the signal handler waits until it is gone.
    let _list = pending();
    temp_beside(&target, None).map(drop).map_err(fail)
}

/// Where to write for `path`, and the permissions of the file replaced (if
/// any); an error when `path` is something that must not be replaced.
fn target(path: &Path) -> io::Result<(PathBuf, Option<Permissions>)> {
    let meta = match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok((path.to_path_buf(), None)),
        other => other?,
    };
    if meta.is_file() {
        single_link(&meta)?;
        return Ok((path.to_path_buf(), Some(meta.permissions())));
    }
    if !meta.file_type().is_symlink() {
        return Err(refused(&format!("it is {}", kind(&meta))));
    }
    let real = std::fs::canonicalize(path).map_err(|_| refused("it is a symbolic link to nothing"))?;
    let meta = std::fs::metadata(&real)?;
    if !meta.is_file() {
        return Err(refused(&format!("it is a symbolic link to {}", kind(&meta))));
    }
    single_link(&meta)?;
    Ok((real, Some(meta.permissions())))
}

/// Refuses a regular file with more than one hard link (see the module
/// documentation for why).
fn single_link(meta: &std::fs::Metadata) -> io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if meta.nlink() > 1 {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "it has {} hard links, and replacing it would leave the others with the old content \
                     (refusing to replace it: write to a new name, or remove the other links)",
                    meta.nlink()
                ),
            ));
        }
    }
    let _ = meta;
    Ok(())
}

fn refused(why: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("{why}, not a regular file (refusing to replace it)"),
    )
}

/// Checks that `path` is a regular file, a symbolic link to one, or
/// nothing: for files that are appended to rather than replaced (the
/// viewer's frame log), which must not be a device, FIFO or directory.
pub fn check_regular(path: &Path) -> Result<(), WriteError> {
    target(path).map(drop).map_err(|err| WriteError {
        path: path.to_path_buf(),
        err,
    })
}

/// The directories [`create_dirs`] made, removed again (each only if
/// empty, the deepest first) when this is dropped without [`NewDirs::keep`]:
/// a command that fails leaves no directory it created behind.
#[must_use = "dropping it removes the directories made"]
pub struct NewDirs(Vec<PathBuf>);

impl NewDirs {
    /// Keeps the directories (the command succeeded).
    pub fn keep(mut self) {
        self.0.clear();
    }
}

impl Drop for NewDirs {
    fn drop(&mut self) {
        for d in self.0.iter().rev() {
            // Not empty: something else wrote there meanwhile; it stays.
            let _ = std::fs::remove_dir(d);
        }
    }
}

/// `dir` and any missing parents, as `create_dir_all`, remembering the
/// ones it made (see [`NewDirs`]).
pub fn create_dirs(dir: &Path) -> io::Result<NewDirs> {
    let mut missing: Vec<PathBuf> = dir
        .ancestors()
        .filter(|a| !a.as_os_str().is_empty())
        .take_while(|a| std::fs::symlink_metadata(a).is_err())
        .map(Path::to_path_buf)
        .collect();
    missing.reverse();
    std::fs::create_dir_all(dir)?;
    Ok(NewDirs(missing))
}

/// The mode for a new file: passed to open(2), so the umask applies as for
/// any new file (tempfile's own default is 0600).
fn new_file_permissions() -> Option<Permissions> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        Some(Permissions::from_mode(0o666))
    }
    #[cfg(not(unix))]
    None
}

/// Installs a handler of Ctrl-C (SIGINT), SIGTERM and SIGHUP (`ctrlc`'s
/// `termination` feature) that removes the temporary files being written
/// and exits with status 130. For the headless commands; without it any of
/// the three kills the process before any clean-up. (Feature `signals`:
/// a browser has no signals.)
#[cfg(feature = "signals")]
pub fn remove_temp_files_on_interrupt() {
    // It fails only when a handler is already installed: then that one rules.
    let _ = ctrlc::set_handler(|| {
        // The lock is held until the exit, so no temporary file is made,
        // listed or renamed after the sweep: every one that exists is listed
        // (see `stage`) and removed here.
        let list = pending();
        for p in list.iter() {
            let _ = std::fs::remove_file(p);
        }
        std::process::exit(130);
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::files::tests::dir;

    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn writes_replaces_and_keeps_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let d = dir("replace");
        let p = d.join("a.txt");
        write_file(&p, b"one").unwrap();
        std::fs::set_permissions(&p, Permissions::from_mode(0o640)).unwrap();
        write_file(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        assert_eq!(std::fs::metadata(&p).unwrap().permissions().mode() & 0o777, 0o640);
        assert_eq!(names(&d), ["a.txt"]);
    }

    #[test]
    fn a_failed_fill_leaves_the_old_file_and_no_temporary() {
        let d = dir("fail");
        let p = d.join("a.txt");
        std::fs::write(&p, "old").unwrap();
        let e = write_with(&p, |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(e.to_string(), format!("cannot write {}: disk full", p.display()));
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
        assert_eq!(names(&d), ["a.txt"]);
        assert!(!pending().iter().any(|p| p.starts_with(&*d)));
    }

    #[test]
    fn refuses_what_is_not_a_regular_file() {
        let d = dir("refuse");
        let sub = d.join("sub");
        std::fs::create_dir(&sub).unwrap();
        let e = write_file(&sub, b"x").unwrap_err().to_string();
        assert!(e.contains("it is a directory, not a regular file"), "{e}");
        assert!(e.contains(&*sub.to_string_lossy()), "{e}");
        let link = d.join("null");
        std::os::unix::fs::symlink("/dev/null", &link).unwrap();
        let e = write_file(&link, b"x").unwrap_err().to_string();
        assert!(e.contains("a symbolic link to a character device"), "{e}");
        let dangling = d.join("dangling");
        std::os::unix::fs::symlink(d.join("missing"), &dangling).unwrap();
        assert!(write_file(&dangling, b"x").is_err());
        assert!(check_regular(&sub).is_err() && check_regular(&d.join("new")).is_ok());
        assert!(check_target(&sub).is_err() && check_target(&d.join("new")).is_ok());
        assert!(check_target(&d.join("no-such-dir/new")).is_err());
        assert_eq!(names(&d), ["dangling", "null", "sub"]);
    }

    #[test]
    fn a_link_to_a_regular_file_writes_its_target() {
        let d = dir("link");
        let real = d.join("real.txt");
        std::fs::write(&real, "old").unwrap();
        let link = d.join("link.txt");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_file(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
    }

    #[test]
    fn a_file_with_other_hard_links_is_not_replaced() {
        let d = dir("hard");
        let (h1, h2) = (d.join("h1.png"), d.join("h2.png"));
        std::fs::write(&h1, "old").unwrap();
        std::fs::hard_link(&h1, &h2).unwrap();
        let e = write_file(&h1, b"new").unwrap_err().to_string();
        assert!(e.contains("it has 2 hard links"), "{e}");
        assert!(check_target(&h2).is_err());
        let link = d.join("link.png");
        std::os::unix::fs::symlink(&h2, &link).unwrap();
        assert!(check_target(&link).is_err());
        assert_eq!([&h1, &h2].map(|p| std::fs::read_to_string(p).unwrap()), ["old", "old"]);
        std::fs::remove_file(&h2).unwrap();
        write_file(&h1, b"new").unwrap();
        assert_eq!(names(&d), ["h1.png", "link.png"]);
    }

    #[test]
    fn write_all_writes_none_when_one_fails() {
        let d = dir("all");
        let (a, b) = (d.join("a.csv"), d.join("b.png"));
        std::fs::write(&a, "old").unwrap();
        std::fs::create_dir(&b).unwrap();
        let e = write_all(&[(&a, b"new"), (&b, b"png")]).unwrap_err();
        assert_eq!(e.path, b);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");
        assert_eq!(names(&d), ["a.csv", "b.png"]);
        assert!(!pending().iter().any(|p| p.starts_with(&*d)));
        let c = d.join("c.png");
        write_all(&[(&a, b"new"), (&c, b"png")]).unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new");
        assert_eq!(names(&d), ["a.csv", "b.png", "c.png"]);
    }

    #[test]
    fn new_directories_are_removed_unless_kept() {
        let d = dir("dirs");
        let deep = d.join("a/b/c");
        let made = create_dirs(&deep).unwrap();
        assert!(deep.is_dir());
        drop(made);
        assert_eq!(names(&d), Vec::<String>::new());
        std::fs::create_dir(d.join("a")).unwrap();
        let made = create_dirs(&deep).unwrap();
        std::fs::write(d.join("a/b/file"), "x").unwrap();
        drop(made);
        // `c` is gone, `b` holds a file and `a` was there before.
        assert_eq!(names(&d.join("a/b")), ["file"]);
        create_dirs(&deep).unwrap().keep();
        assert!(deep.is_dir());
    }
}
