//! The viewer: a winit 0.30 `ApplicationHandler` that owns the window, the surface, input
//! and the egui UI, and asks the facade's `Renderer` for each frame.

use std::path::PathBuf;
use std::sync::Arc;

use web_time::Instant;

use anyhow::{Context as _, anyhow};
use manylights::gpu::{AdapterRequest, GpuContext, wgpu};
use manylights::{
    AutoExposure, Exposure, FrameSettings, GBufferChannel, LoadedScene, PipelineKind, Renderer,
};
use winit::application::ApplicationHandler;
use winit::event::{
    DeviceEvent, DeviceId, ElementState, MouseButton, MouseScrollDelta, WindowEvent,
};
use winit::event_loop::{ActiveEventLoop, EventLoopProxy};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use crate::ViewArgs;
use crate::camera_controller::CameraController;
use crate::measure::{self, MeasurePanel};
use crate::platform;
use crate::script::{self, ScriptEffects, ScriptStep};
use crate::ui::{self, HISTORY, UiState};

/// Time step of scripted runs (`--frames`), so they are reproducible.
const SCRIPTED_TIME_STEP: f32 = 1.0 / 60.0;

/// What the event loop is told from outside a window event: the end of the asynchronous
/// start-up and of a scene loaded from the UI (natively both finish at once; in the
/// browser they arrive after fetches and device creation).
pub enum AppEvent {
    Started(Box<anyhow::Result<Started>>),
    /// A scene loaded for request `request` ([`SceneRequest`]), named `spec`.
    SceneLoaded {
        request: SceneRequest,
        spec: String,
        loaded: Box<anyhow::Result<LoadedScene>>,
    },
    /// The page asked the measure panel to run this matrix (on the scene shown).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    Measure(Box<manylights_lab::lab::BenchMatrix>),
}

/// Which scene load a result answers: the UI's requests are numbered and only the latest
/// one's result is shown (an earlier, slower fetch must not replace a later choice); a
/// scene the page hands over (files a person opened) always is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneRequest {
    Numbered(u64),
    FromPage,
}

/// The GPU (an adapter that can present to the window) and the scene, made before the
/// first frame.
pub struct Started {
    surface: wgpu::Surface<'static>,
    context: GpuContext,
    scene: LoadedScene,
}

pub struct App {
    args: ViewArgs,
    running: Option<Running>,
    /// The window while the GPU and scene are being made.
    starting: Option<Arc<Window>>,
    /// The number of the latest scene the UI asked for.
    latest_scene_request: u64,
    proxy: EventLoopProxy<AppEvent>,
    /// Why the viewer stopped, if it was an error.
    outcome: anyhow::Result<()>,
}

struct Running {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    renderer: Renderer,
    settings: FrameSettings,
    blitter: wgpu::util::TextureBlitter,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    camera: CameraController,
    ui: UiState,
    script: Vec<ScriptStep>,
    frame: u64,
    last_frame: Instant,
    /// Scripted runs (`--frames` or `--script`) advance time by a fixed step.
    fixed_time_step: bool,
    /// Draw only the rendered image (`--hide-ui`).
    hide_ui: bool,
    /// Times the GPU device was lost and everything recreated.
    device_recoveries: u32,
    /// The last frame whose script steps were applied.
    script_applied_through: Option<u64>,
    /// The lab run from the viewer (while it runs, the viewer's own rendering pauses).
    measure: MeasurePanel,
}

/// egui's context, window state and GPU renderer for a device. A new device needs all
/// three anew: egui sends each texture (the font atlas) once, to the device it had.
fn egui_for(
    window: &Window,
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
) -> (egui::Context, egui_winit::State, egui_wgpu::Renderer) {
    let egui_ctx = egui::Context::default();
    let max_texture_side = device.limits().max_texture_dimension_2d as usize;
    let egui_state = egui_winit::State::new(
        egui_ctx.clone(),
        egui::ViewportId::ROOT,
        window,
        Some(window.scale_factor() as f32),
        None,
        Some(max_texture_side),
    );
    let egui_renderer =
        egui_wgpu::Renderer::new(device, format, egui_wgpu::RendererOptions::default());
    (egui_ctx, egui_state, egui_renderer)
}

