//! `EXT_meshopt_compression` in the browser build: meshoptimizer's decoders are C++, which
//! the wasm32 build cannot compile, so a compressed view is an error naming the view and
//! what to do (the native build decodes it: `gltf_meshopt.rs`).

use crate::gltf_json::MeshoptView;

pub(crate) fn decode(index: usize, _view: &MeshoptView, _buffer: &[u8]) -> Result<Vec<u8>, String> {
    Err(format!(
        "meshopt-compressed buffer view {index}: EXT_meshopt_compression is not decoded in the browser build (its decoder is C++); open the file in the native viewer, or export it without meshopt compression"
    ))
}
