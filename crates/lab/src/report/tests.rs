use plotters::prelude::RGBColor;

use super::axes::{MAX_TICKS, log_ticks, tick_label};
use super::draw::{PanelGrid, panel_keys};
use super::figures::{Labeller, PlotPoint, pareto_front};
use super::point_labels::{Rect, place_label};
use super::style::{DISTINCT_STYLES, PALETTE, Style, series_style};
use super::{measured, replot, write_all, write_charts};
use crate::lab::{Accuracy, BenchConfig, BenchMatrix, BenchReport, BenchResult};

#[test]
fn pareto_front_keeps_only_undominated_points() {
    let points = [(1.0, 5.0), (2.0, 3.0), (3.0, 4.0), (4.0, 1.0), (0.5, 9.0)];
    assert_eq!(
        pareto_front(&points),
        vec![(0.5, 9.0), (1.0, 5.0), (2.0, 3.0), (4.0, 1.0)]
    );
}

fn close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-9 * y.abs())
}

#[test]
fn log_ticks_label_several_values_within_one_decade() {
    // The chart: one label ("1.0") on an axis from 0.15 to 1.
    let ticks = log_ticks(0.15, 1.0, MAX_TICKS);
    assert!(close(&ticks, &[0.2, 0.5, 1.0]), "{ticks:?}");
    // Shorter than 1-2-5 can label: every integer mantissa.
    let ticks = log_ticks(0.62, 1.1, MAX_TICKS);
    assert!(close(&ticks, &[0.7, 0.8, 0.9, 1.0]), "{ticks:?}");
    // Shorter still: round values evenly spaced, all within the range.
    let ticks = log_ticks(0.858, 0.877, MAX_TICKS);
    assert!(ticks.len() >= 3, "{ticks:?}");
    assert!(
        ticks.iter().all(|t| (0.858..=0.877).contains(t)),
        "{ticks:?}"
    );
    let steps: Vec<f64> = ticks.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(
        steps.iter().all(|s| (s - steps[0]).abs() < 1e-9),
        "{ticks:?}"
    );
}

#[test]
fn log_ticks_are_1_2_5_per_decade_over_several_decades() {
    let ticks = log_ticks(3.0, 5000.0, 12);
    let expected = [
        5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0,
    ];
    assert!(close(&ticks, &expected), "{ticks:?}");
    // Where 1-2-5 would crowd the axis, decades; thinned when even those crowd.
    let ticks = log_ticks(0.5, 2e5, MAX_TICKS);
    assert!(
        close(&ticks, &[1.0, 10.0, 100.0, 1e3, 1e4, 1e5]),
        "{ticks:?}"
    );
    let ticks = log_ticks(1.0, 1e15, 4);
    assert!(ticks.len() <= 4 && ticks.len() >= 3, "{ticks:?}");
}

#[test]
fn tick_labels_are_compact() {
    let cases = [
        (0.2, "0.2"),
        (0.05, "0.05"),
        (0.875, "0.875"),
        (1.0, "1"),
        (20.0, "20"),
        (500.0, "500"),
        (1000.0, "1k"),
        (5000.0, "5k"),
        (200_000.0, "200k"),
        (1.5e6, "1.5M"),
        (1e-5, "1e-5"),
        (2.0000000000000004e-4, "2e-4"),
    ];
    for (value, label) in cases {
        assert_eq!(tick_label(value), label, "{value}");
    }
    // A tick computed as 2 * 0.1 still reads "0.2".
    assert_eq!(tick_label(2.0 * 10f64.powi(-1)), "0.2");
}

#[test]
fn palette_does_not_repeat_a_colour_and_marker() {
    for (i, a) in PALETTE.iter().enumerate() {
        assert!(
            !PALETTE[i + 1..].contains(a),
            "colour {a:?} twice in the palette"
        );
    }
    let styles: Vec<Style> = (0..DISTINCT_STYLES).map(series_style).collect();
    for (i, a) in styles.iter().enumerate() {
        assert!(!styles[i + 1..].contains(a), "series {i} repeats {a:?}");
    }
    // Up to the palette's size, colours alone differ.
    for i in 0..PALETTE.len() {
        for j in 0..i {
            assert_ne!(series_style(i).colour, series_style(j).colour);
        }
    }
}