/// The surface, the GPU and the scene: asynchronous because the browser can wait for
/// none of them (natively the platform blocks on this).
async fn start_gpu_and_scene(
    window: Arc<Window>,
    instance: wgpu::Instance,
    scene_spec: String,
) -> anyhow::Result<Started> {
    let scene = platform::load_scene(&scene_spec)
        .await
        .with_context(|| format!("loading scene '{scene_spec}'"))?;
    let surface = instance
        .create_surface(window)
        .context("creating the window surface")?;
    let context = GpuContext::for_surface_async(instance, &surface, &AdapterRequest::from_env())
        .await
        .context("creating the GPU context")?;
    Ok(Started {
        surface,
        context,
        scene,
    })
}

impl App {
    pub fn new(args: ViewArgs, proxy: EventLoopProxy<AppEvent>) -> Self {
        Self {
            args,
            running: None,
            starting: None,
            latest_scene_request: 0,
            proxy,
            outcome: Ok(()),
        }
    }

    /// Why the viewer stopped, if it was an error (natively; the page writes it on itself,
    /// `platform::stopped`).
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    pub fn into_outcome(self) -> anyhow::Result<()> {
        self.outcome
    }

    /// Opens the window and starts making the GPU and the scene for it.
    fn open(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<()> {
        let attributes = Window::default_attributes().with_title("manylights");
        let attributes = platform::window_attributes(attributes, &self.args)?;
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .context("creating the window")?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        self.starting = Some(window.clone());
        let future = start_gpu_and_scene(window, instance, self.args.frame.scene.clone());
        if let Some(started) = platform::launch(&self.proxy, future, |started| {
            AppEvent::Started(Box::new(started))
        }) {
            self.started(event_loop, started);
        }
        Ok(())
    }

    /// The GPU and scene are ready (or failed): the viewer runs or stops with the error.
    fn started(&mut self, event_loop: &ActiveEventLoop, started: anyhow::Result<Started>) {
        let Some(window) = self.starting.take() else {
            return;
        };
        match started.and_then(|started| Running::new(window, started, &self.args)) {
            Ok(running) => {
                running.window.request_redraw();
                self.running = Some(running);
                platform::started();
            }
            Err(error) => self.stop(event_loop, Err(error)),
        }
    }

    fn stop(&mut self, event_loop: &ActiveEventLoop, outcome: anyhow::Result<()>) {
        platform::stopped(&outcome);
        self.outcome = outcome;
        event_loop.exit();
    }

    /// Loads the scene the UI asked for, without blocking (the page fetches it).
    fn request_scene(&mut self, event_loop: &ActiveEventLoop, spec: String) {
        self.latest_scene_request += 1;
        let request = SceneRequest::Numbered(self.latest_scene_request);
        let future = {
            let spec = spec.clone();
            async move { platform::load_scene(&spec).await }
        };
        let event = {
            let spec = spec.clone();
            move |loaded| AppEvent::SceneLoaded {
                request,
                spec,
                loaded: Box::new(loaded),
            }
        };
        if let Some(loaded) = platform::launch(&self.proxy, future, event) {
            let loaded = Box::new(loaded);
            let event = AppEvent::SceneLoaded {
                request,
                spec,
                loaded,
            };
            self.user_event(event_loop, event);
        }
    }
}

impl Running {
    fn new(window: Arc<Window>, started: Started, args: &ViewArgs) -> anyhow::Result<Self> {
        let Started {
            surface,
            context,
            scene,
        } = started;
        let frame_args = &args.frame;
        let mut settings = manylights_lab::cli::frame_settings(frame_args, &scene)?;
        let capabilities = surface.get_capabilities(&context.adapter);
        // egui draws into a non-sRGB (gamma-space) view; the rendered image is blitted
        // through an sRGB view of the same texture, so both come out right.
        let format = capabilities
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb() && f.add_srgb_suffix() != *f)
            .or_else(|| capabilities.formats.first().copied())
            .ok_or_else(|| {
                anyhow!(
                    "the window surface supports no format on {}",
                    context.summary.name
                )
            })?;
        let srgb_view_format = format.add_srgb_suffix();
        let size = window.inner_size();
        let size = if size.width > 0 && size.height > 0 {
            (size.width, size.height)
        } else {
            settings.view.size
        };
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.0,
            height: size.1,
            present_mode: if args.no_vsync {
                wgpu::PresentMode::AutoNoVsync
            } else {
                wgpu::PresentMode::AutoVsync
            },
            desired_maximum_frame_latency: 2,
            alpha_mode: capabilities
                .alpha_modes
                .first()
                .copied()
                .unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: if srgb_view_format != format {
                vec![srgb_view_format]
            } else {
                vec![]
            },
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&context.device, &config);
        settings.view.size = (config.width, config.height);
        // The stats panel shows lights per cluster: computed on the GPU and read back
        // without stalling (a few microseconds of GPU time).
        let false_positives = settings
            .pipeline
            .clustering()
            .is_some_and(|clustering| clustering.false_positives);
        settings.pipeline.set_list_statistics(true, false_positives);
        let blitter = wgpu::util::TextureBlitter::new(&context.device, srgb_view_format);
        let (egui_ctx, egui_state, egui_renderer) = egui_for(&window, &context.device, format);
        let script = match &args.script {
            Some(text) => script::parse(text, &settings)?,
            None => Vec::new(),
        };
        let ui = UiState {
            paused: args.paused,
            vsync: !args.no_vsync,
            animation_speed: 1.0,
            adapter: context.summary.to_string(),
            max_lights: max_lights(&context),
            scene_name: scene.name.clone(),
            scene_lights: scene.scene.lights.clone(),
            presets: scene.presets.iter().map(|(n, _)| n.clone()).collect(),
            scene_path: frame_args.scene.clone(),
            ..UiState::default()
        };
        let camera_speed = (scene.scene.bounds().size().length() * 0.05).clamp(0.5, 50.0);
        let renderer = Renderer::new(context, scene).context("preparing the renderer")?;
        let mut ui = ui;
        ui.gbuffer_bytes_per_pixel = gbuffer_bytes_per_pixel(&renderer);
        Ok(Running {
            window,
            surface,
            config,
            renderer,
            settings,
            blitter,
            egui_ctx,
            egui_state,
            egui_renderer,
            camera: CameraController::new(camera_speed),
            ui,
            script,
            frame: 0,
            last_frame: Instant::now(),
            fixed_time_step: frame_args.frames.is_some() || args.script.is_some(),
            hide_ui: args.hide_ui,
            device_recoveries: 0,
            script_applied_through: None,
            measure: MeasurePanel::default(),
        })
    }
}

