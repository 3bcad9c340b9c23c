//! The page's test (`cargo xtask web-test`, a command of its own: docs/testing.md): builds
//! the page, renders fixed frames in headless Chromium (WebGPU on SwiftShader) and
//! natively (`manylights render` on lavapipe) with the same settings, and compares them.
//!
//! Each case is one list of `render` options. The page gets them as its URL (`--a b` is
//! `a=b`) plus `paused&frames=2&hide-ui`, and the native binary as its command line. The
//! exposure is fixed (`--exposure`): an automatic one would compare two histograms as well.
//!
//! What may legitimately differ: two rasterisers (lavapipe's, and SwiftShader's behind
//! Chrome) and two shader compilers (naga's SPIR-V into Mesa's LLVM, and naga's WGSL into
//! Tint, then SwiftShader's). The tolerance follows from what the specifications leave to
//! each implementation:
//! - **Colour conversions.** The page's frame goes through two 8-bit sRGB conversions more
//!   than the native one (the viewer samples the tonemapped image, decoding it, and writes
//!   it to the canvas through an sRGB view, encoding it); each may round a channel to the
//!   neighbouring step, and the tonemap's own encoding may too: [`STEP_TOLERANCE`] = 3.
//! - **Triangle edges.** Sub-pixel precision differs, so a pixel whose centre lies within
//!   a sub-pixel step of an edge may be covered on one side and not the other:
//!   [`manylights_tests::GOLDEN_CHANGED_FRACTION`] of the pixels may differ by more (the golden test's bound
//!   for another driver).
//! - **Texture filtering.** How sRGB texels are decoded and filtered, and which mip level
//!   a pixel takes, are left to the implementation within a few bits of precision, so a
//!   textured pixel has no per-pixel bound (measured: Sponza's floor differs by up to
//!   ~10 steps; the mean over the frame is 1.4 steps). Textured cases are held to a
//!   chosen, not derived, bound instead: at least [`TEXTURED_WITHIN_FRACTION`] of the
//!   pixels within [`STEP_TOLERANCE`] and a mean difference under
//!   [`TEXTURED_MEAN_STEPS`]; a missing texture, light or pass moves far more than that.
//!   So are frames where much of the image lies on triangle edges (the glass room's 400
//!   sparks, a pixel or two wide at the test's size: 51 of 12,288 pixels differ), beyond
//!   the edge bound above, which assumes edges are a small part of the frame.
//!
//! Each frame must also have content: lit pixels over a stated fraction.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context as _, bail};
use manylights_tests::{changed_pixels_allowed, channel_steps};

use crate::web::{self, WebOptions, workspace_root};

/// 8-bit steps a channel may differ by (see the module's documentation).
const STEP_TOLERANCE: u8 = 3;
/// Textured cases: the fraction of pixels that must be within [`STEP_TOLERANCE`], and the
/// largest mean difference in steps.
const TEXTURED_WITHIN_FRACTION: f64 = 0.95;
const TEXTURED_MEAN_STEPS: f64 = 2.0;

/// Each frame of the comparison is this small (CI renders every case twice on the CPU).
const SIZE: &str = "128x96";
/// The measure case's frame and cluster grid (see [`measure_matrix`]).
const MEASURE_SIZE: &str = "64x48";
const MEASURE_GRID: &str = "8x6x16:log-near";
/// A case's frame must have at least this fraction of pixels brighter than black (every
/// case lights most of its view; a failed frame is black or the clear colour).
const MIN_LIT_FRACTION: f64 = 0.25;
/// How long one page may take to load, compile its shaders on SwiftShader and draw, and
/// the measure case's run (110 s on a fresh clone; see [`measure_matrix`], whose warm-ups
/// stop at 2 s a configuration).
const PAGE_TIMEOUT_MS: u64 = 420_000;

struct Case {
    name: &'static str,
    /// The scene has textures, or geometry a pixel or two wide over much of the frame
    /// (compared by [`TEXTURED_WITHIN_FRACTION`]).
    textured: bool,
    /// `manylights render` options (without `--size`, `--out`), separated by spaces.
    options: &'static str,
}

impl Case {
    fn options(&self) -> Vec<&'static str> {
        self.options.split_whitespace().collect()
    }
}

