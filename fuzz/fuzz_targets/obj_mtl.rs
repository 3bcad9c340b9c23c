//! Fuzz target: see `manylights_scene::fuzz_harness::obj_mtl`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = manylights_scene::fuzz_harness::obj_mtl(data);
});