impl ApplicationHandler<AppEvent> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() || self.starting.is_some() {
            return;
        }
        if let Err(error) = self.open(event_loop) {
            self.stop(event_loop, Err(error));
        }
    }

    fn user_event(&mut self, event_loop: &ActiveEventLoop, event: AppEvent) {
        match event {
            AppEvent::Started(started) => self.started(event_loop, *started),
            AppEvent::SceneLoaded {
                request,
                spec,
                loaded,
            } => {
                let latest = SceneRequest::Numbered(self.latest_scene_request);
                if request != latest && request != SceneRequest::FromPage {
                    log::info!("{spec} loaded after a later scene was asked for: not shown");
                    return;
                }
                match &mut self.running {
                    Some(running) => running.scene_loaded(&spec, *loaded),
                    None => log::warn!("{spec} loaded before the viewer started: not shown"),
                }
            }
            AppEvent::Measure(matrix) => match &mut self.running {
                Some(running) => running.start_measure(*matrix),
                None => {
                    platform::measure_ended(Err("the viewer has not started yet"));
                }
            },
        }
    }

    fn device_event(&mut self, _: &ActiveEventLoop, _: DeviceId, event: DeviceEvent) {
        if let (Some(running), DeviceEvent::MouseMotion { delta }) = (&mut self.running, event) {
            running
                .camera
                .mouse_motion(&mut running.settings.view.camera, delta.0, delta.1);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(running) = &mut self.running else {
            return;
        };
        let consumed = running
            .egui_state
            .on_window_event(&running.window, &event)
            .consumed;
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => running.resize(size.width, size.height),
            WindowEvent::DroppedFile(path) => {
                running.ui.load_requested = Some(path.display().to_string())
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Right,
                ..
            } if !consumed || state == ElementState::Released => {
                running.camera.set_looking(state == ElementState::Pressed);
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                running.camera.scroll(notches);
            }
            WindowEvent::KeyboardInput { event, .. } if !consumed => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    let pressed = event.state == ElementState::Pressed;
                    if !running.camera.key(code, pressed) && pressed && !event.repeat {
                        running.shortcut(code);
                    }
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(error) = running.redraw() {
                    self.stop(event_loop, Err(error));
                    return;
                }
                let done =
                    (self.args.frame.frames).is_some_and(|limit| running.frame >= u64::from(limit));
                if !done {
                    running.window.request_redraw();
                }
            }
            _ => {}
        }
        if let Some(spec) = self
            .running
            .as_mut()
            .and_then(|running| running.ui.load_requested.take())
        {
            self.request_scene(event_loop, spec);
        }
        // Scripted runs stop after their frames.
        if self.frames_done() {
            let outcome = match &self.running {
                Some(running) => platform::frames_done(&running.summary(), &running.window, || {
                    match &self.args.screenshot {
                        Some(path) => running.save_screenshot(path),
                        None => Ok(()),
                    }
                }),
                None => Ok(()),
            };
            self.stop(event_loop, outcome);
        }
    }
}