/// Every pipeline, each deferred layout (the visibility buffer on Sponza) and lighting path
/// the page can run, a far field, spots and exact shadows, on the small scenes (Sponza's
/// 13 MB of textures load too, in its own cases).
const CASES: [Case; 22] = [
    Case {
        name: "naive",
        textured: false,
        options: "--scene cornell --pipeline naive --lights 64",
    },
    Case {
        name: "forward-plus",
        textured: false,
        options: "--scene cornell --pipeline forward-plus --lights 300",
    },
    Case {
        name: "deferred-compact-compute",
        textured: false,
        options: "--scene cornell --pipeline deferred --gbuffer compact --lighting compute --lights 300",
    },
    Case {
        name: "deferred-compact-tiles-spots",
        textured: false,
        options: "--scene cornell --pipeline deferred --gbuffer compact --lighting tiles --lights 300 --spot-fraction 0.5",
    },
    Case {
        name: "deferred-compact-fragment",
        textured: false,
        options: "--scene cornell --pipeline deferred --gbuffer compact --lighting fragment --lights 300",
    },
    Case {
        name: "deferred-packed-compute",
        textured: false,
        options: "--scene cornell --pipeline deferred --gbuffer packed --lighting compute --lights 300",
    },
    Case {
        name: "deferred-packed-fragment",
        textured: false,
        options: "--scene cornell --pipeline deferred --gbuffer packed --lighting fragment --lights 300",
    },
    Case {
        name: "far-field-tree",
        textured: false,
        options: "--scene cornell --pipeline deferred --lights 300 --falloff inverse-square --far-field tree:1",
    },
    Case {
        name: "spots-lamps",
        textured: true,
        options: "--scene lamps --pipeline forward-plus --lights 200 --spot-fraction 0.5",
    },
    Case {
        // glTF's metallic-roughness: gold and black spheres from mirror to rough, lit by
        // the file's one light.
        name: "pbr-spheres",
        textured: false,
        options: "--scene spheres --pipeline deferred --lights 0",
    },
    Case {
        // Blended panes and sparks over the opaque frame (issue 45), stored as per-pixel
        // layers, shaded in compute from deferred's clusters and composited back to front
        // (issue 61: fragment-stage storage atomics on WebGPU).
        name: "blended-glass",
        textured: true,
        options: "--scene glass --pipeline deferred --lights 100",
    },
    Case {
        // Textured blended surfaces through deferred's layers: their store samples the
        // banners' and embers' textures, which WGSL allows only in uniform control flow
        // (Tint, unlike naga, refused the first store program, which sampled after its
        // depth test returned).
        name: "blended-sponza-glass",
        textured: true,
        // The embers glow but light nothing, as this case was measured before they did.
        options: "--scene sponza-glass --pipeline deferred --lights 500 --emissive-lights off",
    },
    Case {
        // The post stack (issue 62): bloom's chain, on the glowing sparks. Temporal
        // anti-aliasing runs on the page too, but its frame depends on how many frames
        // (and jitters) came before, which `render`'s warm-up and the page do not share.
        // Bloom set by its path: natively `--set post.bloom=0.1`, on the page
        // `?post.bloom=0.1` (settings as data, issue 79).
        name: "post-bloom",
        textured: true,
        options: "--scene glass --pipeline deferred --lights 40 --set post.bloom=0.1",
    },
    // Area lights (issue 63): spheres in Forward+, squares in deferred, squares on PBR
    // materials. (The panel room,
    // lit by its emissive quad, covers too little of its frame for the lit-pixel floor;
    // exact shadows in deferred's tiles meet lavapipe's known runs of black pixels.)
    Case {
        name: "area-spheres",
        textured: false,
        options: "--scene cornell --pipeline forward-plus --lights 32 --light-shape sphere:0.5",
    },
    Case {
        name: "area-rects",
        textured: false,
        options: "--scene cornell --pipeline deferred --lights 64 --light-shape rect:0.4",
    },
    Case {
        // The cornell cases shade Blinn-Phong; Sponza's glTF materials take PBR's specular
        // term through the linearly transformed cosines' table (`lights::SpecularTables`).
        name: "area-rects-pbr",
        textured: true,
        options: "--scene sponza --pipeline deferred --lights 300 --light-shape rect:0.5",
    },
    Case {
        name: "sponza",
        textured: true,
        options: "--scene sponza --pipeline deferred --lights 500",
    },
    Case {
        // Exact shadows from positions rebuilt from depth (issue 46: a black block on the
        // lit floor beside the wall), in the default layout, and naive's rays beside them.
        name: "shadows-wall-deferred",
        textured: false,
        options: "--scene wall --lights 0 --pipeline deferred --shadows exact",
    },
    Case {
        name: "shadows-wall-naive",
        textured: false,
        options: "--scene wall --lights 0 --pipeline naive --shadows exact",
    },
    Case {
        // The gallery's corridor, where the page drew the balustrade and the floor black.
        name: "shadows-sponza-deferred",
        textured: true,
        options: "--scene sponza --pipeline deferred --lights 300 --shadows exact --camera 10,6.5,-3.5,107,-13,65",
    },
    Case {
        name: "shadows-sponza-naive",
        textured: true,
        options: "--scene sponza --pipeline naive --lights 300 --shadows exact --camera 10,6.5,-3.5,107,-13,65",
    },
    Case {
        // Sponza's textures, normal maps and alpha masks through the resolve's explicit
        // gradients.
        name: "sponza-visibility",
        textured: true,
        options: "--scene sponza --pipeline deferred --gbuffer visibility --lights 500",
    },
];

