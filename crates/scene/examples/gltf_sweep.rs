//! Loads every `.gltf`/`.glb` under a folder (for example a checkout of Khronos's
//! glTF-Sample-Assets) and reports which load, with their warnings, and which are refused,
//! with the reason, then the totals.
//!
//! ```sh
//! cargo run --release -p manylights-scene --example gltf_sweep -- path/to/glTF-Sample-Assets/Models
//! ```

use std::path::{Path, PathBuf};

fn collect(folder: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(folder) else {
        return;
    };
    let mut entries: Vec<_> = entries.flatten().map(|entry| entry.path()).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            collect(&path, out);
        } else if matches!(
            path.extension().and_then(|e| e.to_str()),
            Some("gltf" | "glb")
        ) {
            out.push(path);
        }
    }
}

fn main() {
    let Some(folder) = std::env::args().nth(1) else {
        eprintln!("usage: gltf_sweep FOLDER");
        std::process::exit(2);
    };
    let mut files = Vec::new();
    collect(Path::new(&folder), &mut files);
    let (mut loaded, mut refused) = (0, 0);
    for file in &files {
        let shown = file.strip_prefix(&folder).unwrap_or(file).display();
        match manylights_scene::load(file) {
            Ok(scene) => {
                loaded += 1;
                println!(
                    "LOADED  {shown}: {} triangles, {} materials, {} warnings",
                    scene.triangle_count(),
                    scene.materials.len(),
                    scene.warnings.len()
                );
                for warning in scene.warnings.iter().take(3) {
                    println!("        warning: {}", warning.message);
                }
            }
            Err(error) => {
                refused += 1;
                println!("REFUSED {shown}: {error}");
            }
        }
    }
    println!("{} files: {loaded} loaded, {refused} refused", files.len());
}