impl App {
    /// A scripted run (`--frames N`) has drawn its frames.
    fn frames_done(&self) -> bool {
        matches!((&self.running, self.args.frame.frames),
            (Some(running), Some(limit)) if running.frame >= u64::from(limit))
    }
}

impl Running {
    fn resize(&mut self, width: u32, height: u32) {
        // A minimised (0x0) window keeps the old configuration; frames are skipped.
        if width > 0 && height > 0 {
            self.config.width = width;
            self.config.height = height;
            self.surface
                .configure(&self.renderer.context().device, &self.config);
            self.settings.view.size = (width, height);
        }
    }

    fn shortcut(&mut self, code: KeyCode) {
        let settings = &mut self.settings;
        match code {
            KeyCode::Digit1 => ui::switch_pipeline(settings, PipelineKind::Naive),
            KeyCode::Digit2 => ui::switch_pipeline(settings, PipelineKind::ForwardPlus),
            KeyCode::Digit3 => ui::switch_pipeline(settings, PipelineKind::Deferred),
            // H, Z: toggle a cluster view; G: cycle the G-buffer channels. A pipeline without
            // the view keeps what it shows.
            KeyCode::KeyH | KeyCode::KeyZ => {
                let view = if code == KeyCode::KeyH {
                    "heatmap"
                } else {
                    "slices"
                };
                let current = settings.pipeline.debug_view_name();
                let next = if current.as_deref() == Some(view) {
                    "none"
                } else {
                    view
                };
                if let Ok(pipeline) = settings.pipeline.with_debug_view_named(next) {
                    settings.pipeline = pipeline;
                }
            }
            KeyCode::KeyG => {
                let channels = GBufferChannel::ALL.map(|c| c.name());
                let current = settings.pipeline.debug_view_name();
                let next = match channels.iter().position(|c| Some(*c) == current.as_deref()) {
                    Some(i) if i + 1 < channels.len() => channels[i + 1],
                    Some(_) => "none",
                    None => channels[0],
                };
                if let Ok(pipeline) = settings.pipeline.with_debug_view_named(next) {
                    settings.pipeline = pipeline;
                }
            }
            KeyCode::Space => self.ui.paused = !self.ui.paused,
            KeyCode::KeyP => println!("--camera {}", settings.view.camera.to_argument()),
            KeyCode::F1 => self.ui.show_help = !self.ui.show_help,
            KeyCode::F12 => self.ui.screenshot_requested = true,
            _ => {}
        }
    }