/// Shared by every case: a fixed exposure, time and seed.
const COMMON: [&str; 6] = ["--exposure", "1.5", "--time", "0.5", "--seed", "3"];

/// `--a b --c` as a URL query: `a=b&c`; `--set PATH=VALUE` is the page's `PATH=VALUE`.
fn query(options: &[&str]) -> String {
    let mut parts = Vec::new();
    let mut i = 0;
    while i < options.len() {
        let key = options[i].trim_start_matches("--");
        match options.get(i + 1).filter(|v| !v.starts_with("--")) {
            Some(assignment) if key == "set" => {
                parts.push(assignment.to_string());
                i += 2;
            }
            Some(value) => {
                parts.push(format!("{key}={value}"));
                i += 2;
            }
            None => {
                parts.push(key.to_string());
                i += 1;
            }
        }
    }
    parts.join("&")
}

fn chromium() -> anyhow::Result<PathBuf> {
    let path = PathBuf::from("/usr/bin/chromium");
    if !path.exists() {
        web::apt_install(&["chromium"], "the page's headless test (Chromium)")?;
    }
    Ok(path)
}

fn cases_json(out: &Path, chromium: &Path) -> anyhow::Result<PathBuf> {
    let mut cases: Vec<serde_json::Value> = CASES
        .iter()
        .map(|case| {
            let mut options = case.options();
            options.extend(COMMON);
            options.extend(["--size", SIZE, "--frames", "2", "--paused", "--hide-ui"]);
            serde_json::json!({"name": case.name, "query": query(&options), "webgpu": true})
        })
        .collect();
    // The page without WebGPU must explain itself, not stay blank.
    cases.push(serde_json::json!({"name": "no-webgpu", "query": "scene=cornell", "webgpu": false}));
    // A user's own scene through the file picker, and a file that is not one.
    let root = workspace_root();
    let sample = root.join("assets/gltf-samples/SimpleInstancing/SimpleInstancing.glb");
    let not_a_scene = root.join("assets/gltf-samples/SimpleMeshes/screenshot.png");
    for (name, file) in [("open-glb", sample), ("open-not-a-scene", not_a_scene)] {
        cases.push(serde_json::json!({
            "name": name, "query": format!("scene=cornell&size={SIZE}&hide-ui&lights=50"),
            "webgpu": true, "until": ["running", "error"], "files": [file],
        }));
    }
    // F12 downloads the frame, without the panels, as a PNG: the forward-plus case's
    // settings on a running page (panels shown), compared with that case's native frame.
    let mut screenshot = CASES[1].options();
    screenshot.extend(COMMON);
    screenshot.extend(["--size", SIZE, "--paused"]);
    cases.push(serde_json::json!({
        "name": "screenshot", "query": query(&screenshot),
        "webgpu": true, "until": ["running", "error"], "downloadKey": "F12",
    }));
    // The measure panel: the lab's matrix run in the page on cornell, every pipeline
    // without a far field; its bench.json must parse and replot natively. The page is
    // photographed with the results over the canvas (docs/images/web-measure-chromium.png).
    // The viewer's own frame at a quarter of the window's size: at the window's 1100x800,
    // SwiftShader drew the scene behind the panels for 24 s before the run and 50 s after
    // it (the screenshot waits for a frame), of the case's 155 s alone; at 275x200 the case
    // takes 50 s, and the results cover the canvas either way.
    cases.push(serde_json::json!({
        "name": "measure", "query": "scene=cornell&lights=50&paused&size=275x200",
        "webgpu": true, "until": ["running", "error"], "viewport": {"width": 1100, "height": 800},
        "measure": measure_matrix(), "screenshot": true,
    }));
    // The page as a person sees it (the README's screenshot): Sponza with the panels, after
    // 3 frames (the panel shows the GPU time of a frame before; with 10 frames the case took
    // 107 s of SwiftShader on the 2-core machine, for the same picture).
    cases.push(serde_json::json!({
        "name": "page", "query": "scene=sponza&lights=2000&frames=3&paused&time=0.5",
        "webgpu": true, "viewport": {"width": 1280, "height": 720}, "screenshot": true,
    }));
    let file = out.join("cases.json");
    let json = serde_json::json!({
        "site": web::web_dir(),
        "cases": cases,
        "chromium": chromium,
        "timeoutMs": PAGE_TIMEOUT_MS,
        // Side by side, a browser per core (web/test.mjs says why).
        "workers": crate::test_runner::workers(),
    });
    std::fs::write(&file, serde_json::to_string_pretty(&json)?)?;
    Ok(file)
}

