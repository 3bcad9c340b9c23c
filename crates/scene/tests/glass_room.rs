//! The committed `assets/glass/glass.gltf` is exactly the export of
//! `procedural::glass_room`, and loads back with its blended panes and sparks; likewise
//! `assets/sponza-glass/sponza-glass.gltf`, Sponza's blended overlay.

use manylights_scene::procedural::{GLASS_PANES, SPONZA_BANNERS, glass_room, sponza_glass};
use manylights_scene::{AlphaMode, MemoryFiles, Scene, load_from_memory};

mod common;

/// The names of `scene`'s `BLEND` materials, in order.
fn blended_materials(scene: &Scene) -> Vec<&str> {
    scene
        .materials
        .iter()
        .filter(|m| m.alpha_mode == AlphaMode::Blend)
        .map(|m| m.name.as_str())
        .collect()
}

#[test]
fn the_committed_glass_asset_is_the_glass_room() {
    let committed = common::assert_committed_asset_is_export(&glass_room(), "glass", "glass_room");
    let loaded = load_from_memory("glass.gltf", &committed, &MemoryFiles::new()).expect("loads");
    let blended = blended_materials(&loaded);
    let mut expected: Vec<&str> = GLASS_PANES.iter().map(|(name, _, _)| *name).collect();
    expected.push("sparks");
    assert_eq!(blended, expected, "every pane and the sparks are BLEND");
    for (name, base, _) in GLASS_PANES {
        let material = loaded
            .materials
            .iter()
            .find(|m| m.name == name)
            .expect(name);
        assert_eq!(material.base_color_factor.w, base[3], "{name}'s alpha");
        assert!(material.double_sided, "{name} is seen from both sides");
    }
    assert!(loaded.features().alpha_blend);
}

#[test]
fn the_committed_sponza_overlay_is_its_banners_and_embers() {
    let committed =
        common::assert_committed_asset_is_export(&sponza_glass(), "sponza-glass", "glass_room");
    let loaded =
        load_from_memory("sponza-glass.gltf", &committed, &MemoryFiles::new()).expect("loads");
    let blended = blended_materials(&loaded);
    let mut expected: Vec<&str> = SPONZA_BANNERS.iter().map(|(name, _, _)| *name).collect();
    expected.push("embers");
    assert_eq!(blended, expected, "the banners and the embers are BLEND");
    assert_eq!(loaded.triangle_count(), 4 * 2 + 3000 * 2);
}

/// The committed `assets/sponza-embers/sponza-embers.gltf` is the export of
/// `procedural::sponza_embers`: 10,000 emissive triangles, their emission kept.
#[test]
fn the_committed_ember_overlay_is_ten_thousand_emissive_triangles() {
    use manylights_scene::procedural::{SPONZA_EMBERS, sponza_embers};
    let committed =
        common::assert_committed_asset_is_export(&sponza_embers(), "sponza-embers", "glass_room");
    let loaded =
        load_from_memory("sponza-embers.gltf", &committed, &MemoryFiles::new()).expect("loads");
    assert_eq!(loaded.triangle_count(), 2 * SPONZA_EMBERS);
    assert!(loaded.triangle_count() >= 10_000);
    assert_eq!(
        loaded.materials[0].emissive_factor,
        glam::Vec3::new(40.0, 18.0, 6.0)
    );
}
