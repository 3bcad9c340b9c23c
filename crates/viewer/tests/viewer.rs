//! The viewer under Xvfb on whatever Vulkan driver exists (lavapipe in CI): a scripted
//! 30-frame run exits 0 and writes a screenshot matching `manylights render` with the same
//! settings; a run that switches pipelines mid-way exits 0. Needs `xvfb-run` (Debian/Ubuntu:
//! `apt-get install xvfb`); without it the test fails and says so.

use std::path::Path;
use std::process::{Command, Output};

fn xvfb_run(args: &[&str]) -> Output {
    let found = Command::new("sh")
        .args(["-c", "command -v xvfb-run"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    assert!(
        found,
        "the viewer tests need xvfb-run: install it with `sudo apt-get install xvfb` (or run `cargo xtask test` as root, which does)"
    );
    Command::new("xvfb-run")
        .args([
            "-a",
            "-s",
            "-screen 0 640x480x24",
            env!("CARGO_BIN_EXE_manylights"),
        ])
        .args(args)
        .output()
        .expect("run xvfb-run")
}

fn render(args: &[&str], out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_manylights"))
        .arg("render")
        .args(args)
        // Compared, not timed: the first frame is the warm-up.
        .args(["--warmup-seconds", "0"])
        .arg("--out")
        .arg(out)
        .output()
        .expect("run manylights render")
}

const SETTINGS: [&str; 10] = [
    "--scene",
    "cornell",
    "--size",
    "128x96",
    "--lights",
    "64",
    "--time",
    "1.5",
    "--pipeline",
    "forward-plus",
];

/// Mean FLIP allowed between the viewer's screenshot and `render`'s image. They run the
/// same renderer on the same device, so they should be identical; the threshold only
/// leaves room for a driver that is not deterministic between processes.
const MAX_MEAN_FLIP: f32 = 0.01;

/// Runs the viewer for 30 paused frames with `SETTINGS` and `extra` arguments, checks its
/// screenshot against `manylights render` with the same settings, and returns the viewer's
/// stderr.
fn viewer_matches_render(extra: &[&str]) -> String {
    let dir = tempfile::tempdir().expect("tempdir");
    let screenshot = dir.path().join("viewer.png");
    let mut args: Vec<&str> = vec!["view"];
    args.extend(SETTINGS);
    args.extend([
        "--paused",
        "--frames",
        "30",
        "--screenshot",
        screenshot.to_str().expect("utf-8"),
    ]);
    args.extend(extra);
    let viewer = xvfb_run(&args);
    let stderr = String::from_utf8_lossy(&viewer.stderr).into_owned();
    assert!(
        viewer.status.success(),
        "viewer failed:\n{}\n{stderr}",
        String::from_utf8_lossy(&viewer.stdout),
    );
    let rendered = dir.path().join("render.png");
    let output = render(&SETTINGS, &rendered);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );

    let a = image::open(&screenshot).expect("screenshot").into_rgba8();
    let b = image::open(&rendered).expect("render").into_rgba8();
    assert_eq!(
        a.dimensions(),
        (128, 96),
        "the window (and screenshot) has the requested size"
    );
    let first = a.get_pixel(0, 0);
    assert!(
        a.pixels().any(|p| p != first),
        "the screenshot is a uniform colour"
    );
    let (mean, _) = manylights_tests::flip_mean(&b, &a);
    assert!(
        mean <= MAX_MEAN_FLIP,
        "viewer screenshot vs render: mean FLIP {mean}"
    );
    stderr
}

#[test]
fn scripted_run_matches_render() {
    viewer_matches_render(&[]);
}

/// The device is destroyed at frame 10 (as a driver reset would lose it): the viewer
/// recreates the device and every resource, says so, and its last frame equals `render`'s.
#[test]
fn viewer_recovers_from_a_lost_device() {
    let stderr = viewer_matches_render(&["--script", "10:lose-device=true"]);
    assert!(
        stderr.contains("the GPU device was lost") && stderr.contains("recreated the device"),
        "the viewer did not report the recovery:\n{stderr}"
    );
}

#[test]
fn switching_pipelines_during_a_run() {
    let dir = tempfile::tempdir().expect("tempdir");
    let screenshot = dir.path().join("switch.png");
    let output = xvfb_run(&[
        "view",
        "--scene",
        "cornell",
        "--size",
        "160x120",
        "--lights",
        "32",
        "--frames",
        "24",
        "--script",
        "4:pipeline=forward-plus;8:pipeline=deferred;10:gbuffer=packed;12:lighting=fragment;14:debug-view=heatmap;16:debug-view=normal;18:lights=200;20:pipeline=naive;20:debug-view=none",
        "--screenshot",
        screenshot.to_str().expect("utf-8"),
    ]);
    assert!(
        output.status.success(),
        "viewer failed:\n{}\n{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(screenshot.exists());
}

#[test]
fn a_bad_script_is_a_clear_error() {
    let output = xvfb_run(&[
        "view",
        "--scene",
        "cornell",
        "--size",
        "64x48",
        "--frames",
        "2",
        "--script",
        "3:pipeline=raytraced",
    ]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("unknown pipeline `raytraced`"), "{stderr}");
}
