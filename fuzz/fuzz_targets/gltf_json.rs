//! Fuzz target: see `manylights_scene::fuzz_harness::gltf_json`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = manylights_scene::fuzz_harness::gltf_json(data);
});
