//! The lab's outputs: `bench.json` (every raw number), `REPORT.md` (tables), and SVG
//! charts drawn with plotters: GPU time against light count per pipeline, error against
//! time with the Pareto front, and lights per cluster against grid size. A chart whose x
//! setting the run did not vary (one light count, one grid) plots against the setting
//! that did vary (the light radius, the light count) instead of a single column of points.
//!
//! The charts are small multiples: one panel per workload (scene, size, light count, ...
//! whatever the run varied), the same colour and marker for a series in every panel, and
//! one legend beside the panels so it never covers data. Settings the run did not vary
//! are written once under the title instead of in every label. Log axes carry 1-2-5
//! ticks (or finer when the range is short) so a reader can read values off them.

use std::fmt::Write as _;
use std::ops::Range;
use std::path::Path;

use anyhow::Context as _;
use plotters::coord::Shift;
use plotters::coord::combinators::{BindKeyPoints, WithKeyPoints};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::lab::{BenchReport, BenchResult};
use manylights::lights::RadiusMode;

/// Writes bench.json, REPORT.md and the charts into `dir`.
pub fn write_all(report: &BenchReport, dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let json = serde_json::to_string_pretty(report)?;
    std::fs::write(dir.join("bench.json"), json)
        .with_context(|| format!("writing {}", dir.join("bench.json").display()))?;
    write_charts_and_markdown(report, dir)
}

/// Redraws the charts and REPORT.md of a finished run from its `bench.json` into
/// `out_dir`, without a GPU. `bench.json` itself is not rewritten, so replotting into the
/// run's own folder leaves the raw numbers byte for byte as they were measured.
pub fn replot(bench_json: &Path, out_dir: &Path) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(bench_json)
        .with_context(|| format!("reading {}", bench_json.display()))?;
    let report: BenchReport = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a bench report", bench_json.display()))?;
    std::fs::create_dir_all(out_dir).with_context(|| format!("creating {}", out_dir.display()))?;
    write_charts_and_markdown(&report, out_dir)
}

fn write_charts_and_markdown(report: &BenchReport, dir: &Path) -> anyhow::Result<()> {
    let ok = measured(report);
    write_charts(report, &ok, dir)?;
    std::fs::write(dir.join("REPORT.md"), markdown(report, &ok))
        .with_context(|| format!("writing {}", dir.join("REPORT.md").display()))?;
    Ok(())
}

/// The results that have a GPU time: failed configurations have nothing to plot.
fn measured(report: &BenchReport) -> Vec<&BenchResult> {
    report
        .results
        .iter()
        .filter(|r| r.error.is_none() && r.gpu_total_median_ms.is_some())
        .collect()
}

/// Draws the three charts; returns each chart's legend (for the tests).
fn write_charts(
    report: &BenchReport,
    ok: &[&BenchResult],
    dir: &Path,
) -> anyhow::Result<Vec<Vec<(String, Style)>>> {
    let labels = Labeller::new(report, ok);
    let figures = [
        time_figure(&labels, ok),
        error_figure(&labels, ok),
        cluster_figure(&labels, ok),
        assignment_figure(&labels, ok),
    ];
    let mut legends = Vec::new();
    for figure in &figures {
        let path = dir.join(figure.file);
        let legend =
            draw_figure(figure, &path).with_context(|| format!("drawing {}", path.display()))?;
        legends.push(legend);
    }
    Ok(legends)
}

// ---------------------------------------------------------------------------------------
// What to plot: settings as labels, split into panels, series and point labels.

/// A setting a chart can split its data by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Dim {
    Scene,
    Size,
    Falloff,
    Lights,
    Radius,
    Pipeline,
    Grid,
    Assignment,
}

const DIMS: [Dim; 8] = [
    Dim::Scene,
    Dim::Size,
    Dim::Falloff,
    Dim::Lights,
    Dim::Radius,
    Dim::Pipeline,
    Dim::Grid,
    Dim::Assignment,
];

/// Names the settings of results and knows which ones the run varied: only those are
/// worth a panel, a legend entry or a point label; the others are said once, in the
/// subtitle.
struct Labeller {
    intensity: f32,
    adapter: String,
    varying: Vec<Dim>,
    /// The label of each setting that did not vary.
    constant: Vec<String>,
}

impl Labeller {
    fn new(report: &BenchReport, results: &[&BenchResult]) -> Self {
        let mut labels = Self {
            intensity: report.matrix.intensity,
            adapter: report.adapter.clone(),
            varying: Vec::new(),
            constant: Vec::new(),
        };
        for dim in DIMS {
            let mut values: Vec<String> = results
                .iter()
                .filter_map(|r| labels.label(dim, r))
                .collect();
            values.sort();
            values.dedup();
            match values.len() {
                0 => {}
                1 => labels.constant.push(values.remove(0)),
                _ => labels.varying.push(dim),
            }
        }
        labels
    }

    fn varies(&self, dim: Dim) -> bool {
        self.varying.contains(&dim)
    }

    fn radius(&self, r: &BenchResult) -> f32 {
        RadiusMode::LuminanceThreshold(r.config.threshold).radius(self.intensity)
    }

    /// The long label of a setting; None where it does not apply (naive has no grid).
    fn label(&self, dim: Dim, r: &BenchResult) -> Option<String> {
        let c = &r.config;
        Some(match dim {
            Dim::Scene => c.scene.clone(),
            Dim::Size => format!("{}x{}", c.size.0, c.size.1),
            Dim::Falloff => format!("{} falloff", c.falloff),
            Dim::Lights => format!("{} lights", thousands(c.lights)),
            Dim::Radius => format!(
                "radius {} m (threshold {})",
                metres(self.radius(r)),
                c.threshold
            ),
            Dim::Pipeline => c.variant(),
            Dim::Grid => format!("grid {}", c.grid.as_ref()?),
            Dim::Assignment => format!("assignment {}", c.assignment.as_ref()?),
        })
    }

    /// The short label a point carries on the chart: `r 2 m`, with a far field's tolerance
    /// `r 2 m t 0.1`.
    fn radius_short(&self, r: &BenchResult) -> String {
        let tolerance = r
            .config
            .far_field
            .as_ref()
            .and_then(|far| far.split_once(':'))
            .map(|(_, tolerance)| format!(" t {tolerance}"))
            .unwrap_or_default();
        format!("r {} m{tolerance}", metres(self.radius(r)))
    }

