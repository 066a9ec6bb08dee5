//! Which files lensview reads and which it may write (how it writes them is
//! `output`'s):
//!
//! - **Only regular files are read** ([`open_regular`]): a scene, a `lens
//!   trace` input, a PNG. A FIFO would block open(2) until a writer comes
//!   and a device may never end, so the type is checked before opening; the
//!   file is opened with `O_NONBLOCK` (no effect on a regular file) and its
//!   type checked again on the open descriptor (fstat), so a path swapped
//!   for a FIFO between the two cannot block either.
//! - **No output is an input or another output** ([`check_distinct`]):
//!   paths are compared as files (device and inode, after resolving
//!   symbolic links; hard links are the same file), and an output that does
//!   not exist yet by the path it would be created at (its directory
//!   resolved), so `--csv X --plot X` is refused before either is written.

use std::fs::{File, Metadata};
use std::io;
use std::path::{Path, PathBuf};

/// What a file is, in words ("a FIFO"), for refusals.
pub fn kind(meta: &Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_file() {
        return "a regular file";
    }
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "a special file"
}

/// The refusal of a file to read that is `meta`.
fn not_regular(meta: &Metadata) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("it is {}, not a regular file (only regular files are read)", kind(meta)),
    )
}

/// `path` opened for reading, if it is a regular file (or a symbolic link
/// to one); anything else is refused without blocking (see the module
/// documentation).
pub fn open_regular(path: &Path) -> io::Result<File> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    Ok(file)
}

/// `path` opened for appending (created if missing), if it is a regular
/// file or nothing: for logs, checked as [`open_regular`] so a FIFO at the
/// path cannot block the open.
pub fn open_append(path: &Path) -> io::Result<File> {
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => return Err(not_written(&meta)),
        Ok(_) => {}
        Err(e) if e.kind() == io::ErrorKind::NotFound => {}
        Err(e) => return Err(e),
    }
    let mut options = std::fs::OpenOptions::new();
    options.create(true).append(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(not_written(&meta));
    }
    Ok(file)
}

fn not_written(meta: &Metadata) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("it is {}, not a regular file (refusing to write to it)", kind(meta)),
    )
}

/// A file as the file system knows it: its device and inode when it exists,
/// else the path it would be created at.
#[derive(Debug, PartialEq)]
enum Identity {
    #[cfg(unix)]
    Inode(u64, u64),
    Path(PathBuf),
}

fn identity(path: &Path) -> Identity {
    #[cfg(unix)]
    if let Ok(meta) = std::fs::metadata(path) {
        use std::os::unix::fs::MetadataExt;
        return Identity::Inode(meta.dev(), meta.ino());
    }
    // Not there (or a link to nothing): where it would be made.
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().map(PathBuf::from).unwrap_or_default();
    match std::fs::canonicalize(dir) {
        Ok(d) => Identity::Path(d.join(name)),
        Err(_) => Identity::Path(std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())),
    }
}

/// An output that is an input or another output.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{what} {} is the same file as {other} {}: {why}", path.display(), other_path.display())]
pub struct SameFile {
    pub what: String,
    pub path: PathBuf,
    pub other: String,
    pub other_path: PathBuf,
    pub why: &'static str,
}