#[test]
fn labels_are_placed_off_markers_and_other_labels() {
    let bounds = Rect {
        x0: 0.0,
        y0: 0.0,
        x1: 200.0,
        y1: 200.0,
    };
    let marker = Rect {
        x0: 94.0,
        y0: 94.0,
        x1: 106.0,
        y1: 106.0,
    };
    // Something already right of the point: the label goes elsewhere.
    let right = Rect {
        x0: 106.0,
        y0: 90.0,
        x1: 160.0,
        y1: 110.0,
    };
    let (_, rect) = place_label((100, 100), 40.0, 12.0, &[marker, right], &bounds);
    assert_eq!(
        rect.overlap(&marker) + rect.overlap(&right),
        0.0,
        "{rect:?}"
    );
    assert!(rect.inside(&bounds));
    // At the right edge the label does not leave the plot.
    let (_, rect) = place_label((195, 100), 40.0, 12.0, &[], &bounds);
    assert!(rect.inside(&bounds), "{rect:?}");
}

#[test]
fn panels_follow_the_run_order_with_the_last_setting_fastest() {
    let point = |panel: &[&str]| PlotPoint {
        panel: panel.iter().map(|s| s.to_string()).collect(),
        series: "s".into(),
        x: 1.0,
        y: 1.0,
        label: None,
        order: 1.0,
    };
    let points = [
        point(&["sponza", "1,000 lights"]),
        point(&["pillars", "10,000 lights"]),
        point(&["sponza", "10,000 lights"]),
        point(&["pillars", "1,000 lights"]),
    ];
    let panels = panel_keys(&points);
    let names: Vec<String> = panels.iter().map(|k| k.join(", ")).collect();
    assert_eq!(
        names,
        [
            "sponza, 1,000 lights",
            "sponza, 10,000 lights",
            "pillars, 1,000 lights",
            "pillars, 10,000 lights"
        ]
    );
    // A column per scene, light counts going down.
    let grid = PanelGrid::new(&panels);
    assert_eq!((grid.rows, grid.cols), (2, 2));
    let cells: Vec<usize> = (0..4).map(|k| grid.cell(k)).collect();
    assert_eq!(cells, [0, 2, 1, 3]);
    // One setting: near-square, row by row.
    let one: Vec<Vec<String>> = (0..5).map(|i| vec![i.to_string()]).collect();
    let grid = PanelGrid::new(&one);
    assert_eq!((grid.rows, grid.cols, grid.cell(4)), (2, 3, 4));
}

fn result(
    scene: &str,
    pipeline: &str,
    grid: Option<&str>,
    lights: u32,
    threshold: f32,
    ms: f64,
) -> BenchResult {
    let deferred = pipeline == "deferred";
    BenchResult {
        config: BenchConfig {
            scene: scene.into(),
            pipeline: pipeline.parse().expect(pipeline),
            lights,
            size: (640, 360),
            grid: grid.map(|grid| grid.parse().expect(grid)),
            gbuffer: deferred.then_some(manylights::GBufferLayout::Compact),
            lighting: deferred.then_some(manylights::LightingPath::Compute),
            assignment: (pipeline != "naive").then(crate::lab::Assignment::default),
            threshold,
            falloff: manylights::lights::Falloff::WindowedInverseSquare,
            far_field: None,
            spot_fraction: 0.0,
            spot_culling: None,
            shadows: Default::default(),
            shading: None,
            view: None,
            settings: Default::default(),
        },
        // Clustered pipelines report their assignment steps (a tenth of the frame).
        passes: if deferred || pipeline == "forward-plus" {
            vec![crate::lab::PassTime {
                name: manylights::cluster::passes::FILL_LISTS.into(),
                median_ms: ms * 0.1,
                p95_ms: ms * 0.11,
            }]
        } else {
            Vec::new()
        },
        gpu_total_median_ms: Some(ms),
        gpu_total_p95_ms: Some(ms * 1.1),
        cpu_frame_median_ms: 1.0,
        accuracy: Accuracy {
            f64_mean_relative: 0.2 + 0.5 * threshold as f64,
            f64_max_relative: 1.0,
            samples: 16,
            ..Accuracy::default()
        },
        lights_per_cluster_mean: grid.map(|g| lights as f64 / g.len() as f64),
        lights_per_cluster_max: grid.map(|_| lights),
        false_positive_ratio: None,
        cluster_count: grid.map(|g| if g.starts_with("16") { 6912 } else { 36864 }),
        light_evaluations: 0,
        evaluations_per_second: None,
        blended_layers: None,
        error: None,
        clock_remeasures: 0,
        frame: None,
    }
}