    /// A scene the UI asked for has loaded (or failed to: the error is shown and the
    /// current scene stays).
    fn scene_loaded(&mut self, spec: &str, loaded: anyhow::Result<LoadedScene>) {
        let loaded = loaded.map_err(|e| format!("{e:#}")).and_then(|scene| {
            let camera = scene.default_camera();
            let name = scene.name.clone();
            let presets = scene.presets.iter().map(|(n, _)| n.clone()).collect();
            let lights = scene.scene.lights.clone();
            self.renderer.load_scene(scene).map_err(|e| e.to_string())?;
            Ok((camera, name, presets, lights))
        });
        platform::scene_loaded(spec, loaded.as_ref().err());
        match loaded {
            Ok((camera, name, presets, lights)) => {
                self.settings.view.camera = camera;
                self.ui.scene_name = name;
                self.ui.scene_lights = lights;
                self.ui.presets = presets;
                self.ui.gbuffer_bytes_per_pixel = gbuffer_bytes_per_pixel(&self.renderer);
                self.ui.load_error = None;
            }
            Err(error) => self.ui.load_error = Some(format!("could not load {spec}: {error}")),
        }
    }

    /// The line a scripted run ends with: frame rate from the same frames the panel shows.
    fn summary(&self) -> String {
        let clock = &self.ui.frame_clock;
        format!(
            "viewer: {} frames; last {} frames: {:.1} FPS, {:.2} ms a frame ({} pipeline, {} lights, {}x{})",
            self.frame,
            clock.frames(),
            clock.fps(),
            clock.frame_ms(),
            self.settings.pipeline.describe(),
            self.settings.lights.count,
            self.settings.view.size.0,
            self.settings.view.size.1
        )
    }

    /// After a device loss: a new device (the adapter chosen again), the surface
    /// configured for it, and every resource rebuilt; the scene, settings and camera stay.
    /// If no device can be made the error ends the viewer with both reasons.
    fn recover_device(&mut self, reason: &str) -> anyhow::Result<()> {
        log::warn!("{reason}; recreating the device and every resource");
        self.renderer
            .recover_device(Some(&self.surface))
            .with_context(|| format!("{reason}, and no new device and renderer could be made"))?;
        let context = self.renderer.context();
        self.surface.configure(&context.device, &self.config);
        self.blitter =
            wgpu::util::TextureBlitter::new(&context.device, self.config.format.add_srgb_suffix());
        (self.egui_ctx, self.egui_state, self.egui_renderer) =
            egui_for(&self.window, &context.device, self.config.format);
        self.device_recoveries += 1;
        let message = format!(
            "{reason}: recreated the device and every resource ({} time(s))",
            self.device_recoveries
        );
        eprintln!("{message}");
        self.ui.device_recoveries = Some((self.device_recoveries, reason.to_string()));
        self.ui.adapter = self.renderer.context().summary.to_string();
        Ok(())
    }

    fn save_screenshot(&self, path: &std::path::Path) -> anyhow::Result<()> {
        platform::save_screenshot(&self.renderer, &self.window, path)
    }

    fn screenshot_name(&self) -> PathBuf {
        let s = &self.settings;
        PathBuf::from(format!(
            "manylights-{}-{:?}-{}lights-{}x{}-t{:.2}.png",
            self.ui.scene_name,
            s.pipeline.describe(),
            s.lights.count,
            s.view.size.0,
            s.view.size.1,
            s.lights.time
        ))
    }

