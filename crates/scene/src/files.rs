//! Reading the files a scene references (buffers, images, material libraries), confined to
//! the scene's folder: a reference that leaves it (`../../etc/passwd`, an absolute path, a
//! symbolic link pointing out) is refused unless the caller allows it
//! ([`crate::LoadOptions::allow_outside_folder`]).
//!
//! References come from the disk or, for scenes loaded from memory, from a
//! [`MemoryFiles`] map (an archive, embedded assets, the fuzzers).

use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};

use crate::error::{Result, SceneError};

/// The files a scene loaded with [`crate::load_from_memory`] may reference, keyed by their
/// path relative to the scene file (`textures/wall.png`, with `/` separators).
#[derive(Debug, Clone, Default)]
pub struct MemoryFiles {
    files: HashMap<String, Vec<u8>>,
}

impl MemoryFiles {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds (or replaces) the file at `relative_path`.
    pub fn insert(&mut self, relative_path: impl Into<String>, bytes: Vec<u8>) {
        let path = relative_path.into();
        let key = inside_folder(Path::new(&path)).unwrap_or(path);
        self.files.insert(key, bytes);
    }

    pub fn get(&self, relative_path: &str) -> Option<&[u8]> {
        self.files.get(relative_path).map(Vec::as_slice)
    }

    pub fn len(&self) -> usize {
        self.files.len()
    }

    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }
}

/// Where a loader finds the files its scene references.
#[derive(Debug, Clone, Copy)]
pub(crate) enum FileSource<'a> {
    /// Files next to the scene file on disk.
    Disk { allow_outside_folder: bool },
    /// Files in memory; references outside the scene's folder are always refused.
    Memory(&'a MemoryFiles),
}

impl FileSource<'_> {
    /// Reads `reference` (relative to `base_dir`, the scene file's folder) for the scene
    /// `file`.
    pub(crate) fn read(
        &self,
        file: &Path,
        base_dir: &Path,
        reference: &Path,
        kind: &'static str,
    ) -> Result<Vec<u8>> {
        let refuse = || SceneError::OutsideSceneFolder {
            file: file.to_path_buf(),
            kind,
            reference: reference.display().to_string(),
        };
        let missing = |resolved: PathBuf| SceneError::MissingReferencedFile {
            file: file.to_path_buf(),
            kind,
            uri: reference.display().to_string(),
            resolved,
        };
        match *self {
            FileSource::Memory(files) => {
                let key = inside_folder(reference).ok_or_else(refuse)?;
                files
                    .get(&key)
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| missing(base_dir.join(&key)))
            }
            FileSource::Disk {
                allow_outside_folder,
            } => {
                let resolved = base_dir.join(reference);
                if !allow_outside_folder {
                    inside_folder(reference).ok_or_else(refuse)?;
                    // A symbolic link inside the folder may point out of it.
                    if let (Ok(real), Ok(folder)) =
                        (resolved.canonicalize(), base_dir.canonicalize())
                        && !real.starts_with(&folder)
                    {
                        return Err(refuse());
                    }
                }
                std::fs::read(&resolved).map_err(|source| match source.kind() {
                    std::io::ErrorKind::NotFound => missing(resolved.clone()),
                    _ => SceneError::Io {
                        file: resolved.clone(),
                        source,
                    },
                })
            }
        }
    }
}

/// `reference` normalised to `a/b/c` if it stays inside its folder (lexically: no root, no
/// prefix, never above the folder), else `None`.
fn inside_folder(reference: &Path) -> Option<String> {
    let mut parts: Vec<String> = Vec::new();
    for component in reference.components() {
        match component {
            Component::Normal(part) => parts.push(part.to_string_lossy().into_owned()),
            Component::CurDir => {}
            Component::ParentDir => {
                parts.pop()?;
            }
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(parts.join("/"))
}
