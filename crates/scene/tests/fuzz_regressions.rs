//! Replays every committed fuzz input (`fuzz/regressions/<target>/`: crashes, hangs and
//! oversized allocations the fuzzers found, each fixed) and the seed corpus through the same
//! entry points the fuzz targets use, without the fuzzer. Each must finish without a panic
//! (a loader error is a pass) and within a time limit.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use manylights_scene::fuzz_harness;

/// Generous for a debug build on a slow CI core; the fuzzer's own limit is 10 s (release).
const TIME_LIMIT: Duration = Duration::from_secs(60);

fn regressions_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/regressions")
}

type Target = fn(&[u8]) -> manylights_scene::Result<manylights_scene::Scene>;

fn target_fn(target: &str) -> Target {
    match target {
        "gltf_json" => fuzz_harness::gltf_json,
        "glb" => fuzz_harness::glb,
        "obj_mtl" => fuzz_harness::obj_mtl,
        other => panic!("unknown fuzz target folder '{other}'"),
    }
}

/// Runs `input` and returns a failure message, if any.
fn replay(target: &str, label: &str, input: &[u8]) -> Option<String> {
    let run = target_fn(target);
    let started = Instant::now();
    // A loader error is a pass here: only panics and hangs are failures.
    let outcome = std::panic::catch_unwind(|| run(input).map(drop));
    let elapsed = started.elapsed();
    match outcome {
        Err(panic) => {
            let message = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Some(format!("{target}/{label}: panicked: {message}"))
        }
        Ok(_) if elapsed > TIME_LIMIT => Some(format!(
            "{target}/{label}: took {elapsed:?} (limit {TIME_LIMIT:?})"
        )),
        Ok(_) => None,
    }
}

#[test]
fn committed_fuzz_inputs_load_or_fail_cleanly() {
    let mut failures = Vec::new();
    let mut replayed = 0;
    for target in ["gltf_json", "glb", "obj_mtl"] {
        let folder = regressions_dir().join(target);
        let entries =
            std::fs::read_dir(&folder).unwrap_or_else(|e| panic!("{}: {e}", folder.display()));
        for entry in entries {
            let path = entry.expect("directory entry").path();
            if path.file_name().is_some_and(|n| n == ".gitkeep") {
                continue;
            }
            let input = std::fs::read(&path).expect("read input");
            let label = path.file_name().unwrap_or_default().to_string_lossy();
            failures.extend(replay(target, &label, &input));
            replayed += 1;
        }
    }
    println!("replayed {replayed} committed fuzz inputs");
    // Every committed input was replayed (7 when this was written: 2 per target and one
    // slow OBJ/MTL unit); a folder that went missing or empty is a failure, not a pass.
    assert!(
        replayed >= 7,
        "only {replayed} committed fuzz inputs were replayed"
    );
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn seeds_load_and_keep_the_invariants() {
    let mut seeds = fuzz_harness::seeds();
    assert_eq!(
        seeds.len(),
        7,
        "two scenes in three formats, and an optimized glTF"
    );
    // The optimized seed (quantized, meshopt-compressed, sparse, emissive, a strip, two
    // instances) has no texture and materials of its own: it must load, with its emission.
    let (target, name, bytes) = seeds.pop().expect("seeds");
    assert_eq!((target, name.as_str()), ("gltf_json", "optimized"));
    assert!(replay(target, &name, &bytes).is_none());
    let optimized = target_fn(target)(&bytes).unwrap_or_else(|e| panic!("optimized: {e}"));
    assert_eq!(optimized.meshes.len(), 1);
    assert_eq!(optimized.instances.len(), 2);
    assert_eq!(optimized.triangle_count(), 2);
    assert!(optimized.warnings.is_empty(), "{:?}", optimized.warnings);
    assert!(optimized.features().emissive);
    assert_eq!(
        optimized.meshes[0].positions[1],
        glam::Vec3::new(1000.0, 0.0, 0.0)
    );
    assert_eq!(optimized.meshes[0].uvs[2], glam::Vec2::splat(0.5));
    let source = fuzz_harness::seed_scene();
    for (target, name, bytes) in seeds {
        assert!(replay(target, &name, &bytes).is_none());
        // Seeds are valid files: through the harness they must load, not merely fail
        // cleanly, and bring their geometry and materials (for OBJ, from the MTL part
        // after the separator).
        let scene = target_fn(target)(&bytes).unwrap_or_else(|e| panic!("{target}/{name}: {e}"));
        assert!(scene.triangle_count() > 0, "{target}/{name}: no triangles");
        assert!(
            scene.warnings.is_empty(),
            "{target}/{name}: {:?}",
            scene.warnings
        );
        assert!(
            scene
                .materials
                .iter()
                .any(|m| m.base_color_texture.is_some()),
            "{target}/{name}: the seed's textured material is missing"
        );
        if target != "obj_mtl" {
            // (OBJ export numbers its materials; the glTF loader adds a "default" one.)
            let expected: Vec<&str> = source
                .materials
                .iter()
                .map(|m| m.name.as_str())
                .chain(["default"])
                .collect();
            for material in &scene.materials {
                assert!(
                    expected.contains(&material.name.as_str()),
                    "{target}/{name}: material {:?} is not the seed's ({expected:?})",
                    material.name
                );
            }
        }
        if name == "cornell" {
            assert_eq!(
                scene.triangle_count(),
                source.triangle_count(),
                "{target}/{name}"
            );
        }
    }
}

/// Inputs may name the harness's extra files (a binary buffer `scene.bin`, the seed's
/// textures); a file it does not hold is a loader error.
#[test]
fn fuzz_inputs_reach_the_referenced_files() {
    let document = |uri: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[]}}],"buffers":[{{"uri":"{uri}","byteLength":4096}}]}}"#
        )
    };
    fuzz_harness::gltf_json(document("scene.bin").as_bytes()).expect("scene.bin is offered");
    let error = fuzz_harness::gltf_json(document("other.bin").as_bytes())
        .expect_err("other.bin is not offered");
    assert!(error.to_string().contains("other.bin"), "{error}");
}

/// The invariants the fuzzers rely on do fail: each broken scene panics.
#[test]
fn invariant_check_catches_broken_scenes() {
    let good = fuzz_harness::seed_scene();
    fuzz_harness::assert_scene_invariants(&good);
    type Break = fn(&mut manylights_scene::Scene);
    let breaks: [(&str, Break); 6] = [
        ("index past the vertices", |s| {
            s.meshes[0].indices[0] = u32::MAX
        }),
        ("missing normals", |s| {
            s.meshes[0].normals.pop();
        }),
        ("non-finite position", |s| {
            s.meshes[0].positions[0].x = f32::NAN
        }),
        ("material", |s| s.meshes[0].material = 99),
        ("instance mesh", |s| s.instances[0].mesh = 99),
        ("texel data", |s| {
            s.textures[0].rgba8.pop();
        }),
    ];
    for (what, break_it) in breaks {
        let mut scene = good.clone();
        break_it(&mut scene);
        let caught = std::panic::catch_unwind(|| fuzz_harness::assert_scene_invariants(&scene));
        assert!(caught.is_err(), "{what} passed the invariant check");
    }
}
