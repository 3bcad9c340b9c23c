//! The `manylights render` command: a real render writes a PNG and prints per-pass GPU
//! times; bad arguments give a clear message and a non-zero exit, never a panic.

use std::process::{Command, Output};

/// Runs the binary. A `render` here is checked, not timed: its warm-up is the first frame
/// (a CPU rasteriser's GPU time never settles, and each render warmed up for 20 s).
fn manylights(args: &[&str]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_manylights"));
    command.args(args);
    if args.first() == Some(&"render") {
        command.args(["--warmup-seconds", "0"]);
    }
    command.output().expect("run manylights")
}

fn assert_fails_with(args: &[&str], expected: &[&str]) {
    let output = manylights(args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{args:?} should fail");
    assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    for text in expected {
        assert!(
            stderr.contains(text),
            "{args:?}: stderr lacks '{text}':\n{stderr}"
        );
    }
}

#[test]
fn renders_cornell_to_a_png_and_reports_gpu_times() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("cornell.png");
    let output = manylights(&[
        "render",
        "--scene",
        "cornell",
        "--lights",
        "16",
        "--size",
        "64x48",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains("adapter:"), "{stdout}");
    // The default pipeline is clustered deferred, with automatic exposure.
    assert!(
        stdout.contains("deferred compact tiles pipeline"),
        "{stdout}"
    );
    assert!(
        stdout.contains("g-buffer") || stdout.contains("GPU timings unavailable"),
        "{stdout}"
    );
    assert!(stdout.contains("exposure: automatic"), "{stdout}");
    let image = image::open(&out).expect("a PNG was written").into_rgba8();
    assert_eq!(image.dimensions(), (64, 48));
    let first = image.get_pixel(0, 0);
    assert!(
        image.pixels().any(|p| p != first),
        "the image is a uniform colour"
    );
}

#[test]
fn unknown_scene_file_is_named() {
    assert_fails_with(
        &["render", "--scene", "/no/such/scene.gltf"],
        &["/no/such/scene.gltf", "not found"],
    );
    assert_fails_with(
        &["render", "--scene", "scene.fbx"],
        &["scene.fbx", "unsupported scene format"],
    );
}

#[test]
fn zero_size_is_refused() {
    assert_fails_with(&["render", "--size", "0x480"], &["at least 1x1", "0x480"]);
    assert_fails_with(&["render", "--size", "640by480"], &["WIDTHxHEIGHT"]);
}

#[test]
fn unknown_pipeline_is_refused() {
    assert_fails_with(
        &["render", "--pipeline", "raytraced"],
        &["raytraced", "naive"],
    );
}

#[test]
fn negative_light_count_is_refused() {
    assert_fails_with(
        &["render", "--lights", "-5"],
        &["--lights -5", "lights.count"],
    );
}

#[test]
fn unknown_camera_preset_lists_the_presets() {
    assert_fails_with(
        &[
            "render", "--scene", "cornell", "--camera", "nowhere", "--size", "8x8",
        ],
        &["nowhere", "default"],
    );
}

#[test]
fn forward_plus_with_cluster_options_and_stats() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("heatmap.png");
    let output = manylights(&[
        "render",
        "--scene",
        "cornell",
        "--pipeline",
        "forward-plus",
        "--lights",
        "64",
        "--size",
        "64x48",
        "--tiles",
        "8x6",
        "--slices",
        "12",
        "--z-scheme",
        "log-near",
        "--first-slice",
        "0.5",
        "--z-range",
        "camera",
        "--debug-view",
        "heatmap",
        "--stats",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains("clusters: 576 clusters"), "{stdout}");
    assert!(stdout.contains("false positives"), "{stdout}");
    assert!(stdout.contains("heatmap legend"), "{stdout}");
    assert!(out.exists());
}

#[test]
fn deferred_with_layout_and_lighting_path() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (gbuffer, lighting) in [
        ("full", "fragment"),
        ("compact", "compute"),
        ("packed", "tiles"),
    ] {
        let out = dir.path().join(format!("{gbuffer}.png"));
        let output = manylights(&[
            "render",
            "--scene",
            "cornell",
            "--pipeline",
            "deferred",
            "--gbuffer",
            gbuffer,
            "--lighting",
            lighting,
            "--lights",
            "32",
            "--size",
            "48x32",
            "--out",
            out.to_str().expect("utf-8"),
        ]);
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(
            output.status.success(),
            "{stdout}\n{}",
            String::from_utf8_lossy(&output.stderr)
        );
        assert!(
            stdout.contains("g-buffer") && stdout.contains(&format!("lighting ({lighting})")),
            "{stdout}"
        );
    }
    assert_fails_with(
        &[
            "render",
            "--pipeline",
            "naive",
            "--debug-view",
            "albedo",
            "--size",
            "8x8",
        ],
        &["naive pipeline has no clusters or G-buffer"],
    );
    assert_fails_with(
        &[
            "render",
            "--pipeline",
            "forward-plus",
            "--debug-view",
            "normal",
            "--size",
            "8x8",
        ],
        &["no G-buffer"],
    );
}

/// The warm-up's limit is a finite number of seconds, 0 or more (parsed before any GPU
/// work: these runs end at once).
#[test]
fn a_warm_up_limit_that_is_no_number_of_seconds_is_refused() {
    for bad in ["nan", "inf", "-1", "soon"] {
        let output = Command::new(env!("CARGO_BIN_EXE_manylights"))
            .args(["render", "--warmup-seconds", bad])
            .output()
            .expect("run manylights");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            !output.status.success(),
            "--warmup-seconds {bad} should fail"
        );
        assert!(!stderr.contains("panicked"), "{bad}: {stderr}");
        assert!(
            stderr.contains("--warmup-seconds") && stderr.contains("not a number of seconds"),
            "{bad}: {stderr}"
        );
    }
}

#[test]
fn non_finite_light_settings_are_refused() {
    assert_fails_with(
        &[
            "render",
            "--scene",
            "cornell",
            "--size",
            "8x8",
            "--intensity",
            "nan",
        ],
        &["intensity"],
    );
    assert_fails_with(
        &[
            "render", "--scene", "cornell", "--size", "8x8", "--radius", "inf",
        ],
        &["radius"],
    );
    assert_fails_with(
        &[
            "render",
            "--scene",
            "cornell",
            "--size",
            "8x8",
            "--threshold",
            "-1",
        ],
        &["threshold"],
    );
    assert_fails_with(
        &[
            "render", "--scene", "cornell", "--size", "8x8", "--time", "nan",
        ],
        &["time"],
    );
}

/// Headless work touches no display server: without `XDG_RUNTIME_DIR` (containers, CI,
/// ssh) a render prints no `error:` line from libwayland (Mesa's device-select layer used
/// to connect to Wayland while listing GPUs), and nothing else on stderr is an error.
#[test]
fn a_headless_render_without_a_runtime_dir_prints_no_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("cornell.png");
    let output = Command::new(env!("CARGO_BIN_EXE_manylights"))
        .args([
            "render",
            "--scene",
            "cornell",
            "--size",
            "32x24",
            "--lights",
            "8",
            "--warmup-seconds",
            "0",
            "--out",
        ])
        .arg(&out)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("NODEVICE_SELECT")
        .output()
        .expect("run manylights");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "render failed: {stderr}");
    assert!(out.exists(), "no PNG written");
    assert!(
        !stderr.to_lowercase().contains("error"),
        "a successful headless render printed errors:\n{stderr}"
    );
}
