//! glTF `KHR_lights_punctual`: point and spot lights load with their node's transform,
//! colour, intensity, range and cone; the exporter writes them back; every bad value is an
//! error naming the file and the light (or, for an "infinite" range, a documented reading
//! as no range), never a panic or a silent zero. The committed `assets/lamps/lamps.gltf`
//! is exactly the export of `procedural::lamp_room`.

use glam::Vec3;
use manylights_scene::export::{ExportFormat, export};
use manylights_scene::procedural::lamp_room;
use manylights_scene::{MemoryFiles, Scene, SceneError, load_from_memory};
use serde_json::{Value, json};

mod common;

/// The lamp room exported as glTF JSON, to edit.
fn lamp_room_json() -> Value {
    let exported = export(&lamp_room(), ExportFormat::GltfEmbedded, "lamps").expect("export");
    serde_json::from_slice(exported.main_bytes()).expect("exported JSON")
}

fn load_json(document: &Value) -> manylights_scene::Result<Scene> {
    load_from_memory(
        "lamps.gltf",
        document.to_string().as_bytes(),
        &MemoryFiles::new(),
    )
}

#[test]
fn lights_round_trip_through_the_exporter() {
    let original = lamp_room();
    let loaded = load_json(&lamp_room_json()).expect("loads");
    assert_eq!(loaded.lights.len(), original.lights.len());
    for (a, b) in original.lights.iter().zip(&loaded.lights) {
        assert_eq!(a.name, b.name);
        assert!(a.position.abs_diff_eq(b.position, 1e-5), "{a:?} / {b:?}");
        assert!(a.direction.abs_diff_eq(b.direction, 1e-5), "{a:?} / {b:?}");
        assert_eq!(a.cone, b.cone);
        assert_eq!(a.color, b.color);
        assert_eq!(a.intensity, b.intensity);
        assert_eq!(a.range, b.range);
    }
    assert!(loaded.lights.iter().any(|l| l.cone.is_some()));
    assert!(loaded.lights.iter().any(|l| l.range.is_none()));
}

/// A spot on a child node: the parent's and the child's transforms both apply, and the
/// spot points along the node's -Z.
#[test]
fn node_hierarchy_places_and_turns_lights() {
    let mut document = lamp_room_json();
    let nodes = document["nodes"].as_array_mut().expect("nodes");
    let light_node = nodes
        .iter()
        .position(|n| n["extensions"]["KHR_lights_punctual"]["light"] == json!(2))
        .expect("the sphere spot's node");
    // The light's own node: 1 m up, turned 90 degrees about Y (-Z becomes -X).
    let half = std::f32::consts::FRAC_PI_4;
    nodes[light_node]["translation"] = json!([0.0, 1.0, 0.0]);
    nodes[light_node]["rotation"] = json!([0.0, half.sin(), 0.0, half.cos()]);
    // Its parent: moved 2 m along +X.
    nodes.push(json!({ "translation": [2.0, 0.0, 0.0], "children": [light_node] }));
    let roots: Vec<usize> = (0..nodes.len()).filter(|&i| i != light_node).collect();
    document["scenes"][0]["nodes"] = json!(roots);
    let scene = load_json(&document).expect("loads");
    let spot = scene
        .lights
        .iter()
        .find(|l| l.name == "sphere spot")
        .expect("the spot");
    assert!(
        spot.position.abs_diff_eq(Vec3::new(2.0, 1.0, 0.0), 1e-5),
        "{spot:?}"
    );
    assert!(spot.direction.abs_diff_eq(Vec3::NEG_X, 1e-5), "{spot:?}");
}

/// Edits light 2 (a spot) of the lamp room and returns the load's error text.
fn error_for(edit: impl FnOnce(&mut Value)) -> String {
    let mut document = lamp_room_json();
    edit(&mut document["extensions"]["KHR_lights_punctual"]["lights"][2]);
    match load_json(&document) {
        Ok(scene) => panic!("loaded with lights {:?}", scene.lights),
        Err(error) => {
            assert!(matches!(error, SceneError::InvalidGltf { .. }), "{error:?}");
            error.to_string()
        }
    }
}