/// Refuses an output (`(flag, path)`) that is the same file as an input or
/// as an earlier output (see the module documentation). Checked before any
/// work, so nothing is written.
pub fn check_distinct(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> Result<(), SameFile> {
    let ins: Vec<Identity> = inputs.iter().map(|(_, p)| identity(p)).collect();
    let mut outs: Vec<Identity> = Vec::with_capacity(outputs.len());
    for &(what, path) in outputs {
        let id = identity(path);
        let same = |others: &[Identity], named: &[(&str, &Path)], why| {
            others.iter().position(|o| *o == id).map(|i| SameFile {
                what: what.into(),
                path: path.into(),
                other: named[i].0.into(),
                other_path: named[i].1.into(),
                why,
            })
        };
        if let Some(e) = same(&ins, inputs, "refusing to write over an input") {
            return Err(e);
        }
        if let Some(e) = same(&outs, outputs, "each output needs its own file") {
            return Err(e);
        }
        outs.push(id);
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A folder of its own for a test, removed when dropped (this module's
    /// tests and `output`'s use it).
    pub(crate) struct Dir(tempfile::TempDir);

    impl std::ops::Deref for Dir {
        type Target = Path;
        fn deref(&self) -> &Path {
            self.0.path()
        }
    }

    /// [`Dir`] for test `name`.
    pub(crate) fn dir(name: &str) -> Dir {
        Dir(tempfile::Builder::new()
            .prefix(&format!("lensview-test-{name}-"))
            .tempdir()
            .unwrap())
    }

    #[test]
    fn only_regular_files_are_opened_and_a_fifo_does_not_block() {
        let d = dir("regular");
        let f = d.join("a.toml");
        std::fs::write(&f, "x").unwrap();
        assert!(open_regular(&f).is_ok());
        let link = d.join("link.toml");
        std::os::unix::fs::symlink(&f, &link).unwrap();
        assert!(open_regular(&link).is_ok());
        let fifo = d.join("fifo");
        assert!(
            std::process::Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .unwrap()
                .success()
        );
        // On another thread, so that a regression fails instead of hanging.
        let (tx, rx) = std::sync::mpsc::channel();
        let (fifo2, d2) = (fifo.clone(), d.to_path_buf());
        std::thread::spawn(move || {
            let e = |p: &Path| open_regular(p).unwrap_err().to_string();
            let a = open_append(&fifo2).unwrap_err().to_string();
            let _ = tx.send([e(&fifo2), e(&d2), e(Path::new("/dev/zero")), a]);
        });
        let got = rx.recv_timeout(std::time::Duration::from_secs(10)).expect("blocked");
        assert_eq!(got[0], "it is a FIFO, not a regular file (only regular files are read)");
        assert!(got[1].starts_with("it is a directory"), "{}", got[1]);
        assert!(got[2].starts_with("it is a character device"), "{}", got[2]);
        assert!(
            got[3].starts_with("it is a FIFO, not a regular file (refusing"),
            "{}",
            got[3]
        );
        assert!(open_append(&d.join("log")).is_ok());
    }

    #[test]
    fn outputs_that_are_inputs_or_each_other_are_refused() {
        let d = dir("distinct");
        let scene = d.join("sc.toml");
        std::fs::write(&scene, "x").unwrap();
        let hard = d.join("hard.toml");
        std::fs::hard_link(&scene, &hard).unwrap();
        let soft = d.join("soft.toml");
        std::os::unix::fs::symlink(&scene, &soft).unwrap();
        let inputs = [("the scene", scene.as_path())];
        let new = d.join("new.csv");
        let via_dot = d.join(".").join("new.csv");
        assert!(check_distinct(&inputs, &[("--csv", &new), ("--plot", &d.join("p.png"))]).is_ok());
        for same in [&scene, &hard, &soft] {
            let e = check_distinct(&inputs, &[("--csv", same)]).unwrap_err().to_string();
            assert!(e.ends_with("refusing to write over an input"), "{e}");
            assert!(e.starts_with(&format!("--csv {} is the same file as the scene", same.display())));
        }
        let e = check_distinct(&inputs, &[("--csv", &new), ("--plot", &via_dot)]).unwrap_err();
        assert_eq!((e.what.as_str(), e.other.as_str()), ("--plot", "--csv"));
        assert!(e.to_string().ends_with("each output needs its own file"), "{e}");
        std::fs::write(&new, "y").unwrap();
        assert!(check_distinct(&inputs, &[("--csv", &new), ("--plot", &via_dot)]).is_err());
    }
}
