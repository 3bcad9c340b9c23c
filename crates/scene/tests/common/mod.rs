//! What the scene crate's test files share.

use manylights_scene::Scene;
use manylights_scene::export::{ExportFormat, export};

/// Holds `assets/NAME/NAME.gltf` to the exporter's output for `scene`, byte for byte, and
/// returns the committed bytes. With `MANYLIGHTS_WRITE_ASSETS=1` it writes the file first:
/// edit the procedural scene, then run `test` (the test file's name) with it set.
pub fn assert_committed_asset_is_export(scene: &Scene, name: &str, test: &str) -> Vec<u8> {
    let exported = export(scene, ExportFormat::GltfEmbedded, name).expect("export");
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../assets/{name}/{name}.gltf"));
    if std::env::var_os("MANYLIGHTS_WRITE_ASSETS").is_some() {
        std::fs::create_dir_all(path.parent().expect("folder")).expect("the asset's folder");
        std::fs::write(&path, exported.main_bytes()).expect("write");
    }
    let committed = std::fs::read(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (write it with MANYLIGHTS_WRITE_ASSETS=1 cargo test -p manylights-scene --test {test})",
            path.display()
        )
    });
    assert!(
        committed == exported.main_bytes(),
        "{} differs from the export of its procedural scene (rewrite it with MANYLIGHTS_WRITE_ASSETS=1 cargo test -p manylights-scene --test {test})",
        path.display()
    );
    committed
}