/// The matrix the measure case runs: every pipeline without a far field, kept
/// small because SwiftShader is slow at exactly what a clustered frame does (measured at
/// 128x96 on the 16x9x48 grid: 1.2 s bounding the visible samples, 1.4 s filling the
/// lists, 4.6 s cutting the far field per cluster, and warm-ups that never settled ran to
/// the default 20 s: the run took 408 s of a 420 s timeout). A quarter of the pixels, a
/// grid of 768 clusters instead of 6,912 and 2 s warm-ups test the same code paths in
/// 110 s; the case checks that the page's lab runs and writes a bench.json the native lab
/// replots, not SwiftShader's speed.
fn measure_matrix() -> serde_json::Value {
    serde_json::json!({
        "pipelines": ["naive", "forward-plus", "deferred"],
        "lights": [32],
        "sizes": [MEASURE_SIZE],
        "grids": [MEASURE_GRID],
        // The far field's page path is the `far-field-tree` case's: with it here too its
        // two configurations (cutting the tree per cluster is SwiftShader's slowest pass)
        // were most of this case's minutes.
        "far_fields": ["off"],
        "warmup_frames": 2,
        "warmup_seconds": 2.0,
        "frames": 3,
        "reference_samples": 64,
    })
}

/// The measure case: the run ended without an error, every configuration has an error
/// against the reference (and a GPU time where the browser gave timestamps) and its error
/// map on the page, and `manylights bench --replot` draws the page's bench.json.
fn judge_measure(result: Option<&serde_json::Value>, out: &Path) -> anyhow::Result<Vec<String>> {
    let Some(result) = result else {
        return Ok(vec!["no result".into()]);
    };
    let messages = result["messages"].as_array().cloned().unwrap_or_default();
    if result["measure"] != "done" || !messages.is_empty() {
        return Ok(vec![format!(
            "the run ended '{}' ({}) with {} message(s): {messages:?}",
            result["measure"],
            result["measure_error"],
            messages.len()
        )]);
    }
    let Some(bench) = result["bench"].as_str() else {
        return Ok(vec!["the page offered no bench.json".into()]);
    };
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(bench)?).context("the page's bench.json")?;
    let mut problems = Vec::new();
    let results = report["results"].as_array().cloned().unwrap_or_default();
    // naive, Forward+ and deferred.
    if results.len() < 3 || report["interrupted"] != false {
        problems.push(format!(
            "{} configurations measured (interrupted: {})",
            results.len(),
            report["interrupted"]
        ));
    }
    // The page shows each configuration's error map (the naive image is the reference at
    // these 32 lights, so every configuration has one).
    let maps = result["error_maps"].as_u64().unwrap_or(0);
    if maps != results.len() as u64 {
        problems.push(format!(
            "the page shows {maps} error maps for {} configurations",
            results.len()
        ));
    }
    let timestamps = report["timestamps"] == true;
    for r in &results {
        let error = r["accuracy"]["f64_mean_relative"].as_f64();
        let timed = r["gpu_total_median_ms"].as_f64().is_some_and(|ms| ms > 0.0);
        if !r["error"].is_null() || !error.is_some_and(f64::is_finite) || (timestamps && !timed) {
            problems.push(format!(
                "{} failed, or has no error or time: {r}",
                r["config"]
            ));
        }
    }
    let replot = out.join("measure-replot");
    std::fs::create_dir_all(&replot)?;
    std::fs::copy(bench, replot.join("bench.json"))?;
    let status = Command::new(workspace_root().join("target/release/manylights"))
        .args(["bench", "--replot"])
        .arg(&replot)
        .status()
        .context("running manylights bench --replot")?;
    let drawn = ["REPORT.md", "error_vs_time.svg", "gpu_ms_vs_lights.svg"]
        .iter()
        .all(|file| replot.join(file).exists());
    if !status.success() || !drawn {
        problems.push(format!(
            "`manylights bench --replot` did not draw the page's bench.json ({})",
            replot.display()
        ));
    }
    println!(
        "web measure: {} configurations on {} in {} ms, timestamps {timestamps}",
        results.len(),
        report["adapter"],
        result["measure_ms"]
    );
    Ok(problems)
}

