//! The egui panels: every setting on the left (changes take effect on the next frame),
//! statistics on the right, and the help window.

use std::collections::VecDeque;

use manylights::cluster::{ClusteringSettings, FarField, FarFieldMethod};
use manylights::cluster::{TileSpec, ZRange, ZScheme};
use manylights::gpu::{AutoExposure, Exposure, GpuTimings, Tonemap};
use manylights::lights::{Falloff, RadiusMode};
use manylights::{
    DeferredView, FrameSettings, FrameStats, GBufferLayout, LightingPath, PipelineKind,
    PipelineSettings,
};

/// Frames of GPU time kept for the history plot.
pub const HISTORY: usize = 240;

mod every_setting;
/// What the UI shows besides the settings.
#[derive(Debug, Default)]
pub struct UiState {
    pub show_help: bool,
    pub paused: bool,
    /// Present with vertical sync (changes reconfigure the surface).
    pub vsync: bool,
    pub animation_speed: f32,
    pub error: Option<String>,
    pub load_error: Option<String>,
    pub scene_path: String,
    pub load_requested: Option<String>,
    pub preset_requested: Option<String>,
    pub screenshot_requested: bool,
    pub gpu_history: VecDeque<f64>,
    pub last_stats: Option<FrameStats>,
    /// Whether the last frame traced shadow rays.
    pub shadows: manylights::Shadows,
    /// The light-list capacity the buffer last grew to (an earlier frame overflowed).
    pub list_capacity_grown_to: Option<u32>,
    /// Frame rate and frame time, both from the same recent frames.
    pub frame_clock: FrameClock,
    pub adapter: String,
    /// Times the GPU device was lost and everything recreated, with the last reason.
    pub device_recoveries: Option<(u32, String)>,
    pub scene_name: String,
    /// The scene's own lights (glTF KHR_lights_punctual), described in the lights panel.
    pub scene_lights: Vec<manylights::scene::SceneLight>,
    pub presets: Vec<String>,
    /// The most lights the device can hold: its largest storage binding over a light's
    /// size (the light buffer is the largest per-light binding). 128 MiB, two million
    /// lights, on a WebGPU adapter that grants only the guaranteed limit.
    pub max_lights: u32,
    /// Bytes per pixel of each G-buffer layout (`GBufferLayout::ALL` order) for this scene.
    pub gbuffer_bytes_per_pixel: Vec<u32>,
    /// The "Every setting" section's `PATH=VALUE` being typed.
    pub setting_assignment: String,
}

/// The frame rate and the frame time over the frames of the last second, so the two
/// figures always describe the same frames and agree (FPS = 1000 / frame ms).
#[derive(Debug, Default)]
pub struct FrameClock {
    /// Seconds between consecutive presented frames, oldest first.
    intervals: VecDeque<f64>,
    sum: f64,
}

impl FrameClock {
    /// Frames are averaged over (at least one frame, at most about) this many seconds.
    const WINDOW_SECONDS: f64 = 1.0;

    pub fn tick(&mut self, interval_s: f64) {
        self.intervals.push_back(interval_s);
        self.sum += interval_s;
        while self.intervals.len() > 1 && self.sum - self.intervals[0] >= Self::WINDOW_SECONDS {
            self.sum -= self.intervals.pop_front().unwrap_or(0.0);
        }
    }

    /// Frames the figures are averaged over.
    pub fn frames(&self) -> usize {
        self.intervals.len()
    }

    /// Mean time between frames, in milliseconds.
    pub fn frame_ms(&self) -> f64 {
        if self.intervals.is_empty() {
            0.0
        } else {
            self.sum * 1000.0 / self.intervals.len() as f64
        }
    }

    pub fn fps(&self) -> f64 {
        if self.sum > 0.0 {
            self.intervals.len() as f64 / self.sum
        } else {
            0.0
        }
    }
}

pub const HELP: &str = "\
W A S D   move          Q / E   down / up
right mouse + drag      look around
scroll    speed         Shift   faster
1 / 2 / 3   naive / Forward+ / deferred
H   cluster heatmap     Z   depth slices
G   cycle G-buffer views (deferred)
Space   pause animation   P   print camera
F12   screenshot        F1   this help
drop a .gltf/.glb/.obj file on the window to load it
(in the page: a .glb, or a .gltf with its files, dropped or opened)";

