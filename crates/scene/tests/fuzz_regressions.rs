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

fn target_fn(target: &str) -> fn(&[u8]) {
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
    let outcome = std::panic::catch_unwind(|| run(input));
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
        Ok(()) if elapsed > TIME_LIMIT => Some(format!(
            "{target}/{label}: took {elapsed:?} (limit {TIME_LIMIT:?})"
        )),
        Ok(()) => None,
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
    let seeds = fuzz_harness::seeds();
    assert_eq!(seeds.len(), 6, "two scenes in three formats");
    for (target, name, bytes) in seeds {
        assert!(replay(target, &name, &bytes).is_none());
        // Seeds are valid files: they must load, not merely fail cleanly.
        let file = match target {
            "gltf_json" => "seed.gltf",
            "glb" => "seed.glb",
            _ => "seed.obj",
        };
        if target != "obj_mtl" {
            let files = manylights_scene::MemoryFiles::new();
            manylights_scene::load_from_memory(file, &bytes, &files)
                .unwrap_or_else(|e| panic!("{target}/{name}: {e}"));
        }
    }
}