/// Renders each case natively into `out/native/<case>.png`.
fn native_frames(out: &Path) -> anyhow::Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let dir = out.join("native");
    std::fs::create_dir_all(&dir)?;
    let status = Command::new(&cargo)
        .args(["build", "--release", "-p", "manylights-viewer"])
        .status()
        .context("building the native renderer")?;
    if !status.success() {
        bail!("building the native renderer failed");
    }
    let binary = workspace_root().join("target/release/manylights");
    // A process per case, side by side (each keeps about one core of lavapipe busy).
    let rendered = crate::test_runner::in_parallel(
        CASES.iter().collect(),
        crate::test_runner::workers(),
        |_, case| -> anyhow::Result<()> {
            let png = dir.join(format!("{}.png", case.name));
            let output = Command::new(&binary)
                .arg("render")
                .args(case.options())
                .args(COMMON)
                .args(["--size", SIZE, "--out"])
                .arg(&png)
                .env_remove("DISPLAY")
                .env_remove("WAYLAND_DISPLAY")
                .output()
                .with_context(|| format!("running manylights render for {}", case.name))?;
            if !output.status.success() {
                bail!(
                    "manylights render for {} failed: {}",
                    case.name,
                    String::from_utf8_lossy(&output.stderr)
                );
            }
            Ok(())
        },
    );
    rendered.into_iter().collect::<anyhow::Result<()>>()?;
    Ok(())
}

/// Where two frames differ, for people to look at: red where a channel differs by more
/// than the tolerance, yellow where by less, the native frame dimmed elsewhere.
fn difference_image(native: &image::RgbaImage, page: &image::RgbaImage) -> image::RgbaImage {
    image::RgbaImage::from_fn(native.width(), native.height(), |x, y| {
        let (a, b) = (native.get_pixel(x, y), page.get_pixel(x, y));
        let steps = (0..3).map(|c| a.0[c].abs_diff(b.0[c])).max().unwrap_or(0);
        match steps {
            0 => image::Rgba([a.0[0] / 3, a.0[1] / 3, a.0[2] / 3, 255]),
            s if s <= STEP_TOLERANCE => image::Rgba([255, 220, 0, 255]),
            _ => image::Rgba([255, 0, 0, 255]),
        }
    })
}

fn lit_fraction(image: &image::RgbaImage) -> f64 {
    let lit = image
        .pixels()
        .filter(|p| p.0[..3].iter().any(|&c| c > 8))
        .count();
    lit as f64 / f64::from(image.width() * image.height())
}

/// One check a case failed.
struct Problem {
    /// The case's name (its files in the output folder start with it).
    case: &'static str,
    what: String,
}

impl Problem {
    fn of(case: &'static str, what: String) -> Problem {
        Problem { case, what }
    }
}

