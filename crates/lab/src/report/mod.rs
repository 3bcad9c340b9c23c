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
//!
//! One idea per file: `figures` (what to plot: labels, panels, series, the Pareto front),
//! `axes` (log ranges and ticks), `style` (each series' colour and marker), `draw` (the
//! header, the panel grid and the legend), `point_labels` (labels that cover nothing) and
//! `markdown` (REPORT.md).

use std::path::Path;

use anyhow::Context as _;

use crate::lab::{BenchReport, BenchResult};

mod axes;
mod draw;
mod figures;
mod markdown;
mod point_labels;
mod style;
#[cfg(test)]
mod tests;

use draw::draw_figure;
use figures::{Labeller, assignment_figure, cluster_figure, error_figure, time_figure};
use markdown::markdown;
use style::Style;

/// Writes bench.json, REPORT.md and the charts into `dir`.
pub fn write_all(report: &BenchReport, dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let report = &write_error_maps(report, dir)?;
    let json = serde_json::to_string_pretty(report)?;
    std::fs::write(dir.join("bench.json"), json)
        .with_context(|| format!("writing {}", dir.join("bench.json").display()))?;
    write_charts_and_markdown(report, dir)
}

/// Writes each configuration's error map (`error-maps/NNN.png`, by its place in the run)
/// and returns the report naming them.
fn write_error_maps(report: &BenchReport, dir: &Path) -> anyhow::Result<BenchReport> {
    let mut named = report.clone();
    for (index, result) in named.results.iter_mut().enumerate() {
        let Some(map) = result.accuracy.error_map.take() else {
            continue;
        };
        let file = format!("error-maps/{index:03}.png");
        let path = dir.join(&file);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("creating {}", parent.display()))?;
        }
        map.save(&path)
            .with_context(|| format!("writing {}", path.display()))?;
        result.accuracy.error_map_file = Some(file);
    }
    Ok(named)
}

/// An error map as PNG bytes (the page shows it inline; `write_all` saves it as a file).
pub fn error_map_png(map: &image::RgbImage) -> anyhow::Result<Vec<u8>> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    map.write_to(&mut bytes, image::ImageFormat::Png)
        .context("encoding an error map as PNG")?;
    Ok(bytes.into_inner())
}

/// Redraws the charts and REPORT.md of a finished run from its `bench.json` into
/// `out_dir`, without a GPU. `bench.json` itself is not rewritten, so replotting into the
/// run's own folder leaves the raw numbers byte for byte as they were measured.
pub fn replot(bench_json: &Path, out_dir: &Path) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(bench_json)
        .with_context(|| format!("reading {}", bench_json.display()))?;
    let not_a_report = || format!("{}: not a bench report", bench_json.display());
    let mut data: serde_json::Value = serde_json::from_str(&text).with_context(not_a_report)?;
    crate::lab::setting_axes::upgrade_report(&mut data);
    let report: BenchReport = serde_json::from_value(data).with_context(not_a_report)?;
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

/// A chart of a run: the file name the reports give it and its SVG source.
#[derive(Debug, Clone)]
pub struct Chart {
    pub file: &'static str,
    pub svg: String,
}

/// A chart's legend: each series' label and style.
type Legend = Vec<(String, Style)>;

/// The run's charts (time against light count, error against time, lights per cluster,
/// assignment) as SVG source, and each one's legend (for the tests).
fn draw_charts(report: &BenchReport, ok: &[&BenchResult]) -> anyhow::Result<Vec<(Chart, Legend)>> {
    let labels = Labeller::new(report, ok);
    let figures = [
        time_figure(&labels, ok),
        error_figure(&labels, ok),
        cluster_figure(&labels, ok),
        assignment_figure(&labels, ok),
    ];
    figures
        .iter()
        .map(|figure| {
            let (svg, legend) =
                draw_figure(figure).with_context(|| format!("drawing {}", figure.file))?;
            Ok((
                Chart {
                    file: figure.file,
                    svg,
                },
                legend,
            ))
        })
        .collect()
}

/// The charts `manylights bench` writes, drawn in memory (the page shows them).
pub fn charts(report: &BenchReport) -> anyhow::Result<Vec<Chart>> {
    let ok = measured(report);
    Ok(draw_charts(report, &ok)?
        .into_iter()
        .map(|(chart, _)| chart)
        .collect())
}

/// REPORT.md's text for a run (the page offers it beside bench.json).
pub fn report_markdown(report: &BenchReport) -> String {
    markdown(report, &measured(report))
}

/// Writes the charts into `dir`; returns each chart's legend (for the tests).
fn write_charts(
    report: &BenchReport,
    ok: &[&BenchResult],
    dir: &Path,
) -> anyhow::Result<Vec<Legend>> {
    let mut legends = Vec::new();
    for (chart, legend) in draw_charts(report, ok)? {
        let path = dir.join(chart.file);
        std::fs::write(&path, chart.svg).with_context(|| format!("writing {}", path.display()))?;
        legends.push(legend);
    }
    Ok(legends)
}
