//! The CPU side of manylights' scenes: the scene model, loaders for glTF 2.0 and OBJ/MTL
//! (from disk, [`load`], or from memory, [`load_from_memory`]), an exporter to glTF, GLB
//! and OBJ ([`export`]), and deterministic procedural scenes for tests and benchmarks. No
//! GPU dependency: other engines can use it on its own.
//!
//! Every loader failure is a [`SceneError`] naming the file and the problem; problems the
//! scene survives (an undecodable texture) are [`LoadWarning`]s in [`Scene::warnings`].
//!
//! ```no_run
//! let scene = manylights_scene::load("assets/sponza/Sponza.gltf")?;
//! println!("{} meshes, features {:?}", scene.meshes.len(), scene.features());
//! for warning in &scene.warnings {
//!     eprintln!("warning: {warning}");
//! }
//! # Ok::<(), manylights_scene::SceneError>(())
//! ```

pub mod color;
mod error;
pub mod export;
mod files;
#[doc(hidden)]
#[cfg(not(target_arch = "wasm32"))]
pub mod fuzz_harness;
mod gltf_accessor;
mod gltf_json;
mod gltf_loader;
#[cfg(not(target_arch = "wasm32"))]
mod gltf_meshopt;
// The browser build has no meshoptimizer (C++): compressed views are refused by name.
#[cfg(target_arch = "wasm32")]
#[path = "gltf_meshopt_web.rs"]
mod gltf_meshopt;
mod mesh_builder;
mod model;
mod obj_loader;
pub mod procedural;
mod tangents;
mod texture;

use std::path::Path;

pub use error::{Result, SceneError};
use files::FileSource;
pub use files::MemoryFiles;
pub use model::{
    Aabb, AlphaMode, ColorSpace, Instance, LoadWarning, Material, Mesh, Scene, SceneFeatures,
    SceneLight, Shading, SpotCone, Texture, bounds_of, smooth_normals,
};
pub use tangents::generate_tangents;
pub use texture::{MAX_TEXTURE_DIMENSION, fallback as fallback_texture};

/// Largest scene file read into memory (the binary buffers are separate files for
/// `.gltf`). Bigger inputs are refused with [`SceneError::LimitExceeded`].
pub const MAX_SCENE_FILE_BYTES: u64 = 2 << 30;

/// How scene files may be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LoadOptions {
    /// Let a scene reference files outside its own folder (absolute paths, `..`, links
    /// pointing out). Off by default: a downloaded scene cannot read the rest of the disk.
    pub allow_outside_folder: bool,
}

/// Loads a `.gltf`, `.glb` or `.obj` file (chosen by extension).
pub fn load(path: impl AsRef<Path>) -> Result<Scene> {
    load_with(path, &LoadOptions::default())
}

/// [`load`] with options.
pub fn load_with(path: impl AsRef<Path>, options: &LoadOptions) -> Result<Scene> {
    let file = path.as_ref();
    let format = SceneFormat::of(file)?;
    let metadata = std::fs::metadata(file).map_err(|source| match source.kind() {
        std::io::ErrorKind::NotFound => SceneError::FileNotFound {
            file: file.to_path_buf(),
        },
        _ => SceneError::Io {
            file: file.to_path_buf(),
            source,
        },
    })?;
    if metadata.len() > MAX_SCENE_FILE_BYTES {
        return Err(SceneError::LimitExceeded {
            file: file.to_path_buf(),
            message: format!(
                "{} bytes is over the {MAX_SCENE_FILE_BYTES}-byte limit",
                metadata.len()
            ),
        });
    }
    let bytes = std::fs::read(file).map_err(|source| SceneError::Io {
        file: file.to_path_buf(),
        source,
    })?;
    let files = FileSource::Disk {
        allow_outside_folder: options.allow_outside_folder,
    };
    parse(format, file, &bytes, files)
}

/// Loads a scene from memory: `file` names it (its extension picks the format; messages
/// use it) and `bytes` are its contents. The files it references (buffers, images,
/// material libraries) come from `files` only; nothing is read from disk.
pub fn load_from_memory(
    file: impl AsRef<Path>,
    bytes: &[u8],
    files: &MemoryFiles,
) -> Result<Scene> {
    let file = file.as_ref();
    if bytes.len() as u64 > MAX_SCENE_FILE_BYTES {
        return Err(SceneError::LimitExceeded {
            file: file.to_path_buf(),
            message: format!(
                "{} bytes is over the {MAX_SCENE_FILE_BYTES}-byte limit",
                bytes.len()
            ),
        });
    }
    parse(
        SceneFormat::of(file)?,
        file,
        bytes,
        FileSource::Memory(files),
    )
}

/// A file a scene file references.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct ReferencedFile {
    /// The URI as the file writes it (percent-encoded, relative to the scene file): what to
    /// fetch.
    pub uri: String,
    /// The path the loader looks it up by in [`MemoryFiles`] (decoded).
    pub path: String,
}

/// The files a `.gltf`/`.glb` file references by URI (its buffers and images, relative to
/// its folder; `data:` URIs are inside the file), for a caller that must fetch them before
/// [`load_from_memory`] (the browser build). An `.obj` file lists none here: its material
/// libraries are named by the load's error if missing.
pub fn referenced_files(file: impl AsRef<Path>, bytes: &[u8]) -> Result<Vec<ReferencedFile>> {
    let file = file.as_ref();
    if SceneFormat::of(file)? == SceneFormat::Obj {
        return Ok(Vec::new());
    }
    let invalid = |message: String| SceneError::InvalidGltf {
        file: file.to_path_buf(),
        message,
    };
    let json: serde_json::Value = if bytes.starts_with(b"glTF") {
        let glb =
            gltf::Glb::from_slice(bytes).map_err(|e| invalid(format!("bad GLB container: {e}")))?;
        serde_json::from_slice(&glb.json)
    } else {
        serde_json::from_slice(bytes)
    }
    .map_err(|e| invalid(format!("bad JSON: {e}")))?;
    let mut uris: Vec<ReferencedFile> = ["buffers", "images"]
        .iter()
        .filter_map(|list| json.get(list)?.as_array())
        .flatten()
        .filter_map(|item| item.get("uri")?.as_str())
        .filter(|uri| !uri.starts_with("data:"))
        .map(|uri| ReferencedFile {
            uri: uri.to_string(),
            path: gltf_loader::percent_decode(uri)
                .to_string_lossy()
                .into_owned(),
        })
        .collect();
    uris.sort();
    uris.dedup();
    Ok(uris)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SceneFormat {
    Gltf,
    Obj,
}

impl SceneFormat {
    fn of(file: &Path) -> Result<Self> {
        let extension = file
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match extension.as_str() {
            "gltf" | "glb" => Ok(Self::Gltf),
            "obj" => Ok(Self::Obj),
            _ => Err(SceneError::UnsupportedFormat {
                file: file.to_path_buf(),
            }),
        }
    }
}

fn parse(format: SceneFormat, file: &Path, bytes: &[u8], files: FileSource) -> Result<Scene> {
    let scene = match format {
        SceneFormat::Obj => obj_loader::load_obj(file, bytes, files)?,
        SceneFormat::Gltf => gltf_loader::load_gltf(file, bytes, files)?,
    };
    for warning in &scene.warnings {
        log::warn!("{warning}");
    }
    Ok(scene)
}