/// Copies what a failed case left (the page's frame or photograph, the native frame, their
/// difference, its bench.json or download, and everything the page printed) into
/// `out/failed/<case>/`, so one folder holds what to look at; returns that folder.
fn keep_failed_cases(out: &Path, problems: &[Problem]) -> anyhow::Result<PathBuf> {
    let results: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json"))?)?;
    let failed = out.join("failed");
    let mut cases: Vec<&str> = problems.iter().map(|p| p.case).collect();
    cases.sort_unstable();
    cases.dedup();
    for case in cases {
        let folder = failed.join(case);
        std::fs::create_dir_all(&folder)?;
        let copies = [
            (format!("{case}.png"), "page.png"),
            (format!("{case}-page.png"), "page-photograph.png"),
            (format!("{case}-download.png"), "page-download.png"),
            (format!("{case}-bench.json"), "page-bench.json"),
            (format!("native/{case}.png"), "native.png"),
        ];
        for (from, to) in copies {
            let from = out.join(from);
            if from.exists() {
                std::fs::copy(&from, folder.join(to))
                    .with_context(|| format!("keeping {}", from.display()))?;
            }
        }
        // Drawn here, not copied: a case that ended with messages was never compared.
        let (page, native) = (folder.join("page.png"), folder.join("native.png"));
        if page.exists() && native.exists() {
            let (page, native) = (
                image::open(&page)?.to_rgba8(),
                image::open(&native)?.to_rgba8(),
            );
            if page.dimensions() == native.dimensions() {
                difference_image(&native, &page).save(folder.join("difference.png"))?;
            }
        }
        let result = results.iter().find(|r| r["name"] == case);
        let console: Vec<String> = result
            .and_then(|r| r["console"].as_array())
            .map(|lines| {
                lines
                    .iter()
                    .filter_map(|l| l.as_str().map(String::from))
                    .collect()
            })
            .unwrap_or_default();
        let what: Vec<&str> = problems
            .iter()
            .filter(|p| p.case == case)
            .map(|p| p.what.as_str())
            .collect();
        let log = format!(
            "failed: {}\nthe page's result: {}\n\nthe page's console ({} lines):\n{}\n",
            what.join("\nfailed: "),
            result.map_or_else(|| "none".to_string(), |r| format!("{r:#}")),
            console.len(),
            console.join("\n")
        );
        std::fs::write(folder.join("console.log"), log)?;
    }
    Ok(failed)
}