/// A section of the panel, open by default.
fn section(ui: &mut egui::Ui, title: &str, add_contents: impl FnOnce(&mut egui::Ui)) {
    egui::CollapsingHeader::new(title)
        .default_open(true)
        .show(ui, add_contents);
}

fn combo<T: PartialEq + Copy>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut T,
    options: &[(T, &str)],
) {
    combo_planned(ui, label, value, options, |_| None);
}

/// [`combo`] with the options `refusal` names a reason for greyed out, the reason shown on
/// hover: the frame plan's rules ([`manylights::DialCombination`]), asked before a choice
/// is made rather than refused after.
fn combo_planned<T: PartialEq + Copy>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut T,
    options: &[(T, &str)],
    refusal: impl Fn(T) -> Option<String>,
) {
    let current = options
        .iter()
        .find(|(v, _)| v == value)
        .map(|(_, n)| *n)
        .unwrap_or("?");
    egui::ComboBox::from_label(label)
        .selected_text(current)
        .show_ui(ui, |ui| {
            for (option, name) in options {
                match refusal(*option) {
                    None => {
                        ui.selectable_value(value, *option, *name);
                    }
                    Some(reason) => {
                        let selected = *value == *option;
                        ui.add_enabled(false, egui::Button::selectable(selected, *name))
                            .on_disabled_hover_text(reason);
                    }
                }
            }
        });
}

/// Why the frame plan would refuse `settings` changed by `change`, if it would.
fn refused_with(
    settings: &FrameSettings,
    change: impl FnOnce(&mut FrameSettings),
) -> Option<String> {
    let mut changed = settings.clone();
    change(&mut changed);
    manylights::DialCombination::of(&changed).check().err()
}

pub fn settings_panel(ui: &mut egui::Ui, settings: &mut FrameSettings, state: &mut UiState) {
    ui.heading("manylights");
    if let Some(error) = &state.error {
        ui.colored_label(egui::Color32::LIGHT_RED, error);
    }
    section(ui, "Scene", |ui| scene_section(ui, state));
    section(ui, "Pipeline", |ui| pipeline_section(ui, settings, state));
    section(ui, "Lights", |ui| lights_section(ui, settings, state));
    if let Some(clustering) = settings.pipeline.clustering_mut() {
        section(ui, "Clusters", |ui| clusters_section(ui, clustering));
    }
    section(ui, "Image", |ui| image_section(ui, settings));
    egui::CollapsingHeader::new("Every setting")
        .default_open(false)
        .show(ui, |ui| every_setting::section(ui, settings, state));
    ui.horizontal(|ui| {
        if ui.button("Screenshot (F12)").clicked() {
            state.screenshot_requested = true;
        }
        if ui.button("Help (F1)").clicked() {
            state.show_help = !state.show_help;
        }
    });
}
/// The scene: the named ones, a file, the camera presets.
fn scene_section(ui: &mut egui::Ui, state: &mut UiState) {
    ui.label(format!("current: {}", state.scene_name));
    // The named scenes, one click each (`lamps`: the room lit by its file's own point
    // and spot lights; `panel` and `sponza-embers`: lit by their emissive surfaces).
    ui.horizontal(|ui| {
        for name in [
            "sponza",
            "sponza-glass",
            "sponza-embers",
            "cornell",
            "panel",
            "lamps",
            "spheres",
            "glass",
            "wall",
            "pillars",
        ] {
            if ui.button(name).clicked() {
                state.scene_path = name.to_string();
                state.load_requested = Some(name.to_string());
            }
        }
    });
    ui.horizontal(|ui| {
        ui.text_edit_singleline(&mut state.scene_path);
        if ui.button("Load").clicked() {
            state.load_requested = Some(state.scene_path.clone());
        }
    });
    if let Some(error) = &state.load_error {
        ui.colored_label(egui::Color32::LIGHT_RED, error);
    }
    ui.horizontal_wrapped(|ui| {
        for preset in state.presets.clone() {
            if ui.button(&preset).clicked() {
                state.preset_requested = Some(preset);
            }
        }
    });
}

