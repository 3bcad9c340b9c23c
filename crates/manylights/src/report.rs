//! The lab's outputs: `bench.json` (every raw number), `REPORT.md` (tables), and SVG
//! charts drawn with plotters: GPU time against light count per pipeline (log axes),
//! error against time with the Pareto front, and lights per cluster against grid size.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context as _;
use plotters::prelude::*;

use crate::lab::{BenchReport, BenchResult};

/// Writes bench.json, REPORT.md and the charts into `dir`.
pub fn write_all(report: &BenchReport, dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let json = serde_json::to_string_pretty(report)?;
    std::fs::write(dir.join("bench.json"), json)
        .with_context(|| format!("writing {}", dir.join("bench.json").display()))?;
    let ok: Vec<&BenchResult> = report
        .results
        .iter()
        .filter(|r| r.error.is_none() && r.gpu_total_median_ms.is_some())
        .collect();
    time_vs_lights(&ok, &dir.join("gpu_ms_vs_lights.svg"))?;
    error_vs_time(&ok, &dir.join("error_vs_time.svg"))?;
    lights_per_cluster_vs_grid(&ok, &dir.join("lights_per_cluster_vs_grid.svg"))?;
    std::fs::write(dir.join("REPORT.md"), markdown(report, &ok))
        .with_context(|| format!("writing {}", dir.join("REPORT.md").display()))?;
    Ok(())
}

/// The configuration apart from the light count: one line per such variant.
fn series_key(r: &BenchResult) -> String {
    let c = &r.config;
    let mut key = format!("{} {}", c.scene, c.variant());
    if let Some(grid) = &c.grid {
        key.push_str(&format!(" {grid}"));
    }
    key.push_str(&format!(" t{} {}x{}", c.threshold, c.size.0, c.size.1));
    key
}

fn palette(i: usize) -> RGBColor {
    const COLOURS: [RGBColor; 10] = [
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
    COLOURS[i % COLOURS.len()]
}

fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| *v > 0.0 && v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return 0.1..10.0;
    }
    (lo / 1.5)..(hi * 1.5).max(lo * 2.0)
}

fn time_vs_lights(results: &[&BenchResult], path: &Path) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let x = log_range(results.iter().map(|r| r.config.lights as f64));
    let y = log_range(results.iter().filter_map(|r| r.gpu_total_median_ms));
    let mut chart = ChartBuilder::on(&root)
        .caption("GPU time per frame against light count", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x.log_scale(), y.log_scale())?;
    chart
        .configure_mesh()
        .x_desc("lights")
        .y_desc("GPU ms (median)")
        .draw()?;
    let mut keys: Vec<String> = results.iter().map(|r| series_key(r)).collect();
    keys.sort();
    keys.dedup();
    for (i, key) in keys.iter().enumerate() {
        let mut points: Vec<(f64, f64)> = results
            .iter()
            .filter(|r| &series_key(r) == key)
            .filter_map(|r| r.gpu_total_median_ms.map(|ms| (r.config.lights as f64, ms)))
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let colour = palette(i);
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
            .label(key.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2))
            });
        chart.draw_series(points.iter().map(|p| Circle::new(*p, 3, colour.filled())))?;
    }
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    root.present()?;
    Ok(())
}

/// The error on the speed/accuracy chart: the mean relative error against the f64
/// reference at the sampled pixels, which every configuration has (the reference image
/// is skipped above its light limit).
fn error_of(r: &BenchResult) -> f64 {
    r.accuracy.f64_mean_relative.max(1e-9)
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

fn error_vs_time(results: &[&BenchResult], path: &Path) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let points: Vec<(f64, f64)> = results
        .iter()
        .filter_map(|r| r.gpu_total_median_ms.map(|ms| (ms, error_of(r))))
        .collect();
    let x = log_range(points.iter().map(|p| p.0));
    let y = log_range(points.iter().map(|p| p.1));
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Error against GPU time (Pareto front in red)",
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x.log_scale(), y.log_scale())?;
    chart
        .configure_mesh()
        .x_desc("GPU ms per frame (median)")
        .y_desc("mean relative error vs f64 reference")
        .draw()?;
    chart.draw_series(
        points
            .iter()
            .map(|p| Circle::new(*p, 4, BLUE.mix(0.6).filled())),
    )?;
    let front = pareto_front(&points);
    chart.draw_series(LineSeries::new(front.clone(), RED.stroke_width(2)))?;
    chart.draw_series(front.iter().map(|p| Circle::new(*p, 5, RED.filled())))?;
    root.present()?;
    Ok(())
}

fn lights_per_cluster_vs_grid(results: &[&BenchResult], path: &Path) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let points: Vec<(f64, f64, u32)> = results
        .iter()
        .filter_map(|r| {
            Some((
                r.cluster_count? as f64,
                r.lights_per_cluster_mean?,
                r.config.lights,
            ))
        })
        .collect();
    let x = log_range(points.iter().map(|p| p.0));
    let y = log_range(points.iter().map(|p| p.1));
    let mut chart = ChartBuilder::on(&root)
        .caption("Lights per cluster against grid size", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x.log_scale(), y.log_scale())?;
    chart
        .configure_mesh()
        .x_desc("clusters")
        .y_desc("mean lights per cluster")
        .draw()?;
    let mut counts: Vec<u32> = points.iter().map(|p| p.2).collect();
    counts.sort_unstable();
    counts.dedup();
    for (i, count) in counts.iter().enumerate() {
        let colour = palette(i);
        chart
            .draw_series(
                points
                    .iter()
                    .filter(|p| p.2 == *count)
                    .map(|p| Circle::new((p.0, p.1), 4, colour.filled())),
            )?
            .label(format!("{count} lights"))
            .legend(move |(x, y)| Circle::new((x + 8, y), 4, colour.filled()));
    }
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .draw()?;
    root.present()?;
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
    if report.interrupted {
        let _ = writeln!(
            md,
            "- **interrupted**: only the configurations below were measured"
        );
    }
    let _ = writeln!(
        md,
        "\nCharts: [GPU ms vs lights](gpu_ms_vs_lights.svg), [error vs time](error_vs_time.svg), [lights per cluster vs grid](lights_per_cluster_vs_grid.svg). Raw numbers: `bench.json`.\n"
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
    use super::pareto_front;

    #[test]
    fn pareto_front_keeps_only_undominated_points() {
        let points = [(1.0, 5.0), (2.0, 3.0), (3.0, 4.0), (4.0, 1.0), (0.5, 9.0)];
        assert_eq!(
            pareto_front(&points),
            vec![(0.5, 9.0), (1.0, 5.0), (2.0, 3.0), (4.0, 1.0)]
        );
    }
}