    /// The labels of those of `dims` that vary.
    fn key(&self, dims: &[Dim], r: &BenchResult) -> Vec<String> {
        dims.iter()
            .filter(|d| self.varies(**d))
            .filter_map(|d| self.label(*d, r))
            .collect()
    }

    /// A series per pipeline configuration (layout, lighting path, grid when it varies).
    fn pipeline_series(&self, r: &BenchResult) -> String {
        let mut key = vec![r.config.variant()];
        if self.varies(Dim::Grid) {
            key.extend(self.label(Dim::Grid, r));
        }
        key.join(", ")
    }

    /// The settings every point shares, for the subtitle.
    fn subtitle(&self) -> String {
        let mut parts = vec![self.adapter.clone()];
        parts.extend(self.constant.iter().cloned());
        parts.join("; ")
    }
}

/// `200,000`.
fn thousands(n: u32) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, ch) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(ch);
    }
    out
}

/// A radius to two significant digits: `14`, `6.3`, `2`.
fn metres(radius: f32) -> String {
    let decimals = if radius >= 10.0 {
        0
    } else if radius >= 1.0 {
        1
    } else {
        2
    };
    trim_zeros(format!("{radius:.decimals$}"))
}

fn trim_zeros(text: String) -> String {
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// One plotted value, already assigned to its panel and series.
#[derive(Debug, Clone)]
struct PlotPoint {
    /// The labels of the settings that pick the panel.
    panel: Vec<String>,
    series: String,
    x: f64,
    y: f64,
    /// Drawn next to the point when the series has several points that x alone does not
    /// tell apart (the radius on the error chart).
    label: Option<String>,
    /// Points of a series are joined in this order.
    order: f64,
}

/// A chart: panels of points, one shared legend.
struct Figure {
    file: &'static str,
    title: String,
    subtitle: String,
    x_desc: String,
    y_desc: String,
    /// Names shown instead of numbers at these x values (cluster grids).
    x_names: Vec<(f64, String)>,
    points: Vec<PlotPoint>,
    /// Legend order; a series' index picks its colour and marker.
    series: Vec<String>,
    pareto: bool,
    /// Each series' line joins its own Pareto front (time against error) instead of its
    /// points in order: a method's best trade at each cost.
    series_fronts: bool,
    /// What the point labels mean, for the legend.
    label_note: Option<&'static str>,
    /// Points are labelled with their series' number, which the legend shows too.
    numbered: bool,
    /// Shown instead of panels when there is nothing to plot.
    empty_note: &'static str,
}

impl Figure {
    fn new(file: &'static str, title: String, labels: &Labeller, points: Vec<PlotPoint>) -> Self {
        let mut series: Vec<String> = Vec::new();
        for p in &points {
            if !series.contains(&p.series) {
                series.push(p.series.clone());
            }
        }
        Self {
            file,
            title,
            subtitle: labels.subtitle(),
            x_desc: String::new(),
            y_desc: String::new(),
            x_names: Vec::new(),
            points,
            series,
            pareto: false,
            series_fronts: false,
            label_note: None,
            numbered: false,
            empty_note: "no configuration was measured",
        }
    }
}

/// The x axis of a chart that plots against a setting: the first of `preferred` that the
/// run varied (a chart against a setting with one value would be a single column of
/// points), else the first.
fn x_dim(labels: &Labeller, preferred: &[Dim]) -> Dim {
    preferred
        .iter()
        .copied()
        .find(|d| labels.varies(*d))
        .unwrap_or(preferred[0])
}

fn setting_value(labels: &Labeller, dim: Dim, r: &BenchResult) -> Option<f64> {
    match dim {
        Dim::Lights => Some(r.config.lights as f64),
        Dim::Radius => Some(labels.radius(r) as f64),
        Dim::Grid => r.cluster_count.map(|c| c as f64),
        _ => None,
    }
}

/// GPU time against light count: a line per pipeline configuration, a panel per scene,
/// size, falloff and radius. A run with one light count plots against the radius instead.
fn time_figure(labels: &Labeller, results: &[&BenchResult]) -> Figure {
    let x = x_dim(labels, &[Dim::Lights, Dim::Radius]);
    let panel_dims: Vec<Dim> = [
        Dim::Scene,
        Dim::Size,
        Dim::Falloff,
        Dim::Lights,
        Dim::Radius,
    ]
    .into_iter()
    .filter(|d| *d != x)
    .collect();
    let points = results
        .iter()
        .filter_map(|r| {
            let xv = setting_value(labels, x, r)?;
            Some(PlotPoint {
                panel: labels.key(&panel_dims, r),
                series: labels.pipeline_series(r),
                x: xv,
                y: r.gpu_total_median_ms?,
                label: None,
                order: xv,
            })
        })
        .collect();
    let (title, x_desc) = match x {
        Dim::Radius => (
            "GPU time per frame against light radius",
            "light radius (m)",
        ),
        _ => ("GPU time per frame against light count", "lights"),
    };
    let mut figure = Figure::new("gpu_ms_vs_lights.svg", title.into(), labels, points);
    figure.x_desc = x_desc.into();
    figure.y_desc = "GPU ms per frame (median)".into();
    figure
}

/// The light assignment's GPU time (the sum of its steps' medians, every pass named
/// `assign...`) against light count: a line per assignment (design and boxes) and pipeline,
/// a panel per scene, size, radius and grid.
fn assignment_figure(labels: &Labeller, results: &[&BenchResult]) -> Figure {
    let panel_dims = [Dim::Scene, Dim::Size, Dim::Falloff, Dim::Radius, Dim::Grid];
    let points = results
        .iter()
        .filter_map(|r| {
            let steps: Vec<f64> = r
                .passes
                .iter()
                .filter(|p| p.name.starts_with("assign"))
                .map(|p| p.median_ms)
                .collect();
            if steps.is_empty() {
                return None;
            }
            let x = r.config.lights as f64;
            Some(PlotPoint {
                panel: labels.key(&panel_dims, r),
                series: format!(
                    "{}, {}",
                    r.config
                        .assignment
                        .as_deref()
                        .unwrap_or(crate::lab::DEFAULT_ASSIGNMENT),
                    r.config.pipeline
                ),
                x,
                y: steps.iter().sum(),
                label: None,
                order: x,
            })
        })
        .collect();
    let mut figure = Figure::new(
        "assign_ms_vs_lights.svg",
        "Light assignment GPU time against light count".into(),
        labels,
        points,
    );
    figure.x_desc = "lights".into();
    figure.y_desc = "GPU ms per frame, all assignment steps (medians)".into();
    figure.empty_note = "no clustered configuration was measured";
    figure
}

/// The error on the speed/accuracy chart: the mean relative error against the f64
/// reference at the sampled pixels, which every configuration has (the reference image
/// is skipped above its light limit).
fn error_of(r: &BenchResult) -> f64 {
    r.accuracy.f64_mean_relative.max(1e-9)
}

/// Error against time: a panel per workload (scene, size, falloff, light count) since
/// only configurations of the same workload compete; a series per pipeline
/// configuration, its points labelled with their radius and joined in radius order.
fn error_figure(labels: &Labeller, results: &[&BenchResult]) -> Figure {
    let panel_dims = [Dim::Scene, Dim::Size, Dim::Falloff, Dim::Lights];
    let radius_varies = labels.varies(Dim::Radius);
    let points = results
        .iter()
        .filter_map(|r| {
            Some(PlotPoint {
                panel: labels.key(&panel_dims, r),
                series: labels.pipeline_series(r),
                x: r.gpu_total_median_ms?,
                y: error_of(r),
                label: radius_varies.then(|| labels.radius_short(r)),
                order: labels.radius(r) as f64,
            })
        })
        .collect();
    let mut figure = Figure::new(
        "error_vs_time.svg",
        "Error against GPU time".into(),
        labels,
        points,
    );
    figure.x_desc = "GPU ms per frame (median)".into();
    figure.y_desc = "mean relative error vs f64 reference".into();
    figure.pareto = true;
    figure.series_fronts = true;
    if radius_varies {
        figure.label_note = Some(if results.iter().any(|r| r.config.far_field.is_some()) {
            "point labels: light radius r, far-field tolerance t; lines: each series' Pareto front"
        } else {
            "point labels: light radius r"
        });
    } else if figure.series.len() > 1 {
        number_points(&mut figure);
    }
    figure
}

/// Labels each point with its series' number: on a scatter without lines, points of
/// equal time overlap and colour alone does not tell them apart.
fn number_points(figure: &mut Figure) {
    for p in &mut figure.points {
        let index = figure
            .series
            .iter()
            .position(|s| *s == p.series)
            .unwrap_or(0);
        p.label = Some((index + 1).to_string());
    }
    figure.numbered = true;
    figure.label_note = Some("point labels: series number");
}

/// Mean lights per cluster against the cluster grid (or, when the run used one grid,
/// against light count or radius): a series per light count and radius, a panel per
/// scene. Pipelines sharing a grid share its light lists, so each is plotted once.
fn cluster_figure(labels: &Labeller, results: &[&BenchResult]) -> Figure {
    let x = x_dim(labels, &[Dim::Grid, Dim::Lights, Dim::Radius]);
    let series_dims: Vec<Dim> = [Dim::Lights, Dim::Radius]
        .into_iter()
        .filter(|d| *d != x)
        .collect();
    let mut points: Vec<PlotPoint> = Vec::new();
    let mut x_names: Vec<(f64, String)> = Vec::new();
    for r in results {
        let (Some(xv), Some(y)) = (setting_value(labels, x, r), r.lights_per_cluster_mean) else {
            continue;
        };
        if r.cluster_count.is_none() {
            continue;
        }
        let mut series = labels.key(&series_dims, r);
        if series.is_empty() {
            // One line: name it by what it is drawn for.
            let dim = if x == Dim::Lights {
                Dim::Grid
            } else {
                Dim::Lights
            };
            series.extend(labels.label(dim, r));
        }
        let point = PlotPoint {
            panel: labels.key(&[Dim::Scene, Dim::Size, Dim::Falloff], r),
            series: series.join(", "),
            x: xv,
            y,
            label: None,
            order: xv,
        };
        let duplicate = points
            .iter()
            .any(|p| p.panel == point.panel && p.series == point.series && p.x == point.x);
        if duplicate {
            continue;
        }
        if x == Dim::Grid && !x_names.iter().any(|(v, _)| *v == xv) {
            let grid = r.config.grid.clone().unwrap_or_default();
            x_names.push((xv, grid.split(':').next().unwrap_or_default().to_string()));
        }
        points.push(point);
    }
    let (title, x_desc) = match x {
        Dim::Lights => ("Mean lights per cluster against light count", "lights"),
        Dim::Radius => (
            "Mean lights per cluster against light radius",
            "light radius (m)",
        ),
        _ => (
            "Mean lights per cluster against cluster grid",
            "cluster grid (tiles x tiles x slices, at its cluster count)",
        ),
    };
    let mut figure = Figure::new(
        "lights_per_cluster_vs_grid.svg",
        title.into(),
        labels,
        points,
    );
    figure.x_desc = x_desc.into();
    figure.y_desc = "mean lights per cluster".into();
    figure.x_names = x_names;
    figure.empty_note = "no clustered configuration was measured";
    figure
}

fn pareto_front(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for p in sorted {
        if p.1 < best {
            best = p.1;
            front.push(p);
        }
    }
    front
}

// ---------------------------------------------------------------------------------------
// Log axes: range and ticks.

/// The most labelled ticks on an axis of a panel before labels crowd.
const MAX_TICKS: usize = 10;

/// The data range widened a little on a log scale so the extreme points and their
/// labels sit inside the plot.
fn padded_log_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| *v > 0.0 && v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return 0.1..10.0;
    }
    let span = (hi / lo).log10();
    let pad = 10f64.powf((span * 0.1).max(0.06));
    (lo / pad)..(hi * pad)
}