/// Switches to another pipeline ([`PipelineSettings::switched_to`]); the lights-per-cluster
/// statistics the stats panel shows stay as they were, and are on when the lists are new.
pub fn switch_pipeline(settings: &mut FrameSettings, kind: PipelineKind) {
    let (statistics, false_positives) = settings
        .pipeline
        .clustering()
        .map_or((true, false), |clustering| {
            (clustering.stats, clustering.false_positives)
        });
    settings.pipeline = settings.pipeline.switched_to(kind);
    settings
        .pipeline
        .set_list_statistics(statistics, false_positives);
}

/// The pipeline and its own settings.
fn pipeline_section(ui: &mut egui::Ui, settings: &mut FrameSettings, state: &mut UiState) {
    let mut kind = settings.pipeline.kind();
    let kinds = PipelineKind::ALL.map(|k| (k, k.name()));
    let current = settings.clone();
    combo_planned(ui, "pipeline", &mut kind, &kinds, |kind| {
        refused_with(&current, |s| switch_pipeline(s, kind))
    });
    if kind != settings.pipeline.kind() {
        switch_pipeline(settings, kind);
    }
    let unchanged = settings.clone();
    match &mut settings.pipeline {
        PipelineSettings::Deferred(deferred) => {
            let layouts: Vec<(GBufferLayout, String)> = GBufferLayout::ALL
                .iter()
                .enumerate()
                .map(|(i, layout)| match state.gbuffer_bytes_per_pixel.get(i) {
                    Some(bytes) => (*layout, format!("{layout} ({bytes} B/px)")),
                    None => (*layout, layout.to_string()),
                })
                .collect();
            let layouts: Vec<(GBufferLayout, &str)> =
                layouts.iter().map(|(l, n)| (*l, n.as_str())).collect();
            combo(ui, "G-buffer", &mut deferred.layout, &layouts);
            let paths = LightingPath::ALL.map(|p| (p, p.name()));
            let mut lighting = deferred.lighting;
            combo_planned(ui, "lighting", &mut lighting, &paths, |path| {
                refused_with(&unchanged, |s| {
                    if let PipelineSettings::Deferred(d) = &mut s.pipeline {
                        d.lighting = path;
                    }
                })
            });
            deferred.lighting = lighting;
        }
        PipelineSettings::ForwardPlus(forward_plus) => {
            ui.checkbox(&mut forward_plus.depth_prepass, "depth pre-pass");
        }
        PipelineSettings::Naive(_) => {}
    }
    let shadows = manylights::Shadows::ALL.map(|s| (s, s.name()));
    let unchanged = settings.clone();
    combo_planned(
        ui,
        "shadows",
        &mut settings.shadows.mode,
        &shadows,
        |mode| refused_with(&unchanged, |s| s.shadows.mode = mode),
    );
    let brdfs = manylights::lights::Shading::ALL.map(|s| (s, s.name()));
    combo(ui, "BRDF", &mut settings.shading, &brdfs);
    let transparencies = manylights::Transparency::ALL.map(|t| (t, t.name()));
    combo(
        ui,
        "transparency",
        &mut settings.transparency,
        &transparencies,
    );
    ui.checkbox(&mut state.vsync, "vsync (off: GPU-bound frame rate)");
}

/// The spot cone, in degrees on screen; the outer angle bounds the inner one.
fn spot_cone_controls(ui: &mut egui::Ui, cone: &mut manylights::lights::SpotCone) {
    let mut outer = cone.outer.to_degrees();
    let mut inner = cone.inner.to_degrees();
    ui.add(egui::Slider::new(&mut outer, 0.01..=90.0).text("spot outer angle (deg)"));
    ui.add(egui::Slider::new(&mut inner, 0.0..=outer).text("spot inner angle (deg)"));
    cone.outer = outer.to_radians().min(std::f32::consts::FRAC_PI_2);
    cone.inner = inner.min(outer).to_radians().min(cone.outer);
}

/// A fixed radius or one from a luminance threshold.
fn radius_controls(ui: &mut egui::Ui, radius: &mut RadiusMode) {
    let mut threshold_mode = matches!(*radius, RadiusMode::LuminanceThreshold(_));
    ui.checkbox(&mut threshold_mode, "radius from luminance threshold");
    match (radius, threshold_mode) {
        (RadiusMode::LuminanceThreshold(t), true) => {
            ui.add(
                egui::Slider::new(t, 1e-5..=10.0)
                    .logarithmic(true)
                    .text("threshold"),
            );
        }
        (RadiusMode::Fixed(r), false) => {
            ui.add(
                egui::Slider::new(r, 0.01..=100.0)
                    .logarithmic(true)
                    .text("radius (m)"),
            );
        }
        (radius, true) => *radius = RadiusMode::LuminanceThreshold(manylights::DEFAULT_THRESHOLD),
        (radius, false) => *radius = RadiusMode::Fixed(2.0),
    }
}