/// The page's results, judged: every problem found.
fn judge(out: &Path) -> anyhow::Result<Vec<Problem>> {
    let results: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json"))?)?;
    let mut problems = Vec::new();
    let result_of = |name: &str| results.iter().find(|r| r["name"] == name);
    for case in &CASES {
        let Some(result) = result_of(case.name) else {
            problems.push(Problem::of(case.name, "no result".into()));
            continue;
        };
        let messages = result["messages"].as_array().cloned().unwrap_or_default();
        if result["state"] != "done" || !messages.is_empty() {
            problems.push(Problem::of(
                case.name,
                format!(
                    "the page ended '{}' ({}) with {} message(s): {}",
                    result["state"],
                    result["status"],
                    messages.len(),
                    messages
                        .iter()
                        .map(|m| m.to_string())
                        .collect::<Vec<_>>()
                        .join("; ")
                ),
            ));
            continue;
        }
        let page = image::open(out.join(format!("{}.png", case.name)))
            .with_context(|| format!("{}: the page's frame", case.name))?
            .to_rgba8();
        let native = image::open(out.join(format!("native/{}.png", case.name)))?.to_rgba8();
        if page.dimensions() != native.dimensions() {
            problems.push(Problem::of(
                case.name,
                format!(
                    "the page drew {:?}, native {:?}",
                    page.dimensions(),
                    native.dimensions()
                ),
            ));
            continue;
        }
        let differences = channel_steps(&native, &page);
        let beyond = differences.iter().filter(|&&d| d > STEP_TOLERANCE).count();
        let pixels = differences.len();
        let mean = differences.iter().map(|&d| f64::from(d)).sum::<f64>() / pixels as f64;
        difference_image(&native, &page)
            .save(out.join(format!("{}-diff.png", case.name)))
            .context("writing the difference image")?;
        let lit = lit_fraction(&native);
        let allowed = if case.textured {
            (pixels as f64 * (1.0 - TEXTURED_WITHIN_FRACTION)) as usize
        } else {
            changed_pixels_allowed(pixels)
        };
        println!(
            "web {:<26} {beyond:>5} of {pixels} pixels beyond {STEP_TOLERANCE} steps (allowed {allowed}), mean {mean:.2} steps, native lit {:.0}%, page load to frame {} ms",
            case.name,
            lit * 100.0,
            result["elapsed_ms"]
        );
        if beyond > allowed {
            problems.push(Problem::of(case.name, format!(
                "{beyond} pixels differ from native by more than {STEP_TOLERANCE} steps (allowed: {allowed})"
            )));
        }
        if case.textured && mean > TEXTURED_MEAN_STEPS {
            problems.push(Problem::of(case.name, format!(
                "the mean difference from native is {mean:.2} steps (allowed: {TEXTURED_MEAN_STEPS})"
            )));
        }
        if lit < MIN_LIT_FRACTION {
            problems.push(Problem::of(
                case.name,
                format!("only {:.0}% of the native frame is lit", lit * 100.0),
            ));
        }
    }
    match result_of("no-webgpu") {
        Some(r)
            if r["state"] == "error"
                && r["status"].as_str().is_some_and(|s| s.contains("WebGPU")) => {}
        other => problems.push(Problem::of(
            "no-webgpu",
            format!("without WebGPU the page must explain itself; it showed {other:?}"),
        )),
    }
    match result_of("open-glb") {
        Some(r)
            if r["scene"] == "SimpleInstancing.glb"
                && r["messages"].as_array().is_some_and(Vec::is_empty) => {}
        other => problems.push(Problem::of(
            "open-glb",
            format!("opening a .glb with the file picker: {other:?}"),
        )),
    }
    match result_of("open-not-a-scene") {
        Some(r)
            if r["load_error"].as_str().is_some_and(|e| e.contains("is a .gltf or .glb"))
                && r["state"] == "running" => {}
        other => problems.push(Problem::of("open-not-a-scene", format!(
            "a file that is not a scene must be refused by name while the page keeps running: {other:?}"
        ))),
    }
    let downloaded = result_of("screenshot")
        .and_then(|r| r["download"].as_str())
        .and_then(|path| image::open(path).ok())
        .map(|png| png.to_rgba8());
    let native = image::open(out.join(format!("native/{}.png", CASES[1].name)))?.to_rgba8();
    match downloaded {
        Some(png) if png.dimensions() == native.dimensions() => {
            let beyond = channel_steps(&native, &png)
                .iter()
                .filter(|&&d| d > STEP_TOLERANCE)
                .count();
            let allowed = changed_pixels_allowed(native.pixels().len());
            if beyond > allowed {
                problems.push(Problem::of("screenshot", format!(
                    "F12's download differs from the native frame in {beyond} pixels (allowed {allowed}): panels in it?"
                )));
            }
        }
        _ => problems.push(Problem::of(
            "screenshot",
            format!(
                "F12 must download the {}x{} frame as a PNG: {:?}",
                native.width(),
                native.height(),
                result_of("screenshot")
            ),
        )),
    }
    problems.extend(
        judge_measure(result_of("measure"), out)?
            .into_iter()
            .map(|what| Problem::of("measure", what)),
    );
    match result_of("page") {
        Some(r) if r["state"] == "done" && r["messages"].as_array().is_some_and(Vec::is_empty) => {}
        other => problems.push(Problem::of(
            "page",
            format!("the page with its panels: {other:?}"),
        )),
    }
    Ok(problems)
}

/// Builds the page, renders every case in the browser and natively, and compares.
pub fn web_test() -> anyhow::Result<()> {
    let started = std::time::Instant::now();
    web::build(&WebOptions {
        wasm_opt: false,
        profile: web::TESTED_PROFILE,
    })?;
    let chromium = chromium()?;
    let node_modules = web::ensure_npm_tools()?;
    let out = workspace_root().join("target/web-test");
    if out.exists() {
        std::fs::remove_dir_all(&out)?;
    }
    std::fs::create_dir_all(&out)?;
    native_frames(&out)?;
    let cases = cases_json(&out, &chromium)?;
    let status = Command::new("node")
        .arg(workspace_root().join("web/test.mjs"))
        .arg(&cases)
        .arg(&out)
        .env("NODE_PATH", &node_modules)
        .current_dir(workspace_root().join("web"))
        .status()
        .context("running node web/test.mjs")?;
    if !status.success() {
        bail!("the headless browser run failed (see above)");
    }
    let problems = judge(&out)?;
    if !problems.is_empty() {
        let failed = keep_failed_cases(&out, &problems)?;
        bail!(
            "the page failed {} check(s); each failed case's page frame, native frame, \
             difference and console log are in {}:\n  {}",
            problems.len(),
            failed.display(),
            problems
                .iter()
                .map(|p| format!("{}: {}", p.case, p.what))
                .collect::<Vec<_>>()
                .join("\n  ")
        );
    }
    println!(
        "web: every case matches native within {STEP_TOLERANCE} steps; the page without WebGPU explains itself ({:.0} s)",
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