    fn redraw(&mut self) -> anyhow::Result<()> {
        let now = Instant::now();
        let dt = now.duration_since(self.last_frame).as_secs_f32();
        self.last_frame = now;
        let size = self.window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(());
        }
        if self.measure.running() {
            // The lab's run has the GPU: the last frame stays on screen under the panels.
            self.advance_measure();
        } else {
            self.advance(dt)?;
            if let Some(reason) = self.render_scene() {
                return self.recover_device(&reason);
            }
        }
        if self.frame > 0 {
            self.ui.frame_clock.tick(f64::from(dt));
        }
        // A screenshot is the image without the UI. The page reads it from the canvas, so
        // that frame draws no panels; natively it is read from the renderer's output.
        let screenshot = self.ui.screenshot_requested;
        let output = if self.hide_ui || (screenshot && platform::SCREENSHOT_FROM_WINDOW) {
            // Unread input would pile up in egui's state.
            let _ = self.egui_state.take_egui_input(&self.window);
            None
        } else {
            Some(self.run_ui())
        };
        let presented = self.present(output)?;
        if presented {
            self.frame += 1;
        }
        // A frame that was not presented is retried with the next one.
        if screenshot && presented {
            self.ui.screenshot_requested = false;
            let name = self.screenshot_name();
            if let Err(error) = platform::save_screenshot(&self.renderer, &self.window, &name) {
                self.ui.error = Some(format!("{error:#}"));
            }
        }
        Ok(())
    }

    /// This frame's script steps, then time, camera and exposure moved on by `dt` seconds.
    fn advance(&mut self, dt: f32) -> anyhow::Result<()> {
        // Script steps for this frame.
        let mut effects = ScriptEffects {
            paused: self.ui.paused,
            lose_device: false,
        };
        // Once per frame number: a frame redrawn after a device recovery does not repeat
        // its steps.
        if self
            .script_applied_through
            .is_none_or(|frame| frame < self.frame)
        {
            for step in self.script.iter().filter(|s| s.frame == self.frame) {
                script::apply(step, &mut self.settings, &mut effects)?;
            }
            self.script_applied_through = Some(self.frame);
        }
        self.ui.paused = effects.paused;
        if effects.lose_device {
            self.renderer.context().device.destroy();
        }
        let step = if self.fixed_time_step {
            SCRIPTED_TIME_STEP
        } else {
            dt
        };
        if !self.ui.paused {
            self.settings.lights.time += step * self.ui.animation_speed;
        }
        self.camera
            .update(&mut self.settings.view.camera, dt.min(0.1));
        // Automatic exposure adapts smoothly when a person watches; scripted runs converge
        // every frame, so each of their frames depends on that frame alone and a
        // screenshot equals `manylights render` with the same settings.
        if let Exposure::Auto(auto) = &mut self.settings.post.exposure {
            *auto = if self.fixed_time_step {
                AutoExposure {
                    compensation_ev: auto.compensation_ev,
                    ..AutoExposure::CONVERGE_NOW
                }
            } else {
                AutoExposure::adapting(
                    auto.compensation_ev,
                    step,
                    AutoExposure::VIEWER_TIME_CONSTANT_S,
                )
            };
        }
        Ok(())
    }

    /// Renders the scene and keeps its statistics for the UI; the reason, if the device
    /// was lost.
    fn render_scene(&mut self) -> Option<String> {
        // Render the frame (errors in settings are shown, not fatal), each with its own
        // shadow rays' noise.
        self.settings.shadows.seed = self.settings.shadows.seed.wrapping_add(1);
        match self.renderer.render_frame(&self.settings) {
            Ok(stats) => {
                // Timings arrive frames late and only for finished frames: each is plotted
                // once.
                let new_timings = stats.timed_frame.is_some()
                    && stats.timed_frame
                        != self
                            .ui
                            .last_stats
                            .as_ref()
                            .and_then(|last| last.timed_frame);
                if let Some(grown) = stats.list_capacity_grown_to {
                    self.ui.list_capacity_grown_to = Some(grown);
                }
                if new_timings && let Some(total) = stats.timings.total() {
                    self.ui.gpu_history.push_back(total);
                    if self.ui.gpu_history.len() > HISTORY {
                        self.ui.gpu_history.pop_front();
                    }
                }
                self.ui.last_stats = Some(stats);
                self.ui.shadows = self.settings.shadows.mode;
                self.ui.error = None;
            }
            Err(error) if error.is_device_lost() => return Some(error.to_string()),
            Err(error) => self.ui.error = Some(error.to_string()),
        }
        None
    }

    /// Runs the UI (the settings and statistics panels) and acts on what it asked for.
    fn run_ui(&mut self) -> egui::FullOutput {
        let input = self.egui_state.take_egui_input(&self.window);
        let (settings, ui_state, measure_panel) =
            (&mut self.settings, &mut self.ui, &mut self.measure);
        let mut output = self.egui_ctx.run_ui(input, |root| {
            egui::Panel::left("settings")
                .resizable(true)
                .show(root, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        ui::settings_panel(ui, settings, ui_state);
                        egui::CollapsingHeader::new("Measure")
                            .default_open(false)
                            .show(ui, |ui| measure::measure_section(ui, measure_panel));
                    });
                });
            egui::Panel::right("stats").show(root, |ui| ui::stats_panel(ui, ui_state));
            if ui_state.show_help {
                egui::Window::new("Help").show(root.ctx(), |ui| ui.monospace(ui::HELP));
            }
            measure::results_window(root.ctx(), measure_panel);
        });
        self.egui_state
            .handle_platform_output(&self.window, std::mem::take(&mut output.platform_output));
        if let Some(preset) = self.ui.preset_requested.take()
            && let Some(camera) = self.renderer.scene().preset(&preset)
        {
            self.settings.view.camera = camera;
        }
        if std::mem::take(&mut self.measure.start_requested) {
            match self.measure.setup.matrix(self.settings.view.size) {
                Ok(matrix) => self.start_measure(matrix),
                Err(error) => self.measure.error = Some(error),
            }
        }
        output
    }

    /// Starts the lab on `matrix` with the scene shown, on a device of its own.
    fn start_measure(&mut self, matrix: manylights_lab::lab::BenchMatrix) {
        if self.measure.running() {
            platform::measure_ended(Err("a measurement is already running"));
            return;
        }
        let context = self.renderer.context();
        let job = manylights_lab::lab::LabJob::start(
            context.instance.clone(),
            context.request().clone(),
            self.renderer.scene().clone(),
            self.ui.scene_name.clone(),
            matrix,
        );
        log::info!("measuring {} configurations", job.progress().total);
        self.measure.job = Some(job);
        self.measure.error = None;
        platform::measure_started();
    }

    /// Runs the lab a little further; once it ended, its report is kept and handed to the
    /// platform (written to a folder natively, shown and offered for download in the page).
    fn advance_measure(&mut self) {
        match self.measure.advance() {
            None => {}
            Some(Ok(report)) => {
                let saved = platform::measure_ended(Ok(&report));
                self.measure.finished = Some((report, saved));
                self.measure.show_results = true;
            }
            Some(Err(error)) => {
                let error = format!("the measurement failed: {error:#}");
                platform::measure_ended(Err(&error));
                self.measure.error = Some(error);
            }
        }
    }

    /// Draws the rendered image and the UI into the window; false when nothing was shown
    /// (a surface to reconfigure, or a device recovered instead).
    fn present(&mut self, mut output: Option<egui::FullOutput>) -> anyhow::Result<bool> {
        // egui's texture changes apply whether or not this frame presents.
        let context = self.renderer.context();
        if let Some(output) = &mut output {
            for (id, deltas) in &output.textures_delta.set {
                for delta in deltas {
                    self.egui_renderer
                        .update_texture(&context.device, &context.queue, *id, delta);
                }
            }
            for id in &output.textures_delta.free {
                self.egui_renderer.free_texture(id);
            }
            output.textures_delta.clear();
        }

        // Vsync toggled in the UI: reconfigure the surface.
        let present_mode = if self.ui.vsync {
            wgpu::PresentMode::AutoVsync
        } else {
            wgpu::PresentMode::AutoNoVsync
        };
        if present_mode != self.config.present_mode {
            self.config.present_mode = present_mode;
            self.surface
                .configure(&self.renderer.context().device, &self.config);
        }

        // Present: the rendered image, then the UI on top.
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame)
            | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => frame,
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface
                    .configure(&self.renderer.context().device, &self.config);
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Validation
                if self.renderer.context().device_lost().is_some() =>
            {
                let reason = self
                    .renderer
                    .context()
                    .check_device()
                    .err()
                    .map(|e| e.to_string());
                self.recover_device(&reason.unwrap_or_default())?;
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                let errors = self.renderer.context().take_uncaptured_errors().join("; ");
                return Err(anyhow!("the window surface failed validation: {errors}"));
            }
        };
        let target = frame
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let srgb_target = frame.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(self.config.format.add_srgb_suffix()),
            ..Default::default()
        });
        let mut encoder = context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("present"),
            });
        if let Some(output_view) = self.renderer.output_view() {
            self.blitter
                .copy(&context.device, &mut encoder, output_view, &srgb_target);
        }
        let ui_buffers = match output {
            Some(output) => self.draw_ui(&mut encoder, &target, output),
            None => Vec::new(),
        };
        let context = self.renderer.context();
        context
            .queue
            .submit(ui_buffers.into_iter().chain([encoder.finish()]));
        context.queue.present(frame);
        // A device lost during the frame (wgpu reports it asynchronously) is recovered
        // before the next one.
        if let Err(error) = context.check_device() {
            self.recover_device(&error.to_string())?;
            return Ok(false);
        }
        let uncaptured = context.take_uncaptured_errors();
        if !uncaptured.is_empty() {
            self.ui.error = Some(uncaptured.join("; "));
        }
        Ok(true)
    }

    /// Records egui's panels on top of the image in `target`; returns the command buffers
    /// egui's own uploads need (submitted first).
    fn draw_ui(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        output: egui::FullOutput,
    ) -> Vec<wgpu::CommandBuffer> {
        let context = self.renderer.context();
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: output.pixels_per_point,
        };
        let paint_jobs = self
            .egui_ctx
            .tessellate(output.shapes, output.pixels_per_point);
        let uploads = self.egui_renderer.update_buffers(
            &context.device,
            &context.queue,
            encoder,
            &paint_jobs,
            &screen,
        );
        let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("egui"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.egui_renderer
            .render(&mut pass.forget_lifetime(), &paint_jobs, &screen);
        uploads
    }
}

/// The most lights the device holds: its largest storage binding and buffer over a light's
/// size, and the per-light passes' one-dimensional dispatches (64 lights a workgroup, at
/// most `max_compute_workgroups_per_dimension` workgroups).
fn max_lights(context: &GpuContext) -> u32 {
    let limits = context.device.limits();
    let light_bytes = std::mem::size_of::<manylights::lights::Light>() as u64;
    let by_memory = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size)
        / light_bytes;
    let by_dispatch = u64::from(limits.max_compute_workgroups_per_dimension) * 64;
    u32::try_from(by_memory.min(by_dispatch)).unwrap_or(u32::MAX)
}

/// Bytes per pixel of each G-buffer layout for the renderer's scene (for the UI).
fn gbuffer_bytes_per_pixel(renderer: &Renderer) -> Vec<u32> {
    manylights::GBufferLayout::ALL
        .iter()
        .map(|layout| renderer.gbuffer_bytes_per_pixel(*layout))
        .collect()
}