/// The generated lights' shape (points, spheres, squares) and size.
fn light_shape_controls(ui: &mut egui::Ui, shape: &mut manylights::lights::LightShape) {
    use manylights::lights::LightShape;
    let mut size = match shape.size() {
        0.0 => 0.3,
        size => size,
    };
    let mut name = shape.name();
    egui::ComboBox::from_label("light shape")
        .selected_text(name)
        .show_ui(ui, |ui| {
            for choice in ["point", "sphere", "rect"] {
                ui.selectable_value(&mut name, choice, choice);
            }
        });
    if name != "point" {
        ui.add(
            egui::Slider::new(&mut size, 0.01..=4.0)
                .logarithmic(true)
                .text("light size (m)"),
        );
    }
    *shape = LightShape::new(name, size).unwrap_or(LightShape::Point);
}

/// Light count, radius, colour, spots and animation.
fn lights_section(ui: &mut egui::Ui, settings: &mut FrameSettings, state: &mut UiState) {
    ui.add(
        egui::Slider::new(&mut settings.lights.count, 1..=state.max_lights.max(1))
            .logarithmic(true)
            .text("lights"),
    );
    ui.add(
        egui::Slider::new(&mut settings.lights.intensity, 0.001..=100.0)
            .logarithmic(true)
            .text("intensity"),
    );
    ui.add(egui::Slider::new(&mut settings.lights.saturation, 0.0..=1.0).text("saturation"));
    ui.add(egui::Slider::new(&mut settings.lights.spots.fraction, 0.0..=1.0).text("spot fraction"));
    if settings.lights.spots.fraction > 0.0 {
        spot_cone_controls(ui, &mut settings.lights.spots.cone);
    }
    light_shape_controls(ui, &mut settings.lights.shape);
    ui.checkbox(
        &mut settings.lights.emissive,
        "emissive surfaces are lights",
    );
    if let Some(line) = manylights::describe_scene_lights(
        &state.scene_lights,
        settings.lights.radius,
        settings.pipeline.far_field().is_some(),
    ) {
        ui.label(line);
    }
    radius_controls(ui, &mut settings.lights.radius);
    let asked = settings.lights.radius.radius(settings.lights.intensity);
    match state
        .last_stats
        .as_ref()
        .filter(|_| settings.budget.is_some())
    {
        Some(stats) => {
            let slots = stats
                .far_slots
                .map(|slots| format!(", {slots} far-field slots"))
                .unwrap_or_default();
            let label = ui.label(format!(
                "radius: {:.3} m{slots} (the budget's; asked {asked:.3} m)",
                stats.radius
            ));
            if stats.budget_out_of_reach {
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    "the budget is out of reach: frames are over it with the radius and slots at their least",
                );
            }
            label
        }
        None => ui.label(format!("radius: {asked:.3} m")),
    };
    budget_controls(ui, settings);
    falloff_controls(ui, settings);
    ui.add(egui::Slider::new(&mut state.animation_speed, 0.0..=4.0).text("animation speed"));
    ui.checkbox(&mut state.paused, "paused (Space)");
    ui.add(egui::DragValue::new(&mut settings.lights.seed).prefix("seed "));
}

/// A GPU time per frame to stay within: the renderer shortens the radius (and with a tree
/// far field takes slots) to fit it.
fn budget_controls(ui: &mut egui::Ui, settings: &mut FrameSettings) {
    let mut on = settings.budget.is_some();
    ui.checkbox(
        &mut on,
        "frame-time budget (shortens the radius, takes slots)",
    );
    match (on, &mut settings.budget) {
        (true, Some(ms)) => {
            ui.add(
                egui::Slider::new(ms, 0.5..=100.0)
                    .logarithmic(true)
                    .text("budget (GPU ms)"),
            );
        }
        (true, budget @ None) => *budget = Some(8.0),
        (false, budget) => *budget = None,
    }
}

