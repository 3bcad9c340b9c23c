//! What to plot: settings as labels, split into panels, series and point labels (the figures
//! each chart draws, and the Pareto front).

use crate::lab::{BenchReport, BenchResult};
use manylights::lights::RadiusMode;

/// A setting a chart can split its data by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Dim {
    Scene,
    Size,
    Falloff,
    Lights,
    Radius,
    Pipeline,
    Grid,
    Assignment,
}

pub(super) const DIMS: [Dim; 8] = [
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
pub(super) struct Labeller {
    pub(super) intensity: f32,
    pub(super) adapter: String,
    pub(super) varying: Vec<Dim>,
    /// The label of each setting that did not vary.
    pub(super) constant: Vec<String>,
}

impl Labeller {
    pub(super) fn new(report: &BenchReport, results: &[&BenchResult]) -> Self {
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

    pub(super) fn varies(&self, dim: Dim) -> bool {
        self.varying.contains(&dim)
    }

    pub(super) fn radius(&self, r: &BenchResult) -> f32 {
        RadiusMode::LuminanceThreshold(r.config.threshold).radius(self.intensity)
    }

    /// The long label of a setting; None where it does not apply (naive has no grid).
    pub(super) fn label(&self, dim: Dim, r: &BenchResult) -> Option<String> {
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
    pub(super) fn radius_short(&self, r: &BenchResult) -> String {
        let tolerance = r
            .config
            .far_field
            .map(|far| format!(" t {}", far.tolerance))
            .unwrap_or_default();
        format!("r {} m{tolerance}", metres(self.radius(r)))
    }

    /// The labels of those of `dims` that vary.
    pub(super) fn key(&self, dims: &[Dim], r: &BenchResult) -> Vec<String> {
        dims.iter()
            .filter(|d| self.varies(**d))
            .filter_map(|d| self.label(*d, r))
            .collect()
    }

    /// A series per pipeline configuration (layout, lighting path, grid when it varies).
    pub(super) fn pipeline_series(&self, r: &BenchResult) -> String {
        let mut key = vec![r.config.variant()];
        if self.varies(Dim::Grid) {
            key.extend(self.label(Dim::Grid, r));
        }
        key.join(", ")
    }

    /// The settings every point shares, for the subtitle.
    pub(super) fn subtitle(&self) -> String {
        // Browsers may keep the adapter's name to themselves: then it is left out.
        let adapter = Some(self.adapter.clone()).filter(|name| !name.is_empty());
        let mut parts: Vec<String> = adapter.into_iter().collect();
        parts.extend(self.constant.iter().cloned());
        parts.join("; ")
    }
}

/// `200,000`.
pub(super) fn thousands(n: u32) -> String {
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
pub(super) fn metres(radius: f32) -> String {
    let decimals = if radius >= 10.0 {
        0
    } else if radius >= 1.0 {
        1
    } else {
        2
    };
    trim_zeros(format!("{radius:.decimals$}"))
}

pub(super) fn trim_zeros(text: String) -> String {
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// One plotted value, already assigned to its panel and series.
#[derive(Debug, Clone)]
pub(super) struct PlotPoint {
    /// The labels of the settings that pick the panel.
    pub(super) panel: Vec<String>,
    pub(super) series: String,
    pub(super) x: f64,
    pub(super) y: f64,
    /// Drawn next to the point when the series has several points that x alone does not
    /// tell apart (the radius on the error chart).
    pub(super) label: Option<String>,
    /// Points of a series are joined in this order.
    pub(super) order: f64,
}

/// A chart: panels of points, one shared legend.
pub(super) struct Figure {
    pub(super) file: &'static str,
    pub(super) title: String,
    pub(super) subtitle: String,
    pub(super) x_desc: String,
    pub(super) y_desc: String,
    /// Names shown instead of numbers at these x values (cluster grids).
    pub(super) x_names: Vec<(f64, String)>,
    pub(super) points: Vec<PlotPoint>,
    /// Legend order; a series' index picks its colour and marker.
    pub(super) series: Vec<String>,
    pub(super) pareto: bool,
    /// Each series' line joins its own Pareto front (time against error) instead of its
    /// points in order: a method's best trade at each cost.
    pub(super) series_fronts: bool,
    /// What the point labels mean, for the legend.
    pub(super) label_note: Option<&'static str>,
    /// Points are labelled with their series' number, which the legend shows too.
    pub(super) numbered: bool,
    /// Shown instead of panels when there is nothing to plot.
    pub(super) empty_note: &'static str,
}

impl Figure {
    pub(super) fn new(
        file: &'static str,
        title: String,
        labels: &Labeller,
        points: Vec<PlotPoint>,
    ) -> Self {
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
pub(super) fn x_dim(labels: &Labeller, preferred: &[Dim]) -> Dim {
    preferred
        .iter()
        .copied()
        .find(|d| labels.varies(*d))
        .unwrap_or(preferred[0])
}

pub(super) fn setting_value(labels: &Labeller, dim: Dim, r: &BenchResult) -> Option<f64> {
    match dim {
        Dim::Lights => Some(r.config.lights as f64),
        Dim::Radius => Some(labels.radius(r) as f64),
        Dim::Grid => r.cluster_count.map(|c| c as f64),
        _ => None,
    }
}

/// GPU time against light count: a line per pipeline configuration, a panel per scene,
/// size, falloff and radius. A run with one light count plots against the radius instead.
pub(super) fn time_figure(labels: &Labeller, results: &[&BenchResult]) -> Figure {
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
pub(super) fn assignment_figure(labels: &Labeller, results: &[&BenchResult]) -> Figure {
    let panel_dims = [Dim::Scene, Dim::Size, Dim::Falloff, Dim::Radius, Dim::Grid];
    let points = results
        .iter()
        .filter_map(|r| {
            let steps: Vec<f64> = r
                .passes
                .iter()
                .filter(|p| p.name.in_stage(manylights::cluster::passes::ASSIGN_STAGE))
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
                    r.config.assignment.unwrap_or_default(),
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
pub(super) fn error_of(r: &BenchResult) -> f64 {
    r.accuracy.f64_mean_relative.max(1e-9)
}

/// Error against time: a panel per workload (scene, size, falloff, light count) since
/// only configurations of the same workload compete; a series per pipeline
/// configuration, its points labelled with their radius and joined in radius order.
pub(super) fn error_figure(labels: &Labeller, results: &[&BenchResult]) -> Figure {
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
pub(super) fn number_points(figure: &mut Figure) {
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
pub(super) fn cluster_figure(labels: &Labeller, results: &[&BenchResult]) -> Figure {
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
            let grid = r.config.grid.unwrap_or_default();
            let dims = format!("{}x{}x{}", grid.tiles_x, grid.tiles_y, grid.slices);
            x_names.push((xv, dims));
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

pub(super) fn pareto_front(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
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
