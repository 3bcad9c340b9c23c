//! Typed load errors. Every variant names the file and says what is wrong with it.

use std::path::PathBuf;

/// Why a scene could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{file}: file not found")]
    FileNotFound { file: PathBuf },

    #[error("{file}: cannot read: {source}")]
    Io {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },

    #[error("{file}: unsupported scene format (expected .gltf, .glb or .obj)")]
    UnsupportedFormat { file: PathBuf },

    #[error("{file}: referenced {kind} file '{uri}' not found (looked for {resolved})")]
    MissingReferencedFile {
        file: PathBuf,
        kind: &'static str,
        uri: String,
        resolved: PathBuf,
    },

    #[error("{file}: buffer {buffer} declares {declared} bytes but its data has only {actual}")]
    BufferTooShort {
        file: PathBuf,
        buffer: usize,
        declared: usize,
        actual: usize,
    },

    #[error("{file}: invalid glTF: {message}")]
    InvalidGltf { file: PathBuf, message: String },

    #[error("{file}: invalid OBJ/MTL: {message}")]
    InvalidObj { file: PathBuf, message: String },

    #[error("{file}: accessor {accessor} reads past the end of its data: {message}")]
    AccessorOutOfRange {
        file: PathBuf,
        accessor: usize,
        message: String,
    },

    #[error("{file}: mesh '{mesh}': index {index} is out of range ({vertex_count} vertices)")]
    IndexOutOfRange {
        file: PathBuf,
        mesh: String,
        index: u32,
        vertex_count: usize,
    },

    #[error("{file}: mesh '{mesh}': {message}")]
    InvalidMesh {
        file: PathBuf,
        mesh: String,
        message: String,
    },

    #[error("{file}: mesh '{mesh}': position {vertex} is not finite ({value})")]
    NonFinitePosition {
        file: PathBuf,
        mesh: String,
        vertex: usize,
        value: String,
    },

    #[error("{file}: required extension '{extension}' is not supported{hint}")]
    UnsupportedExtension {
        file: PathBuf,
        extension: String,
        /// What to do about it, starting with ": " (empty when there is nothing to say).
        hint: String,
    },

    #[error("{file}: {message}")]
    LimitExceeded { file: PathBuf, message: String },

    #[error(
        "{file}: the {kind} '{reference}' is outside the scene's folder; refused (LoadOptions::allow_outside_folder allows it)"
    )]
    OutsideSceneFolder {
        file: PathBuf,
        kind: &'static str,
        reference: String,
    },
}

pub type Result<T, E = SceneError> = std::result::Result<T, E>;