/// The falloff and, for Forward+/deferred, the far field: what lights add beyond their
/// radius (it completes the windowed falloff to the unbounded inverse-square one), so the
/// two are chosen together.
fn falloff_controls(ui: &mut egui::Ui, settings: &mut FrameSettings) {
    let clustered = settings.pipeline.needs_clusters();
    if clustered {
        let choices = [
            (None, "off"),
            (Some(FarFieldMethod::Tree), "tree"),
            (Some(FarFieldMethod::Stochastic), "stochastic"),
        ];
        let current = settings.pipeline.far_field().map(|far| far.method);
        let mut method = current;
        combo(ui, "far field", &mut method, &choices);
        if method != current {
            let result = match method {
                Some(method) => {
                    settings.set_falloff(Falloff::InverseSquare, Some(FarField::new(method)))
                }
                None => settings.set_falloff(Falloff::WindowedInverseSquare, None),
            };
            if let Err(error) = result {
                log::warn!("far field: {error}");
            }
        }
        if let Some(far) = settings
            .pipeline
            .clustering_mut()
            .and_then(|clustering| clustering.far_field.as_mut())
        {
            ui.add(
                egui::Slider::new(&mut far.tolerance, 0.0..=100.0)
                    .logarithmic(true)
                    .text("far-field tolerance"),
            );
            if far.method == FarFieldMethod::Stochastic {
                ui.add(egui::DragValue::new(&mut far.seed).prefix("far-field seed "));
            } else {
                // The cut's entries per cluster: at many lights they, not the tolerance,
                // bound the error (and each pixel's far-field cost).
                ui.add(
                    egui::Slider::new(&mut far.slots, 8..=manylights::cluster::MAX_FAR_CUT_SLOTS)
                        .logarithmic(true)
                        .text("far-field slots"),
                );
            }
        }
    }
    if settings.pipeline.far_field().is_some() {
        ui.label("falloff: inverse-square (windowed near + far field)");
    } else {
        // Only the falloffs this pipeline can render.
        let falloffs: Vec<(Falloff, &str)> = Falloff::ALL
            .into_iter()
            .filter(|f| settings.pipeline.with_falloff(*f).is_ok())
            .map(|f| (f, f.name()))
            .collect();
        let mut falloff = settings.pipeline.falloff();
        combo(ui, "falloff", &mut falloff, &falloffs);
        if let Ok(pipeline) = settings.pipeline.with_falloff(falloff) {
            settings.pipeline = pipeline;
        }
    }
}

/// A clustered pipeline's light lists: the grid, the assignment, the boxes and the
/// statistics (the far field is chosen with the falloff, in the lights' section).
fn clusters_section(ui: &mut egui::Ui, clustering: &mut ClusteringSettings) {
    let (mut x, mut y) = match clustering.grid.tiles {
        TileSpec::Count { x, y } => (x, y),
        TileSpec::PixelSize(_) => (16, 9),
    };
    ui.horizontal(|ui| {
        ui.add(
            egui::DragValue::new(&mut x)
                .range(1..=256)
                .prefix("tiles x "),
        );
        ui.add(egui::DragValue::new(&mut y).range(1..=256).prefix("y "));
    });
    clustering.grid.tiles = TileSpec::Count { x, y };
    ui.add(egui::Slider::new(&mut clustering.grid.z_slices, 1..=128).text("depth slices"));
    let mut first_far = match clustering.grid.z_scheme {
        ZScheme::LogarithmicWithNearSlice { first_slice_far } => first_slice_far,
        _ => 1.0,
    };
    let mut scheme = std::mem::discriminant(&clustering.grid.z_scheme);
    let log = std::mem::discriminant(&ZScheme::Logarithmic);
    let log_near = std::mem::discriminant(&ZScheme::LogarithmicWithNearSlice {
        first_slice_far: 1.0,
    });
    let linear = std::mem::discriminant(&ZScheme::Linear);
    combo(
        ui,
        "slicing",
        &mut scheme,
        &[
            (log, "logarithmic"),
            (log_near, "log + near slice"),
            (linear, "linear"),
        ],
    );
    if scheme == log_near {
        ui.add(
            egui::Slider::new(&mut first_far, 0.05..=20.0)
                .logarithmic(true)
                .text("first slice far (m)"),
        );
    }
    clustering.grid.z_scheme = if scheme == log {
        ZScheme::Logarithmic
    } else if scheme == linear {
        ZScheme::Linear
    } else {
        ZScheme::LogarithmicWithNearSlice {
            first_slice_far: first_far,
        }
    };
    let mut fitted = clustering.grid.z_range == ZRange::FittedToScene;
    ui.checkbox(&mut fitted, "depth range fitted to the scene");
    clustering.grid.z_range = if fitted {
        ZRange::FittedToScene
    } else {
        ZRange::Camera
    };
    let designs = manylights::cluster::AssignmentDesign::ALL.map(|d| (d, d.name()));
    combo(ui, "light assignment", &mut clustering.assignment, &designs);
    let boxes = manylights::cluster::ClusterBoxes::ALL.map(|b| (b, b.name()));
    combo(ui, "cluster boxes", &mut clustering.boxes, &boxes);
    ui.checkbox(&mut clustering.stats, "lights-per-cluster statistics");
}

