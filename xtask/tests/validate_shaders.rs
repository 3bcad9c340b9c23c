//! `cargo xtask validate-shaders` rejects a deliberately broken shader, naming its file and
//! line, with a non-zero exit. That the real shaders pass is xtask's unit test
//! `every_declared_program_validates`, which runs the same validation of every program in
//! process: a second run through the command cost 517 s beside another binary (2 cores).

use std::path::Path;
use std::process::Command;

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("mkdir");
    for entry in std::fs::read_dir(from).expect("read_dir") {
        let entry = entry.expect("entry");
        let target = to.join(entry.file_name());
        if entry.path().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).expect("copy");
        }
    }
}

#[test]
fn broken_shader_fails_with_file_and_line() {
    // Every crate's shaders/ folder, merged into the one tree --shaders-dir reads.
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("../crates");
    let dir = tempfile::tempdir().expect("tempdir");
    for entry in std::fs::read_dir(&crates).expect("crates/") {
        let shaders = entry.expect("entry").path().join("shaders");
        if shaders.is_dir() {
            copy_dir(&shaders, dir.path());
        }
    }
    // Line 2 calls a function that does not exist.
    let broken = dir.path().join("common/material.wgsl");
    let original = std::fs::read_to_string(&broken).expect("read");
    std::fs::write(
        &broken,
        format!("// broken on purpose\nconst BROKEN: f32 = no_such_function();\n{original}"),
    )
    .expect("write");
    let output = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(["validate-shaders", "--shaders-dir"])
        .arg(dir.path())
        .output()
        .expect("run xtask");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success(),
        "a broken shader must fail validation"
    );
    assert!(
        stderr.contains("shaders/common/material.wgsl:2"),
        "{stderr}"
    );
}