/// Two scenes, two light counts, two thresholds, naive, Forward+ and deferred on
/// two grids: every axis the charts split by varies.
fn synthetic_report() -> BenchReport {
    let mut results = Vec::new();
    for scene in ["sponza", "pillars:4x4"] {
        for lights in [1000, 10_000] {
            for threshold in [0.05, 0.2] {
                let base = lights as f64 / 1000.0 / threshold as f64;
                results.push(result(scene, "naive", None, lights, threshold, 50.0 * base));
                for (i, grid) in ["16x9x24:log-near", "32x18x48:log-near"].iter().enumerate() {
                    let slower = 1.0 + i as f64;
                    let fp = result(
                        scene,
                        "forward-plus",
                        Some(grid),
                        lights,
                        threshold,
                        base * slower,
                    );
                    let def = result(
                        scene,
                        "deferred",
                        Some(grid),
                        lights,
                        threshold,
                        base * 0.5 * slower,
                    );
                    results.extend([fp, def]);
                }
            }
        }
    }
    BenchReport {
        adapter: "Test GPU".into(),
        backend: "Vulkan".into(),
        driver: "test".into(),
        timestamps: true,
        started: "unix time 0".into(),
        matrix: BenchMatrix::default(),
        results,
        interrupted: false,
    }
}

fn svg_colour(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// The text of every `<text>` element of an SVG.
fn svg_texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let body = t.split_once('>')?.1.split_once("</text>")?.0;
            Some(body.trim().replace("&lt;", "<").replace("&amp;", "&"))
        })
        .collect()
}

const CHARTS: [&str; 4] = [
    "gpu_ms_vs_lights.svg",
    "error_vs_time.svg",
    "lights_per_cluster_vs_grid.svg",
    "assign_ms_vs_lights.svg",
];

/// A chart drawn for a test: its legend, SVG source and texts.
type Drawn = (Vec<(String, Style)>, String, Vec<String>);

/// Draws the report's charts into a temporary folder.
fn draw(report: &BenchReport) -> Vec<Drawn> {
    let dir = tempfile::tempdir().unwrap();
    let legends = write_charts(report, &measured(report), dir.path()).unwrap();
    CHARTS
        .iter()
        .zip(legends)
        .map(|(file, legend)| {
            let svg = std::fs::read_to_string(dir.path().join(file)).unwrap();
            let texts = svg_texts(&svg);
            (legend, svg, texts)
        })
        .collect()
}

fn has(texts: &[String], text: &str) -> bool {
    texts.iter().any(|t| t == text)
}