/// The values `m * 10^e` within lo..=hi for the mantissas `m`.
fn mantissa_ticks(lo: f64, hi: f64, mantissas: &[f64]) -> Vec<f64> {
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let mut ticks = Vec::new();
    for e in first..=last {
        for m in mantissas {
            let v = m * 10f64.powi(e);
            if v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9) {
                ticks.push(v);
            }
        }
    }
    ticks
}

/// Labelled ticks for a log axis over lo..hi: 1-2-5 per decade when that gives at least
/// 3 and at most `max` ticks; decades (thinned to `max`) when 1-2-5 would crowd; every
/// integer mantissa when the range is too short for 1-2-5; evenly spaced round values
/// when even that gives fewer than 3 (a range within one step such as 0.86..0.88).
fn log_ticks(lo: f64, hi: f64, max: usize) -> Vec<f64> {
    let one_two_five = mantissa_ticks(lo, hi, &[1.0, 2.0, 5.0]);
    if one_two_five.len() > max {
        let decades = mantissa_ticks(lo, hi, &[1.0]);
        let every = decades.len().div_ceil(max.max(1));
        return decades.into_iter().step_by(every).collect();
    }
    if one_two_five.len() >= 3 {
        return one_two_five;
    }
    let integers = mantissa_ticks(lo, hi, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    if integers.len() >= 3 {
        return integers;
    }
    linear_ticks(lo, hi)
}

/// Round values evenly spaced over lo..=hi, about four steps of 1, 2 or 5 x 10^k.
fn linear_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if hi <= lo {
        return vec![lo];
    }
    let rough = (hi - lo) / 4.0;
    let power = 10f64.powf(rough.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|s| *s >= rough)
        .unwrap_or(10.0 * power);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|i| i as f64 * step).collect()
}

