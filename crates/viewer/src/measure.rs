//! The measure panel: the lab's matrix (pipelines x light counts x light radius, with and
//! without a far field) run on this GPU from the viewer, on the scene shown and its
//! reference camera. The run is the lab's own ([`LabJob`]), on a device of its own,
//! advanced a little each displayed frame while the viewer's own rendering pauses; its
//! report is the `bench.json` of `manylights bench` (so `manylights bench --replot` draws
//! it), shown as a table here and, by the platform, as the lab's charts.

use std::str::FromStr;

use web_time::Duration;

use manylights::PipelineKind;
use manylights::cluster::OptionalFarField;
use manylights_lab::lab::{BenchMatrix, BenchReport, BenchResult, JobProgress, LabJob};

/// How long the run may take of each displayed frame (natively it renders frames until
/// then; in the page it also stops where it waits for the GPU).
const FRAME_BUDGET: Duration = Duration::from_millis(30);

/// The far field the panel compares with none.
const FAR_FIELD: &str = "tree:1";

/// What the panel runs: the axes a user picks, the rest as the lab's defaults.
#[derive(Debug, Clone)]
pub struct MeasureSetup {
    pub pipelines: [bool; 3],
    pub lights: String,
    pub radii: String,
    pub far_field: bool,
    /// Compare every shadow mode (off, exact and each ray budget), each against the
    /// reference with its own visibility (the lab's `shadows` preset's axis).
    pub shadows: bool,
    pub frames: u32,
}

impl Default for MeasureSetup {
    fn default() -> Self {
        Self {
            pipelines: [true; 3],
            lights: "1000, 5000".into(),
            radii: "1, 2".into(),
            far_field: true,
            shadows: false,
            // Browsers quantize GPU timestamps (Chrome: to 100 us): a median over more
            // frames than the native lab's 10.
            frames: 30,
        }
    }
}

fn numbers<T: FromStr>(text: &str, what: &str) -> Result<Vec<T>, String> {
    let values: Result<Vec<T>, _> = text
        .split(',')
        .map(str::trim)
        .filter(|t| !t.is_empty())
        .map(str::parse)
        .collect();
    match values {
        Ok(values) if !values.is_empty() => Ok(values),
        _ => Err(format!("{what}: numbers separated by commas, not '{text}'")),
    }
}

impl MeasureSetup {
    /// The lab's matrix for these choices at the view's size.
    pub fn matrix(&self, size: (u32, u32)) -> Result<BenchMatrix, String> {
        let pipelines: Vec<PipelineKind> = PipelineKind::ALL
            .iter()
            .zip(self.pipelines)
            .filter_map(|(kind, chosen)| chosen.then_some(*kind))
            .collect();
        if pipelines.is_empty() {
            return Err("choose at least one pipeline".into());
        }
        let lights: Vec<u32> = numbers(&self.lights, "light counts")?;
        let radii: Vec<f32> = numbers(&self.radii, "radii")?;
        if let Some(bad) = radii.iter().find(|r| !(r.is_finite() && **r > 0.0)) {
            return Err(format!("radii must be positive metres, not {bad}"));
        }
        let mut matrix = BenchMatrix {
            pipelines,
            lights,
            sizes: vec![size.into()],
            frames: self.frames.max(1),
            ..BenchMatrix::default()
        };
        // A light's radius is where its intensity falls to the threshold.
        matrix.thresholds = radii.iter().map(|r| matrix.intensity / (r * r)).collect();
        if self.far_field {
            let far = OptionalFarField::from_str(FAR_FIELD).map_err(|e| e.to_string())?;
            matrix.far_fields = vec![OptionalFarField(None), far];
        }
        if self.shadows {
            matrix.shadows = manylights::Shadows::ALL.to_vec();
        }
        Ok(matrix)
    }
}

/// The panel: its setup, the run in progress, and the last run's outcome.
#[derive(Debug, Default)]
pub struct MeasurePanel {
    pub setup: MeasureSetup,
    pub job: Option<LabJob>,
    /// The last run's report and what the platform did with it (the folder it was
    /// written to, or where the page shows it).
    pub finished: Option<(BenchReport, String)>,
    pub error: Option<String>,
    pub start_requested: bool,
    pub show_results: bool,
}