#[test]
fn charts_label_every_series_and_point_with_distinct_styles() {
    let report = synthetic_report();
    let charts = draw(&report);
    for (file, (legend, svg, texts)) in CHARTS.iter().zip(&charts) {
        assert!(!legend.is_empty(), "{file}: no series");
        for (i, (text, style)) in legend.iter().enumerate() {
            assert!(has(texts, text), "{file}: no legend entry '{text}'");
            assert!(
                svg.contains(&svg_colour(style.colour)),
                "{file}: '{text}' not drawn"
            );
            let twin = legend[i + 1..].iter().find(|(_, s)| s == style);
            assert!(twin.is_none(), "{file}: '{text}' and {twin:?} look alike");
        }
    }
    let gpu = &charts[0].2;
    for expected in [
        "naive",
        "forward-plus, grid 16x9x24:log-near",
        "deferred compact/compute, grid 32x18x48:log-near",
        // Panels: scene and radius; log ticks 1-2-5.
        "sponza, radius 2 m (threshold 0.05)",
        "pillars:4x4, radius 1 m (threshold 0.2)",
        "1k",
        "2k",
        "5k",
        "10k",
    ] {
        assert!(has(gpu, expected), "gpu chart lacks '{expected}': {gpu:?}");
    }
    // Every point of the error chart says its radius; panels are workloads.
    let error = &charts[1].2;
    let points = measured(&report).len();
    let labelled = error
        .iter()
        .filter(|t| *t == "r 2 m" || *t == "r 1 m")
        .count();
    assert_eq!(
        labelled, points,
        "every point of the error chart carries its radius"
    );
    for expected in [
        "sponza, 1,000 lights",
        "pillars:4x4, 10,000 lights",
        "Pareto front",
        // Settings shared by every point are said once, in the subtitle.
        "Test GPU; 640x360; windowed falloff; assignment tile-masks/visible",
    ] {
        assert!(
            has(error, expected),
            "error chart lacks '{expected}': {error:?}"
        );
    }
    let cluster = &charts[2].2;
    for expected in [
        "16x9x24",
        "32x18x48",
        "10,000 lights, radius 1 m (threshold 0.2)",
    ] {
        assert!(
            has(cluster, expected),
            "cluster chart lacks '{expected}': {cluster:?}"
        );
    }
}

#[test]
fn a_scatter_without_radius_labels_numbers_its_points() {
    let mut report = synthetic_report();
    report.results.retain(|r| r.config.threshold == 0.05);
    let charts = draw(&report);
    let (legend, _, texts) = &charts[1];
    let ok = measured(&report);
    let labels = Labeller::new(&report, &ok);
    for (i, (text, _)) in legend.iter().enumerate() {
        let number = (i + 1).to_string();
        assert!(text.starts_with(&format!("({number}) ")), "{text}");
        let points = ok
            .iter()
            .filter(|r| text.ends_with(&labels.pipeline_series(r)))
            .count();
        let labelled = texts.iter().filter(|t| **t == number).count();
        assert!(
            labelled >= points,
            "{text}: {labelled} labels for {points} points"
        );
    }
    assert!(!has(texts, "r 2 m"), "one radius: no radius labels");
}

#[test]
fn replot_redraws_the_charts_from_bench_json() {
    let report = synthetic_report();
    let first = tempfile::tempdir().unwrap();
    write_all(&report, first.path()).unwrap();
    let second = tempfile::tempdir().unwrap();
    replot(&first.path().join("bench.json"), second.path()).unwrap();
    for file in [
        "REPORT.md",
        "gpu_ms_vs_lights.svg",
        "error_vs_time.svg",
        "lights_per_cluster_vs_grid.svg",
        "assign_ms_vs_lights.svg",
    ] {
        let a = std::fs::read_to_string(first.path().join(file)).unwrap();
        let b = std::fs::read_to_string(second.path().join(file)).unwrap();
        assert_eq!(a, b, "{file} differs after replot");
    }
    assert!(
        !second.path().join("bench.json").exists(),
        "replot leaves bench.json alone"
    );
    assert!(replot(&second.path().join("bench.json"), second.path()).is_err());
}

#[test]
fn a_run_without_results_still_draws_every_chart() {
    let mut report = synthetic_report();
    report.results.clear();
    let dir = tempfile::tempdir().unwrap();
    write_all(&report, dir.path()).unwrap();
    let svg = std::fs::read_to_string(dir.path().join("error_vs_time.svg")).unwrap();
    assert!(svg.contains("no configuration was measured"));
}