/// Unlabelled grid lines at every integer mantissa, so the log scale reads as one.
fn minor_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let ticks = mantissa_ticks(lo, hi, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    if ticks.len() > 100 { Vec::new() } else { ticks }
}

/// A tick value written compactly: `0.15`, `2`, `500`, `20k`, `1.5M`, `1e-5`.
fn tick_label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    for (scale, suffix) in [(1e9, "G"), (1e6, "M"), (1e3, "k")] {
        if v.abs() >= scale {
            return format!("{}{suffix}", significant(v / scale));
        }
    }
    if v.abs() >= 1e-3 {
        return significant(v);
    }
    let text = format!("{v:.2e}");
    let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
    format!("{}e{exponent}", trim_zeros(mantissa.to_string()))
}

/// Up to 4 significant digits, trailing zeros dropped.
fn significant(v: f64) -> String {
    let decimals = (3 - v.abs().log10().floor() as i32).clamp(0, 9) as usize;
    trim_zeros(format!("{v:.decimals$}"))
}

/// A log axis shared by every panel of a chart (shared so panels compare at a glance).
struct LogAxis {
    range: Range<f64>,
    ticks: Vec<f64>,
    minor: Vec<f64>,
    names: Vec<(f64, String)>,
}

impl LogAxis {
    fn new(values: impl Iterator<Item = f64>, names: &[(f64, String)]) -> Self {
        let range = padded_log_range(values);
        let (ticks, minor) = if names.is_empty() {
            (
                log_ticks(range.start, range.end, MAX_TICKS),
                minor_ticks(range.start, range.end),
            )
        } else {
            (names.iter().map(|(v, _)| *v).collect(), Vec::new())
        };
        Self {
            range,
            ticks,
            minor,
            names: names.to_vec(),
        }
    }

    fn spec(&self) -> WithKeyPoints<LogCoord<f64>> {
        self.range
            .clone()
            .log_scale()
            .with_key_points(self.ticks.clone())
            .with_light_points(self.minor.clone())
    }

    fn label(&self, v: f64) -> String {
        self.names
            .iter()
            .find(|(x, _)| (x - v).abs() <= 1e-9 * x.abs())
            .map(|(_, name)| name.clone())
            .unwrap_or_else(|| tick_label(v))
    }
}

// ---------------------------------------------------------------------------------------
// Series styles: a colour and a marker that no other series of the chart shares.

/// Markers, varied together with the colour so series also differ in grey print and for
/// colour-blind readers, and so that series beyond the palette still look different.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Marker {
    Circle,
    Square,
    TriangleUp,
    Diamond,
    TriangleDown,
}

const MARKERS: [Marker; 5] = [
    Marker::Circle,
    Marker::Square,
    Marker::TriangleUp,
    Marker::Diamond,
    Marker::TriangleDown,
];

/// Tableau 10: ten hues that stay apart from one another on white.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// How many series a chart can draw before a colour and marker pair repeats.
const DISTINCT_STYLES: usize = PALETTE.len() * MARKERS.len();

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Style {
    colour: RGBColor,
    marker: Marker,
}

/// Series `i`'s style: colours in palette order; each pass over the palette shifts the
/// markers by one, so colour `c` comes back only with a marker it had not had yet.
fn series_style(i: usize) -> Style {
    let round = i / PALETTE.len();
    Style {
        colour: PALETTE[i % PALETTE.len()],
        marker: MARKERS[(i + round) % MARKERS.len()],
    }
}

const MARKER_SIZE: i32 = 5;

fn marker_outline(marker: Marker, r: i32) -> Vec<(i32, i32)> {
    match marker {
        Marker::Circle | Marker::Square => vec![(-r, -r), (r, -r), (r, r), (-r, r)],
        Marker::TriangleUp => vec![(0, -r - 1), (r + 1, r), (-r - 1, r)],
        Marker::Diamond => vec![(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)],
        Marker::TriangleDown => vec![(0, r + 1), (r + 1, -r), (-r - 1, -r)],
    }
}