impl MeasurePanel {
    /// Advances the run; its report once it ended.
    pub fn advance(&mut self) -> Option<anyhow::Result<BenchReport>> {
        let ended = self.job.as_mut()?.advance(FRAME_BUDGET);
        if ended.is_some() {
            self.job = None;
        }
        ended
    }

    pub fn running(&self) -> bool {
        self.job.is_some()
    }
}

/// The panel's section of the settings.
pub fn measure_section(ui: &mut egui::Ui, panel: &mut MeasurePanel) {
    ui.label("Times every choice below on this GPU and compares it with the f64 reference (the lab's matrix, on the reference camera).");
    let running = panel.running();
    ui.add_enabled_ui(!running, |ui| {
        ui.horizontal(|ui| {
            for ((kind, chosen), name) in PipelineKind::ALL
                .iter()
                .zip(&mut panel.setup.pipelines)
                .zip(["naive", "Forward+", "deferred"])
            {
                ui.checkbox(chosen, name).on_hover_text(kind.to_string());
            }
        });
        ui.horizontal(|ui| {
            ui.label("lights");
            ui.text_edit_singleline(&mut panel.setup.lights);
        });
        ui.horizontal(|ui| {
            ui.label("radii (m)");
            ui.text_edit_singleline(&mut panel.setup.radii);
        });
        ui.checkbox(
            &mut panel.setup.far_field,
            format!("also with a far field ({FAR_FIELD})"),
        );
        ui.checkbox(
            &mut panel.setup.shadows,
            "every shadow mode (off, exact, 1, 2 and 4 rays a pixel, each also filtered)",
        );
        ui.add(egui::Slider::new(&mut panel.setup.frames, 5..=200).text("timed frames"));
    });
    match &panel.job {
        Some(job) => {
            let JobProgress { done, total, last } = job.progress();
            ui.add(
                egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                    .text(format!("{done} of {total} configurations")),
            );
            if !last.is_empty() {
                ui.small(last);
            }
            if ui.button("Stop").clicked() {
                job.stop();
            }
        }
        None => {
            if ui.button("Measure").clicked() {
                panel.start_requested = true;
            }
        }
    }
    if let Some(error) = &panel.error {
        ui.colored_label(egui::Color32::LIGHT_RED, error);
    }
    if let Some((report, saved)) = &panel.finished {
        ui.label(format!(
            "{} configurations measured on {}{}",
            report.results.len(),
            report.adapter,
            if report.interrupted { " (stopped)" } else { "" }
        ));
        ui.small(saved);
        ui.toggle_value(&mut panel.show_results, "results table");
    }
}

/// The last run's table: one row a configuration.
pub fn results_window(ctx: &egui::Context, panel: &mut MeasurePanel) {
    let Some((report, _)) = &panel.finished else {
        return;
    };
    egui::Window::new("Measured")
        .open(&mut panel.show_results)
        .default_width(620.0)
        .vscroll(true)
        .show(ctx, |ui| {
            ui.small(format!(
                "{}, {} backend; GPU time: median of {} frames after warm-up{}; error: mean relative HDR error at {} pixels against the f64 reference",
                report.adapter,
                report.backend,
                report.matrix.frames,
                if report.timestamps { "" } else { " (no timestamps on this device)" },
                report.matrix.reference_samples
            ));
            egui::Grid::new("measured")
                .striped(true)
                .num_columns(6)
                .show(ui, |ui| {
                    for heading in ["pipeline", "lights", "radius", "GPU ms", "p95 ms", "error"] {
                        ui.strong(heading);
                    }
                    ui.end_row();
                    for result in &report.results {
                        result_row(ui, report, result);
                        ui.end_row();
                    }
                });
        });
}

fn result_row(ui: &mut egui::Ui, report: &BenchReport, result: &BenchResult) {
    let config = &result.config;
    let ms = |value: Option<f64>| value.map_or("-".into(), |ms| format!("{ms:.3}"));
    ui.label(config.variant());
    ui.label(config.lights.to_string());
    ui.label(format!(
        "{:.2} m",
        (report.matrix.intensity / config.threshold).sqrt()
    ));
    ui.label(ms(result.gpu_total_median_ms));
    ui.label(ms(result.gpu_total_p95_ms));
    match &result.error {
        Some(error) => ui.colored_label(egui::Color32::LIGHT_RED, error),
        None => ui.label(format!("{:.4}", result.accuracy.f64_mean_relative)),
    };
}