/// Exposure, tonemap and the debug views.
fn image_section(ui: &mut egui::Ui, settings: &mut FrameSettings) {
    exposure_controls(ui, &mut settings.post.exposure);
    combo(
        ui,
        "tonemap",
        &mut settings.post.tonemap,
        &[
            (Tonemap::None, "none (clamp)"),
            (Tonemap::Reinhard, "Reinhard"),
            (Tonemap::AcesFit, "ACES fit"),
        ],
    );
    let current = settings.clone();
    combo_planned(
        ui,
        "anti-aliasing",
        &mut settings.post.anti_aliasing,
        &[
            (manylights::AntiAliasing::Off, "off"),
            (manylights::AntiAliasing::Taa, "TAA (temporal)"),
        ],
        |choice| refused_with(&current, |s| s.post.anti_aliasing = choice),
    );
    ui.add(egui::Slider::new(&mut settings.post.bloom, 0.0..=0.3).text("bloom"));
    // The views this pipeline has, by their one name.
    let views: Vec<String> = match &settings.pipeline {
        PipelineSettings::Naive(_) => Vec::new(),
        PipelineSettings::ForwardPlus(_) => manylights::ClusterView::ALL
            .iter()
            .map(|v| v.to_string())
            .collect(),
        PipelineSettings::Deferred(_) => {
            DeferredView::all().iter().map(|v| v.to_string()).collect()
        }
    };
    let current = settings.pipeline.debug_view_name();
    egui::ComboBox::from_label("debug view")
        .selected_text(current.as_deref().unwrap_or("none"))
        .show_ui(ui, |ui| {
            for name in std::iter::once("none").chain(views.iter().map(String::as_str)) {
                let selected = current.as_deref().unwrap_or("none") == name;
                if ui.selectable_label(selected, name).clicked()
                    && let Ok(pipeline) = settings.pipeline.with_debug_view_named(name)
                {
                    settings.pipeline = pipeline;
                }
            }
        });
    if let Some(manylights::ClusterView::Heatmap { mut max_lights }) =
        settings.pipeline.cluster_view()
    {
        ui.add(
            egui::Slider::new(&mut max_lights, 1.0..=4096.0)
                .logarithmic(true)
                .text("heatmap white at"),
        );
        settings.pipeline = settings.pipeline.with_heatmap_max(max_lights);
    }
}

/// Automatic exposure (with compensation) or a fixed one.
fn exposure_controls(ui: &mut egui::Ui, exposure: &mut Exposure) {
    let mut automatic = matches!(exposure, Exposure::Auto(_));
    ui.checkbox(&mut automatic, "automatic exposure (median to mid-grey)");
    *exposure = match (automatic, *exposure) {
        (true, Exposure::Auto(mut auto)) => {
            ui.add(
                egui::Slider::new(&mut auto.compensation_ev, -6.0..=6.0).text("compensation (EV)"),
            );
            Exposure::Auto(auto)
        }
        (true, Exposure::Manual(_)) => Exposure::Auto(AutoExposure::CONVERGE_NOW),
        (false, Exposure::Manual(mut value)) => {
            ui.add(
                egui::Slider::new(&mut value, 0.001..=1000.0)
                    .logarithmic(true)
                    .text("exposure"),
            );
            Exposure::Manual(value)
        }
        (false, Exposure::Auto(_)) => Exposure::Manual(1.0),
    };
}