/// A hollow marker with a light fill: overlapping points of different series (equal
/// times are common) stay visible through each other.
fn draw_marker<CT>(
    area: &DrawingArea<SVGBackend<'_>, CT>,
    at: CT::From,
    style: Style,
) -> anyhow::Result<()>
where
    CT: CoordTranslate,
    CT::From: Clone,
{
    let fill = style.colour.mix(0.2).filled();
    let stroke = style.colour.stroke_width(2);
    if style.marker == Marker::Circle {
        area.draw(&(EmptyElement::at(at.clone()) + Circle::new((0, 0), MARKER_SIZE, fill)))?;
        area.draw(&(EmptyElement::at(at) + Circle::new((0, 0), MARKER_SIZE, stroke)))?;
        return Ok(());
    }
    let outline = marker_outline(style.marker, MARKER_SIZE);
    let mut closed = outline.clone();
    closed.push(outline[0]);
    area.draw(&(EmptyElement::at(at.clone()) + Polygon::new(outline, fill)))?;
    area.draw(&(EmptyElement::at(at) + PathElement::new(closed, stroke)))?;
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Layout: a header, a grid of panels, the legend on the right outside every panel.

const FONT: &str = "sans-serif";
/// A panel's size: a lone panel gets more room than one of a grid.
fn panel_size(panels: usize) -> (u32, u32) {
    if panels <= 1 { (620, 430) } else { (430, 330) }
}

const TITLE_FONT: f64 = 24.0;
const SUBTITLE_FONT: f64 = 17.0;
const HEADER_H: u32 = 64;
const LEGEND_ROW: i32 = 22;
const LEGEND_TOP: i32 = 34;

/// plotters writes `font-size` as the style size / 1.24; estimates below need pixels.
fn font_px(size: f64) -> f64 {
    size / 1.24
}

/// A generous width estimate for sans-serif text (browsers do the real layout).
fn text_width(text: &str, size: f64) -> f64 {
    text.chars().count() as f64 * font_px(size) * 0.62
}

/// The panel keys in order: each setting's values in the order the run met them, the
/// last setting varying fastest (so rows and columns line up with settings).
fn panel_keys(points: &[PlotPoint]) -> Vec<Vec<String>> {
    let width = points.first().map_or(0, |p| p.panel.len());
    let mut seen: Vec<Vec<String>> = vec![Vec::new(); width];
    for p in points {
        for (i, value) in p.panel.iter().enumerate() {
            if !seen[i].contains(value) {
                seen[i].push(value.clone());
            }
        }
    }
    let rank = |key: &Vec<String>| -> Vec<usize> {
        key.iter()
            .enumerate()
            .map(|(i, v)| seen[i].iter().position(|s| s == v).unwrap_or(0))
            .collect()
    };
    let mut keys: Vec<Vec<String>> = Vec::new();
    for p in points {
        if !keys.contains(&p.panel) {
            keys.push(p.panel.clone());
        }
    }
    keys.sort_by_key(|k| rank(k));
    keys
}

/// Where the panels go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct PanelGrid {
    rows: usize,
    cols: usize,
    /// Panels fill columns first: a column per value of the first setting (a scene),
    /// the other settings (light counts) going down. Tall rather than wide, so a browser
    /// shows the chart without scrolling sideways.
    column_major: bool,
}

impl PanelGrid {
    fn new(panels: &[Vec<String>]) -> Self {
        let n = panels.len().max(1);
        let mut firsts: Vec<&String> = panels.iter().filter_map(|k| k.first()).collect();
        firsts.dedup();
        let settings = panels.first().map_or(0, |k| k.len());
        // Panel keys come sorted, so equal first values are adjacent: `firsts` counts
        // runs, equal to the distinct values exactly when every value has one block.
        let columns = firsts.len();
        if settings >= 2 && (2..=4).contains(&columns) && n.is_multiple_of(columns) {
            return Self {
                rows: n / columns,
                cols: columns,
                column_major: true,
            };
        }
        let cols = ((n as f64).sqrt().ceil() as usize).clamp(1, 3);
        Self {
            rows: n.div_ceil(cols),
            cols,
            column_major: false,
        }
    }

    /// The row-major cell of the `k`th panel.
    fn cell(&self, k: usize) -> usize {
        if self.column_major {
            (k % self.rows) * self.cols + k / self.rows
        } else {
            k
        }
    }
}

/// A legend line: a series, the Pareto front, or a note.
enum LegendEntry {
    Series(String, Style),
    Pareto,
    Note(String),
}

impl LegendEntry {
    fn text(&self) -> &str {
        match self {
            LegendEntry::Series(text, _) | LegendEntry::Note(text) => text,
            LegendEntry::Pareto => "Pareto front",
        }
    }
}

fn legend_entries(figure: &Figure) -> Vec<LegendEntry> {
    let mut entries: Vec<LegendEntry> = figure
        .series
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let text = if figure.numbered {
                format!("({}) {s}", i + 1)
            } else {
                s.clone()
            };
            LegendEntry::Series(text, series_style(i))
        })
        .collect();
    if figure.pareto {
        entries.push(LegendEntry::Pareto);
        entries.push(LegendEntry::Note(
            "(nothing else is both faster and more accurate)".into(),
        ));
    }
    if let Some(note) = figure.label_note {
        entries.push(LegendEntry::Note(note.into()));
    }
    entries
}

const LEGEND_FONT: f64 = 16.0;

fn legend_width(entries: &[LegendEntry]) -> u32 {
    let widest = entries
        .iter()
        .map(|e| text_width(e.text(), LEGEND_FONT))
        .fold(0.0, f64::max);
    (widest + 56.0).ceil() as u32
}