#[test]
fn bad_light_values_are_errors_naming_the_file_and_light() {
    type Edit = Box<dyn FnOnce(&mut Value)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "negative intensity",
            Box::new(|l| l["intensity"] = json!(-1.0)),
            "intensity -1",
        ),
        (
            // JSON has no NaN; a number past f32's range reads as infinity.
            "infinite intensity",
            Box::new(|l| l["intensity"] = json!(1e39)),
            "intensity inf",
        ),
        (
            "inner wider than outer",
            Box::new(|l| l["spot"] = json!({ "innerConeAngle": 0.5, "outerConeAngle": 0.4 })),
            "inner cone angle must be in [0, outer = 0.4] radians, got 0.5",
        ),
        (
            "outer past pi/2",
            Box::new(|l| l["spot"] = json!({ "innerConeAngle": 0.1, "outerConeAngle": 1.6 })),
            "outer cone angle must be in (0, pi/2] radians, got 1.6",
        ),
        (
            "outer zero",
            Box::new(|l| l["spot"] = json!({ "innerConeAngle": 0.0, "outerConeAngle": 0.0 })),
            "outer cone angle must be in (0, pi/2] radians, got 0",
        ),
        (
            "negative inner",
            Box::new(|l| l["spot"] = json!({ "innerConeAngle": -0.1, "outerConeAngle": 0.4 })),
            "inner cone angle must be in [0, outer = 0.4] radians, got -0.1",
        ),
        (
            "zero range",
            Box::new(|l| l["range"] = json!(0.0)),
            "range 0",
        ),
        (
            "negative range",
            Box::new(|l| l["range"] = json!(-2.0)),
            "range -2",
        ),
        (
            "negative colour",
            Box::new(|l| l["color"] = json!([1.0, -0.5, 1.0])),
            "color",
        ),
    ];
    for (what, edit, expected) in cases {
        let error = error_for(edit);
        assert!(
            error.contains("lamps.gltf")
                && error.contains("sphere spot")
                && error.contains(expected),
            "{what}: {error}"
        );
    }
}

/// 3.4e38 (f32::MAX), some exporters' "infinite" range, reads as no range, with a
/// warning: never a zero range (UnityGLTF's bug) nor a radius whose square overflows.
#[test]
fn an_infinite_range_reads_as_unbounded_with_a_warning() {
    let mut document = lamp_room_json();
    document["extensions"]["KHR_lights_punctual"]["lights"][2]["range"] = json!(3.4e38);
    let scene = load_json(&document).expect("loads");
    let spot = scene
        .lights
        .iter()
        .find(|l| l.name == "sphere spot")
        .expect("the spot");
    assert_eq!(spot.range, None);
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.message.contains("sphere spot") && w.message.contains("no range")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn directional_lights_are_skipped_with_a_warning() {
    let mut document = lamp_room_json();
    let light = &mut document["extensions"]["KHR_lights_punctual"]["lights"][2];
    light["type"] = json!("directional");
    light.as_object_mut().expect("light").remove("spot");
    light.as_object_mut().expect("light").remove("range");
    let scene = load_json(&document).expect("loads");
    assert_eq!(scene.lights.len(), lamp_room().lights.len() - 1);
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.message.contains("directional")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn a_node_naming_a_missing_light_is_an_error() {
    let mut document = lamp_room_json();
    let nodes = document["nodes"].as_array_mut().expect("nodes");
    let node = nodes
        .iter_mut()
        .find(|n| n.get("extensions").is_some())
        .expect("a light node");
    node["extensions"]["KHR_lights_punctual"]["light"] = json!(99);
    let error = load_json(&document).expect_err("refused").to_string();
    assert!(
        error.contains("lamps.gltf") && error.contains("99"),
        "{error}"
    );
}

/// The asset the `lamps` scene loads is the exporter's output for `lamp_room`, byte for
/// byte: edit `lamp_room` and run with `MANYLIGHTS_WRITE_ASSETS=1` to rewrite it.
#[test]
fn the_committed_lamps_asset_is_the_lamp_room() {
    common::assert_committed_asset_is_export(&lamp_room(), "lamps", "scene_lights");
}

/// The committed `assets/panel/panel.gltf` (a room lit only by its emissive panels) is
/// exactly the export of `procedural::panel_room`, and its panels' radiance (40, glTF's
/// unit factor times `KHR_materials_emissive_strength`) survives the round trip.
#[test]
fn the_committed_panel_asset_is_the_panel_room_and_keeps_its_emission() {
    use manylights_scene::procedural::{PANEL_RADIANCE, panel_room};
    let committed =
        common::assert_committed_asset_is_export(&panel_room(), "panel", "scene_lights");
    let loaded = load_from_memory("panel.gltf", &committed, &MemoryFiles::new()).expect("loads");
    let panel = loaded
        .materials
        .iter()
        .find(|m| m.name == "panel")
        .expect("the panel material");
    assert_eq!(panel.emissive_factor, Vec3::splat(PANEL_RADIANCE));
    let document: Value = serde_json::from_slice(&committed).expect("JSON");
    assert_eq!(
        document["extensionsUsed"],
        json!(["KHR_materials_emissive_strength"])
    );
}
