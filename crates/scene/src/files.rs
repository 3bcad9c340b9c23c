//! Reading the files a scene references (buffers, images, material libraries), confined to
//! the scene's folder: a reference that leaves it (`../../etc/passwd`, an absolute path, a
//! symbolic link pointing out) is refused unless the caller allows it
//! ([`crate::LoadOptions::allow_outside_folder`]).

use std::path::{Component, Path};

use crate::error::{Result, SceneError};

/// Reads `reference` (relative to `base_dir`) for the scene `file`.
pub(crate) fn read_referenced(
    file: &Path,
    base_dir: &Path,
    reference: &Path,
    kind: &'static str,
    allow_outside: bool,
) -> Result<Vec<u8>> {
    let resolved = base_dir.join(reference);
    let refuse = || SceneError::OutsideSceneFolder {
        file: file.to_path_buf(),
        kind,
        reference: reference.display().to_string(),
    };
    if !allow_outside {
        // Lexically: no root, no prefix, never above the folder.
        let mut depth = 0i32;
        for component in reference.components() {
            match component {
                Component::Normal(_) => depth += 1,
                Component::CurDir => {}
                Component::ParentDir => depth -= 1,
                Component::RootDir | Component::Prefix(_) => return Err(refuse()),
            }
            if depth < 0 {
                return Err(refuse());
            }
        }
        // And on disk: a symbolic link inside the folder may point out of it.
        if let (Ok(real), Ok(folder)) = (resolved.canonicalize(), base_dir.canonicalize())
            && !real.starts_with(&folder)
        {
            return Err(refuse());
        }
    }
    std::fs::read(&resolved).map_err(|source| match source.kind() {
        std::io::ErrorKind::NotFound => SceneError::MissingReferencedFile {
            file: file.to_path_buf(),
            kind,
            uri: reference.display().to_string(),
            resolved: resolved.clone(),
        },
        _ => SceneError::Io {
            file: resolved.clone(),
            source,
        },
    })
}