/// Draws `figure` into an SVG at `path`; returns its legend (series and style).
fn draw_figure(figure: &Figure, path: &Path) -> anyhow::Result<Vec<(String, Style)>> {
    if figure.series.len() > DISTINCT_STYLES {
        log::warn!(
            "{}: {} series, more than the {DISTINCT_STYLES} distinct styles: some look alike",
            figure.file,
            figure.series.len()
        );
    }
    let panels = panel_keys(&figure.points);
    let legend = legend_entries(figure);
    let grid = PanelGrid::new(&panels);
    let legend_w = legend_width(&legend);
    let legend_h = LEGEND_TOP as u32 + legend.len() as u32 * LEGEND_ROW as u32 + 16;
    let (panel_w, panel_h) = panel_size(panels.len());
    let plots_w = grid.cols as u32 * panel_w;
    let plots_h = grid.rows as u32 * panel_h;
    let header_w = text_width(&figure.title, TITLE_FONT * 1.1)
        .max(text_width(&figure.subtitle, SUBTITLE_FONT))
        + 32.0;
    let size = (
        (plots_w + legend_w).max(header_w.ceil() as u32),
        HEADER_H + plots_h.max(legend_h),
    );
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    let (header, body) = root.split_vertically(HEADER_H);
    draw_header(&header, figure)?;
    let (plots, legend_area) = body.split_horizontally(plots_w);
    if figure.points.is_empty() {
        plots.draw(&Text::new(figure.empty_note, (20, 20), (FONT, 18)))?;
    } else {
        let x_axis = LogAxis::new(figure.points.iter().map(|p| p.x), &figure.x_names);
        let y_axis = LogAxis::new(figure.points.iter().map(|p| p.y), &[]);
        let plots = plots.shrink((0, 0), (plots_w, plots_h));
        let areas = plots.split_evenly((grid.rows, grid.cols));
        for (k, panel) in panels.iter().enumerate() {
            draw_panel(&areas[grid.cell(k)], figure, panel, &x_axis, &y_axis)?;
        }
    }
    draw_legend(&legend_area, &legend)?;
    root.present()?;
    Ok(legend
        .into_iter()
        .filter_map(|e| match e {
            LegendEntry::Series(text, style) => Some((text, style)),
            _ => None,
        })
        .collect())
}

fn draw_header(area: &DrawingArea<SVGBackend<'_>, Shift>, figure: &Figure) -> anyhow::Result<()> {
    let title = FontDesc::new(FontFamily::SansSerif, TITLE_FONT, FontStyle::Bold);
    area.draw(&Text::new(figure.title.clone(), (16, 10), title))?;
    area.draw(&Text::new(
        figure.subtitle.clone(),
        (16, 38),
        (FONT, SUBTITLE_FONT)
            .into_font()
            .color(&RGBColor(80, 80, 80)),
    ))?;
    Ok(())
}

fn draw_legend(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    entries: &[LegendEntry],
) -> anyhow::Result<()> {
    let text_style =
        TextStyle::from((FONT, LEGEND_FONT).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for (i, entry) in entries.iter().enumerate() {
        let y = LEGEND_TOP + i as i32 * LEGEND_ROW;
        match entry {
            LegendEntry::Series(_, style) => {
                area.draw(&PathElement::new(
                    vec![(8, y), (36, y)],
                    style.colour.stroke_width(2),
                ))?;
                draw_marker(area, (22, y), *style)?;
            }
            LegendEntry::Pareto => {
                area.draw(&PathElement::new(vec![(8, y), (36, y)], pareto_style()))?;
            }
            LegendEntry::Note(_) => {}
        }
        area.draw(&Text::new(
            entry.text().to_string(),
            (44, y),
            text_style.clone(),
        ))?;
    }
    Ok(())
}

fn pareto_style() -> ShapeStyle {
    BLACK.mix(0.12).stroke_width(10)
}

/// The darker shade of a series colour that point labels are written in (light hues
/// such as olive or cyan are hard to read as text).
fn label_colour(colour: RGBColor) -> RGBColor {
    let dark = |c: u8| (c as f64 * 0.65) as u8;
    RGBColor(dark(colour.0), dark(colour.1), dark(colour.2))
}

type PanelChart<'a> = ChartContext<
    'a,
    SVGBackend<'a>,
    Cartesian2d<WithKeyPoints<LogCoord<f64>>, WithKeyPoints<LogCoord<f64>>>,
>;

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    figure: &Figure,
    panel: &[String],
    x_axis: &LogAxis,
    y_axis: &LogAxis,
) -> anyhow::Result<()> {
    let points: Vec<&PlotPoint> = figure.points.iter().filter(|p| p.panel == panel).collect();
    let mut builder = ChartBuilder::on(area);
    if !panel.is_empty() {
        builder.caption(panel.join(", "), (FONT, 18));
    }
    let mut chart = builder
        .margin(10)
        .margin_right(18)
        .x_label_area_size(48)
        .y_label_area_size(62)
        .build_cartesian_2d(x_axis.spec(), y_axis.spec())?;
    let x_label = |v: &f64| x_axis.label(*v);
    let y_label = |v: &f64| y_axis.label(*v);
    chart
        .configure_mesh()
        .x_desc(figure.x_desc.as_str())
        .y_desc(figure.y_desc.as_str())
        .x_label_formatter(&x_label)
        .y_label_formatter(&y_label)
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 15))
        .bold_line_style(BLACK.mix(0.2))
        .light_line_style(BLACK.mix(0.06))
        .draw()?;
    if figure.pareto {
        draw_pareto(&mut chart, &points)?;
    }
    draw_series_lines(&mut chart, figure, &points)?;
    for p in &points {
        draw_marker(chart.plotting_area(), (p.x, p.y), style_of(figure, p))?;
    }
    draw_point_labels(&chart, figure, &points)?;
    Ok(())
}

fn style_of(figure: &Figure, p: &PlotPoint) -> Style {
    series_style(
        figure
            .series
            .iter()
            .position(|s| *s == p.series)
            .unwrap_or(0),
    )
}

/// The Pareto front as a wide translucent band under the points, with a disc under each
/// point on it (a front of one point is a disc alone).
fn draw_pareto(chart: &mut PanelChart<'_>, points: &[&PlotPoint]) -> anyhow::Result<()> {
    let xy: Vec<(f64, f64)> = points.iter().map(|p| (p.x, p.y)).collect();
    let front = pareto_front(&xy);
    chart.draw_series(LineSeries::new(front.clone(), pareto_style()))?;
    chart.draw_series(
        front
            .iter()
            .map(|p| Circle::new(*p, 9, BLACK.mix(0.12).filled())),
    )?;
    Ok(())
}