pub fn stats_panel(ui: &mut egui::Ui, state: &UiState) {
    ui.heading("Statistics");
    let clock = &state.frame_clock;
    ui.label(format!(
        "{:.1} FPS, {:.2} ms a frame (last {} frames)",
        clock.fps(),
        clock.frame_ms(),
        clock.frames()
    ));
    ui.label(&state.adapter);
    if let Some((count, reason)) = &state.device_recoveries {
        ui.colored_label(
            egui::Color32::YELLOW,
            format!("device recreated {count}x (last: {reason})"),
        );
    }
    if let Some(stats) = &state.last_stats {
        ui.label(format!("{} lights", stats.light_count));
        match &stats.timings {
            // Timestamps arrive frames later (in the browser, once the page has returned
            // control to it).
            GpuTimings::Measured(passes) if passes.is_empty() => {
                ui.label("GPU times: waiting for the first timed frame");
            }
            GpuTimings::Measured(passes) => {
                egui::Grid::new("gpu passes").show(ui, |ui| {
                    for pass in passes {
                        ui.label(pass.name.as_str());
                        ui.label(format!("{:.3} ms", pass.milliseconds));
                        ui.end_row();
                    }
                    ui.strong("GPU total");
                    ui.strong(format!("{:.3} ms", stats.timings.total().unwrap_or(0.0)));
                    ui.end_row();
                });
                if state.shadows.traced() {
                    // The rays are traced in the shading pass's light loop, not a pass of
                    // their own: its time includes them (switch shadows off to compare).
                    ui.label("shadow rays: traced in the shading pass (included above)");
                }
            }
            GpuTimings::Unsupported => {
                ui.label("GPU timings unavailable (no timestamp queries)");
            }
        }
        if let Some(cluster) = &stats.cluster_stats {
            ui.label(format!(
                "lights per cluster: mean {:.2}, max {}",
                cluster.mean_lights, cluster.max_lights
            ));
            ui.label(format!("list entries: {}", cluster.total_entries));
        }
    }
    if let Some(grown) = state.list_capacity_grown_to {
        ui.label(format!(
            "light lists outgrew their buffer once: that frame shaded the cut-short clusters from all lights (nothing dropped); grown to {grown} entries"
        ));
    }
    history_plot(ui, &state.gpu_history);
}

/// GPU total per frame over the last frames, as a line.
fn history_plot(ui: &mut egui::Ui, history: &VecDeque<f64>) {
    let (rect, _) = ui.allocate_exact_size(
        egui::vec2(ui.available_width().max(120.0), 70.0),
        egui::Sense::hover(),
    );
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, egui::Color32::from_gray(24));
    let max = history.iter().copied().fold(0.0f64, f64::max).max(1e-3);
    let points: Vec<egui::Pos2> = history
        .iter()
        .enumerate()
        .map(|(i, ms)| {
            let x = rect.left() + rect.width() * i as f32 / (HISTORY - 1) as f32;
            let y = rect.bottom() - rect.height() * (*ms / max) as f32;
            egui::pos2(x, y)
        })
        .collect();
    painter.add(egui::Shape::line(
        points,
        egui::Stroke::new(1.5, egui::Color32::LIGHT_GREEN),
    ));
    painter.text(
        rect.left_top() + egui::vec2(4.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!("GPU ms (max {max:.2})"),
        egui::FontId::monospace(10.0),
        egui::Color32::GRAY,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_rate_and_frame_time_describe_the_same_frames() {
        let mut clock = FrameClock::default();
        // Fast frames, then one slow frame: both figures move together.
        for _ in 0..30 {
            clock.tick(1.0 / 60.0);
        }
        assert!((clock.fps() - 60.0).abs() < 1e-9);
        clock.tick(0.939);
        assert!((clock.fps() * clock.frame_ms() - 1000.0).abs() < 1e-9);
        // Only the frames of the last second count: the slow frame and the few fast ones
        // that fit beside it.
        assert!(clock.frame_ms() > 100.0, "{}", clock.frame_ms());
        for _ in 0..120 {
            clock.tick(1.0 / 60.0);
        }
        assert!((clock.frame_ms() - 1000.0 / 60.0).abs() < 1e-6);
        assert!((clock.fps() * clock.frame_ms() - 1000.0).abs() < 1e-9);
    }
}
