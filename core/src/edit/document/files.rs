//! Saving and reloading a [`Document`]: TOML text that reads back to the
//! identical scene, written atomically (`crate::output`) so a failed save
//! never leaves half a file.

use super::{Change, Document, Rejected, Source};
use crate::output::{WriteError, write_file};
use crate::scene::{Scene, SceneError, SceneFile};
use std::path::{Path, PathBuf};

impl Document {
    /// Saves to the document's own file. `Ok(None)` when it has none (a
    /// preset or the default scene): ask for a name and use [`Self::save_as`].
    pub fn save(&mut self) -> Result<Option<PathBuf>, SaveError> {
        match self.source.path().map(Path::to_path_buf) {
            Some(p) => self.save_as(&p).map(Some),
            None => Ok(None),
        }
    }

    /// Writes the scene as TOML to `path` (atomically, [`crate::output`]: a
    /// failed save never leaves half a file or a temporary one), checks that the
    /// text reads back to the identical scene, and makes `path` the
    /// document's file.
    pub fn save_as(&mut self, path: &Path) -> Result<PathBuf, SaveError> {
        let text = to_toml(&self.scene).map_err(SaveError::Serialize)?;
        write_file(path, text.as_bytes()).map_err(SaveError::Io)?;
        self.source = Source::File(path.to_path_buf());
        self.saved = self.scene.clone();
        Ok(path.to_path_buf())
    }

    /// Reads the document's file again as one undoable step. With
    /// `keep_camera` the camera stays where it is. A file that does not load
    /// changes nothing.
    pub fn reload(&mut self, keep_camera: bool) -> Result<Change, ReloadError> {
        let path = self.source.path().ok_or(ReloadError::NoFile)?.to_path_buf();
        let (mut sf, _) = Scene::load(&path).map_err(ReloadError::Scene)?;
        let on_disk = sf.clone();
        if keep_camera {
            sf.camera = self.scene.camera.clone();
        }
        let change = self.edit("reload", |s| *s = sf).map_err(ReloadError::Rejected)?;
        self.saved = on_disk;
        Ok(change)
    }
}

/// The scene as TOML text that reads back to the identical [`SceneFile`].
pub fn to_toml(sf: &SceneFile) -> Result<String, String> {
    let body = toml::to_string(sf).map_err(|e| e.to_string())?;
    let text = format!(
        "# lensview scene (saved by lensview {})\n\n{body}",
        env!("CARGO_PKG_VERSION")
    );
    // The promise is that saving loses nothing: check it before writing.
    let back: SceneFile = toml::from_str(&text).map_err(|e| format!("the saved text does not read back: {e}"))?;
    if &back != sf {
        return Err("the saved text reads back to a different scene".into());
    }
    Ok(text)
}

/// Why a save failed (the document is unchanged and still dirty).
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    #[error("{0}")]
    Io(WriteError),
    #[error("cannot write the scene as TOML: {0}")]
    Serialize(String),
}

/// Why a reload failed (the document is unchanged).
#[derive(Debug, thiserror::Error)]
pub enum ReloadError {
    #[error("this scene has no file to reload (it is a preset or the default scene)")]
    NoFile,
    #[error("{0}")]
    Scene(SceneError),
    #[error("{0}")]
    Rejected(Rejected),
}