/// Joins each series' points in their order (light count, radius, grid).
fn draw_series_lines(
    chart: &mut PanelChart<'_>,
    figure: &Figure,
    points: &[&PlotPoint],
) -> anyhow::Result<()> {
    for series in &figure.series {
        let mut line: Vec<&&PlotPoint> = points.iter().filter(|p| p.series == *series).collect();
        if line.len() < 2 {
            continue;
        }
        line.sort_by(|a, b| a.order.total_cmp(&b.order));
        let style = style_of(figure, line[0]);
        let xy: Vec<(f64, f64)> = if figure.series_fronts {
            pareto_front(&line.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>())
        } else {
            line.iter().map(|p| (p.x, p.y)).collect()
        };
        chart.draw_series(LineSeries::new(xy, style.colour.mix(0.75).stroke_width(2)))?;
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Point labels placed where they cover no marker and no other label.

#[derive(Debug, Clone, Copy, PartialEq)]
struct Rect {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Rect {
    fn overlap(&self, other: &Rect) -> f64 {
        let w = self.x1.min(other.x1) - self.x0.max(other.x0);
        let h = self.y1.min(other.y1) - self.y0.max(other.y0);
        if w > 0.0 && h > 0.0 { w * h } else { 0.0 }
    }

    fn inside(&self, bounds: &Rect) -> bool {
        self.x0 >= bounds.x0 && self.x1 <= bounds.x1 && self.y0 >= bounds.y0 && self.y1 <= bounds.y1
    }
}

const LABEL_FONT: f64 = 14.0;

/// A place for a label around a point: the text anchor's offset from the point and how
/// the text hangs from it.
struct Spot {
    dx: i32,
    dy: i32,
    h: HPos,
    v: VPos,
}

/// Right, left, above, below, the diagonals, then the same farther out.
fn label_spots() -> Vec<Spot> {
    let mut spots = Vec::new();
    for d in [MARKER_SIZE + 4, MARKER_SIZE + 16] {
        spots.extend([
            Spot {
                dx: d,
                dy: 0,
                h: HPos::Left,
                v: VPos::Center,
            },
            Spot {
                dx: -d,
                dy: 0,
                h: HPos::Right,
                v: VPos::Center,
            },
            Spot {
                dx: 0,
                dy: -d,
                h: HPos::Center,
                v: VPos::Bottom,
            },
            Spot {
                dx: 0,
                dy: d,
                h: HPos::Center,
                v: VPos::Top,
            },
            Spot {
                dx: d - 2,
                dy: -(d - 2),
                h: HPos::Left,
                v: VPos::Bottom,
            },
            Spot {
                dx: d - 2,
                dy: d - 2,
                h: HPos::Left,
                v: VPos::Top,
            },
            Spot {
                dx: -(d - 2),
                dy: -(d - 2),
                h: HPos::Right,
                v: VPos::Bottom,
            },
            Spot {
                dx: -(d - 2),
                dy: d - 2,
                h: HPos::Right,
                v: VPos::Top,
            },
        ]);
    }
    spots
}

/// The box a label's text covers at a spot around `at` (pixels).
fn label_box(at: (i32, i32), spot: &Spot, w: f64, h: f64) -> Rect {
    let x = (at.0 + spot.dx) as f64;
    let y = (at.1 + spot.dy) as f64;
    let x0 = match spot.h {
        HPos::Left => x,
        HPos::Center => x - w / 2.0,
        HPos::Right => x - w,
    };
    let y0 = match spot.v {
        VPos::Top => y,
        VPos::Center => y - h / 2.0,
        VPos::Bottom => y - h,
    };
    Rect {
        x0,
        y0,
        x1: x0 + w,
        y1: y0 + h,
    }
}

/// The first spot whose box stays inside `bounds` and overlaps nothing `taken`; else the
/// one that overlaps least (a label is never dropped).
fn place_label(at: (i32, i32), w: f64, h: f64, taken: &[Rect], bounds: &Rect) -> (Spot, Rect) {
    let mut best: Option<(f64, Spot, Rect)> = None;
    for spot in label_spots() {
        let rect = label_box(at, &spot, w, h);
        let mut cost: f64 = taken.iter().map(|t| t.overlap(&rect)).sum();
        if !rect.inside(bounds) {
            cost += 1e6;
        }
        if cost == 0.0 {
            return (spot, rect);
        }
        if best.as_ref().is_none_or(|b| cost < b.0) {
            best = Some((cost, spot, rect));
        }
    }
    let (_, spot, rect) = best.expect("label_spots is not empty");
    (spot, rect)
}

fn draw_point_labels(
    chart: &PanelChart<'_>,
    figure: &Figure,
    points: &[&PlotPoint],
) -> anyhow::Result<()> {
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let bounds = Rect {
        x0: xs.start as f64,
        y0: ys.start as f64,
        x1: xs.end as f64,
        y1: ys.end as f64,
    };
    let pixel = |p: &PlotPoint| chart.backend_coord(&(p.x, p.y));
    let m = MARKER_SIZE as f64 + 1.0;
    let mut taken: Vec<Rect> = points
        .iter()
        .map(|p| {
            let (x, y) = pixel(p);
            Rect {
                x0: x as f64 - m,
                y0: y as f64 - m,
                x1: x as f64 + m,
                y1: y as f64 + m,
            }
        })
        .collect();
    let h = font_px(LABEL_FONT) * 1.15;
    for p in points {
        let Some(text) = &p.label else { continue };
        let (spot, rect) = place_label(pixel(p), text_width(text, LABEL_FONT), h, &taken, &bounds);
        taken.push(rect);
        let colour = label_colour(style_of(figure, p).colour);
        let style = TextStyle::from((FONT, LABEL_FONT).into_font())
            .color(&colour)
            .pos(Pos::new(spot.h, spot.v));
        chart.plotting_area().draw(
            &(EmptyElement::at((p.x, p.y)) + Text::new(text.clone(), (spot.dx, spot.dy), style)),
        )?;
    }
    Ok(())
}

fn opt(value: Option<f64>, digits: usize) -> String {
    value
        .map(|v| format!("{v:.digits$}"))
        .unwrap_or_else(|| "-".into())
}

fn markdown(report: &BenchReport, ok: &[&BenchResult]) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# manylights bench report\n");
    let _ = writeln!(
        md,
        "- adapter: {} ({}), driver {}",
        report.adapter,
        report.backend,
        report.driver.trim()
    );
    let _ = writeln!(
        md,
        "- timestamps: {}; started {}",
        if report.timestamps {
            "yes"
        } else {
            "no (GPU times unavailable)"
        },
        report.started
    );
    let m = &report.matrix;
    let _ = writeln!(
        md,
        "- {} warm-up + {} timed frames per configuration, time step {:.4} s, seed {}, intensity {}",
        m.warmup_frames, m.frames, m.time_step, m.seed, m.intensity
    );
    let _ = writeln!(
        md,
        "- reference: naive + unbounded inverse-square image up to {} lights; f64 CPU shading at {} sampled pixels always",
        m.reference_light_limit, m.reference_samples
    );
    let remeasured: Vec<String> = report
        .results
        .iter()
        .filter(|r| r.clock_remeasures > 0)
        .map(|r| format!("{} ({}x)", r.config.describe(), r.clock_remeasures))
        .collect();
    let still_slow: Vec<String> = crate::lab::slow_clock_results(&report.results)
        .into_iter()
        .map(|i| report.results[i].config.describe())
        .collect();
    let _ = writeln!(
        md,
        "- clock check: a configuration whose g-buffer or depth pre-pass (work the lights do not change) took over 10% longer than the same pass elsewhere in the run was measured while the GPU's clock was low, and is measured again; again: {}; still slow: {}",
        if remeasured.is_empty() {
            "none".to_string()
        } else {
            remeasured.join(", ")
        },
        if still_slow.is_empty() {
            "none".to_string()
        } else {
            still_slow.join(", ")
        }
    );
    if report.interrupted {
        let _ = writeln!(
            md,
            "- **interrupted**: only the configurations below were measured"
        );
    }
    let _ = writeln!(
        md,
        "\nCharts: [GPU ms vs lights](gpu_ms_vs_lights.svg), [error vs time](error_vs_time.svg), [lights per cluster vs grid](lights_per_cluster_vs_grid.svg), [assignment ms vs lights](assign_ms_vs_lights.svg). Raw numbers: `bench.json`.\n"
    );
    let _ = writeln!(
        md,
        "| scene | size | pipeline | grid | threshold | falloff | lights | GPU ms median | p95 | passes (median ms) | PSNR dB | FLIP | max abs | f64 max rel | lights/cluster mean / max | false pos. | evals/s |"
    );
    let _ = writeln!(
        md,
        "|---|---|---|---|---:|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in ok {
        let c = &r.config;
        let passes: Vec<String> = r
            .passes
            .iter()
            .map(|p| format!("{} {:.3}", p.name, p.median_ms))
            .collect();
        let _ = writeln!(
            md,
            "| {} | {}x{} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2e} | {} | {} | {} |",
            c.scene,
            c.size.0,
            c.size.1,
            c.variant(),
            c.grid.clone().unwrap_or_else(|| "-".into()),
            c.threshold,
            c.falloff,
            c.lights,
            opt(r.gpu_total_median_ms, 3),
            opt(r.gpu_total_p95_ms, 3),
            passes.join(", "),
            opt(r.accuracy.psnr_db, 1),
            opt(r.accuracy.flip_mean, 4),
            opt(r.accuracy.max_abs, 4),
            r.accuracy.f64_max_relative,
            match (r.lights_per_cluster_mean, r.lights_per_cluster_max) {
                (Some(mean), Some(max)) => format!("{mean:.1} / {max}"),
                _ => "-".into(),
            },
            opt(r.false_positive_ratio, 3),
            r.evaluations_per_second
                .map(|e| format!("{e:.3e}"))
                .unwrap_or_else(|| "-".into()),
        );
    }
    let _ = writeln!(
        md,
        "\n## Accuracy against the unbounded reference\n\nMean relative error of HDR radiance against the f64 reference at the sampled pixels (all, the darkest third, the brightest third by the reference), FLIP of both images tonemapped at one exposure chosen from the reference (its median lit luminance to mid-grey), and for stochastic far fields the noise (mean relative standard deviation over {} seeds) and bias (mean relative error of the seeds' mean).\n",
        m.noise_seeds
    );
    let _ = writeln!(
        md,
        "| pipeline | lights | radius m | far field | GPU ms | mean rel. | dark third | bright third | FLIP @ ref. exposure | exposure | noise | bias |"
    );
    let _ = writeln!(
        md,
        "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in ok {
        let c = &r.config;
        let a = &r.accuracy;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {} | {} | {} | {} |",
            c.variant(),
            c.lights,
            metres(RadiusMode::LuminanceThreshold(c.threshold).radius(m.intensity)),
            c.far_field.clone().unwrap_or_else(|| "off".into()),
            opt(r.gpu_total_median_ms, 3),
            a.f64_mean_relative,
            a.f64_mean_relative_dark,
            a.f64_mean_relative_bright,
            opt(a.flip_at_reference_exposure, 4),
            opt(a.reference_exposure, 3),
            opt(a.f64_noise_relative, 4),
            opt(a.f64_bias_relative, 4),
        );
    }
    let failed: Vec<&BenchResult> = report
        .results
        .iter()
        .filter(|r| r.error.is_some())
        .collect();
    if !failed.is_empty() {
        let _ = writeln!(md, "\n## Configurations that failed\n");
        for r in failed {
            let _ = writeln!(
                md,
                "- {} {} lights {}x{}: {}",
                r.config.scene,
                r.config.lights,
                r.config.size.0,
                r.config.size.1,
                r.error.clone().unwrap_or_default()
            );
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::{Accuracy, BenchConfig, BenchMatrix};

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
        // The issue's chart: one label ("1.0") on an axis from 0.15 to 1.
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
                pipeline: pipeline.into(),
                lights,
                size: (640, 360),
                grid: grid.map(String::from),
                gbuffer: deferred.then(|| "compact".into()),
                lighting: deferred.then(|| "compute".into()),
                assignment: (pipeline != "naive").then(|| crate::lab::DEFAULT_ASSIGNMENT.into()),
                threshold,
                falloff: "windowed".into(),
                far_field: None,
                spot_fraction: 0.0,
                spot_culling: None,
            },
            // Clustered pipelines report their assignment steps (a tenth of the frame).
            passes: if deferred || pipeline == "forward-plus" {
                vec![crate::lab::PassTime {
                    name: "assign: fill lists".into(),
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
            error: None,
            clock_remeasures: 0,
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
}
