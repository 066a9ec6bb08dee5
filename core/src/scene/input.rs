//! Reading a scene from disk: a stated size cap on every input file
//! ([`read_capped`], also for other inputs than scenes) and bytes that are
//! not UTF-8 refused with the position of the first bad byte.

use super::error::{Located, SceneError};
use super::{Scene, SceneFile};
use std::io::Read;
use std::path::Path;

pub use crate::limits::SCENE_FILE_CAP;

/// The whole of `path`, refused with [`SceneError::TooLarge`] when it holds
/// more than `cap` bytes (measured before it is read, and read no further
/// than one byte past the cap should it grow). Only a regular file is read
/// (`files::open_regular`): a FIFO or a device is refused without
/// blocking, naming what it is.
pub fn read_capped(path: &Path, cap: u64) -> Result<Vec<u8>, SceneError> {
    let file = path.display().to_string();
    let io = |err| SceneError::Io {
        file: file.clone(),
        err,
    };
    let too_large = || SceneError::TooLarge {
        file: file.clone(),
        cap,
    };
    let f = crate::files::open_regular(path).map_err(io)?;
    let meta = f.metadata().map_err(io)?;
    if meta.len() > cap {
        return Err(too_large());
    }
    let hint = meta.len().min(cap);
    let mut bytes = Vec::with_capacity(usize::try_from(hint).unwrap_or(0) + 1);
    f.take(cap.saturating_add(1)).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > cap {
        return Err(too_large());
    }
    Ok(bytes)
}

impl Scene {
    /// Loads and validates a scene file, at most [`SCENE_FILE_CAP`] bytes.
    pub fn load(path: &Path) -> Result<(SceneFile, Scene), SceneError> {
        let bytes = read_capped(path, SCENE_FILE_CAP)?;
        Self::from_bytes(&path.display().to_string(), &bytes)
    }

    /// Parses and validates the bytes of a scene file; `file` names it in
    /// errors. What [`Scene::load`] does after reading, and what the fuzz
    /// target (fuzz/fuzz_targets/scene.rs) calls.
    pub fn from_bytes(file: &str, bytes: &[u8]) -> Result<(SceneFile, Scene), SceneError> {
        match std::str::from_utf8(bytes) {
            Ok(text) => Self::parse(file, text),
            Err(e) => Err(invalid_utf8(file, bytes, e)),
        }
    }
}

/// The error for bytes that are not UTF-8, at the first bad byte. The field
/// is looked up in the text with bad bytes replaced (U+FFFD), which is the
/// same text, byte for byte, up to there.
fn invalid_utf8(file: &str, bytes: &[u8], e: std::str::Utf8Error) -> SceneError {
    let at = e.valid_up_to();
    let lossy = String::from_utf8_lossy(bytes);
    let message = format!(
        "invalid UTF-8 (byte {:#04x}): a scene file must be UTF-8 text",
        bytes[at]
    );
    Located::new(file, &lossy).error_at(at..at + 1, &message)
}

/// The fuzz oracle (fuzz/fuzz_targets/scene.rs, replayed by
/// tests/fuzz_corpus.rs): loads `bytes` as a scene file and panics if the
/// refusal is not one line naming the file, free of control characters,
/// if an accepted scene does not come back the same through TOML (what
/// saving does), if reading object by object gives another scene than
/// the whole-document parse, or if a refusal found with stubs differs from
/// the one found in the whole text. Panicking is its purpose; nothing else
/// calls it.
#[doc(hidden)]
pub fn check_scene_bytes(bytes: &[u8]) {
    let text = std::str::from_utf8(bytes).ok();
    if let Some(super::stream::Read::Scene(sf)) = text.map(super::stream::scene_file) {
        assert_eq!(
            Some(sf),
            text.and_then(super::stream::whole_document),
            "read object by object"
        );
    }
    match Scene::from_bytes("fuzz.toml", bytes) {
        Ok((sf, _)) => {
            let text = toml::to_string(&sf).unwrap_or_else(|e| panic!("cannot save a loaded scene: {e}"));
            match Scene::parse("saved.toml", &text) {
                Ok((again, _)) => assert_eq!(sf, again, "saved as:\n{text}"),
                Err(e) => panic!("a saved scene does not load: {e}\n{text}"),
            }
        }
        Err(e) => {
            let shown = e.to_string();
            if let Some(text) = text {
                let whole = Scene::refusal("fuzz.toml", text, false).err().map(|e| e.to_string());
                assert_eq!(Some(&shown), whole.as_ref(), "refusal found with stubs");
            }
            assert!(shown.starts_with("fuzz.toml:"), "{shown:?}");
            assert!(!shown.chars().any(char::is_control), "{shown:?}");
        }
    }
}
