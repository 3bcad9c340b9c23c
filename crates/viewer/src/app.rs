//! The viewer: a winit 0.30 `ApplicationHandler` that owns the window, the surface, input
//! and the egui UI, and asks the facade's `Renderer` for each frame.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, anyhow};
use manylights::gpu::{AdapterRequest, GpuContext, wgpu};
use manylights::{
    AutoExposure, Exposure, FrameSettings, GBufferChannel, LoadedScene, PipelineKind, Renderer,
};
use winit::application::ApplicationHandler;
use winit::event::{
    DeviceEvent, DeviceId, ElementState, MouseButton, MouseScrollDelta, WindowEvent,
};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use crate::ViewArgs;
use crate::camera_controller::CameraController;
use crate::script::{self, ScriptEffects, ScriptStep};
use crate::ui::{self, HISTORY, UiState};

/// Time step of scripted runs (`--frames`), so they are reproducible.
const SCRIPTED_TIME_STEP: f32 = 1.0 / 60.0;
/// Automatic exposure covers 63% of a change in this many seconds (eyes and cameras
/// adapt over about that; faster looks like flicker when lights move).
const EXPOSURE_TIME_CONSTANT_S: f32 = 0.5;

pub fn run(args: ViewArgs) -> anyhow::Result<()> {
    let event_loop =
        EventLoop::new().context("opening the window system (is a display available?)")?;
    let mut app = App {
        args,
        running: None,
        outcome: Ok(()),
    };
    event_loop
        .run_app(&mut app)
        .context("running the event loop")?;
    app.outcome
}

struct App {
    args: ViewArgs,
    running: Option<Running>,
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
    /// Times the GPU device was lost and recreated.
    device_recoveries: u32,
    /// The last frame whose script steps were applied.
    script_applied_through: Option<u64>,
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

impl App {
    fn start(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<Running> {
        let frame_args = &self.args.frame;
        let scene = LoadedScene::load(&frame_args.scene)
            .with_context(|| format!("loading scene '{}'", frame_args.scene))?;
        let mut settings = manylights_lab::cli::frame_settings(frame_args, &scene)?;
        let attributes = Window::default_attributes()
            .with_title("manylights")
            .with_inner_size(winit::dpi::PhysicalSize::new(
                settings.size.0,
                settings.size.1,
            ));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .context("creating the window")?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance
            .create_surface(window.clone())
            .context("creating the window surface")?;
        let context = GpuContext::for_surface(instance, &surface, &AdapterRequest::from_env())
            .context("creating the GPU context")?;
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
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: if self.args.no_vsync {
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
        settings.size = (config.width, config.height);
        // The stats panel shows lights per cluster: computed on the GPU and read back
        // without stalling (a few microseconds of GPU time).
        settings.cluster_stats = true;
        let blitter = wgpu::util::TextureBlitter::new(&context.device, srgb_view_format);
        let (egui_ctx, egui_state, egui_renderer) = egui_for(&window, &context.device, format);
        let script = match &self.args.script {
            Some(text) => script::parse(text, &settings)?,
            None => Vec::new(),
        };
        let ui = UiState {
            paused: self.args.paused,
            vsync: !self.args.no_vsync,
            animation_speed: 1.0,
            adapter: context.summary.to_string(),
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
            fixed_time_step: self.args.frame.frames.is_some() || self.args.script.is_some(),
            device_recoveries: 0,
            script_applied_through: None,
        })
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        match self.start(event_loop) {
            Ok(running) => {
                running.window.request_redraw();
                self.running = Some(running);
            }
            Err(error) => {
                self.outcome = Err(error);
                event_loop.exit();
            }
        }
    }

    fn device_event(&mut self, _: &ActiveEventLoop, _: DeviceId, event: DeviceEvent) {
        if let (Some(running), DeviceEvent::MouseMotion { delta }) = (&mut self.running, event) {
            running
                .camera
                .mouse_motion(&mut running.settings.camera, delta.0, delta.1);
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
            WindowEvent::DroppedFile(path) => running.load_scene(&path.display().to_string()),
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
            WindowEvent::RedrawRequested => match running.redraw() {
                Ok(()) => running.window.request_redraw(),
                Err(error) => {
                    self.outcome = Err(error);
                    event_loop.exit();
                }
            },
            _ => {}
        }
        // Scripted runs stop after their frames.
        if let (Some(running), Some(limit)) = (&self.running, self.args.frame.frames)
            && running.frame >= limit as u64
        {
            // The frame rate of a scripted run, from the same frames as the panel shows.
            let clock = &running.ui.frame_clock;
            println!(
                "viewer: {} frames; last {} frames: {:.1} FPS, {:.2} ms a frame ({} pipeline, {} lights, {}x{})",
                running.frame,
                clock.frames(),
                clock.fps(),
                clock.frame_ms(),
                running.settings.pipeline.describe(),
                running.settings.light_count,
                running.settings.size.0,
                running.settings.size.1
            );
            if let Some(path) = &self.args.screenshot {
                self.outcome = running.save_screenshot(path);
            }
            event_loop.exit();
        }
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
            self.settings.size = (width, height);
        }
    }

    fn shortcut(&mut self, code: KeyCode) {
        let settings = &mut self.settings;
        match code {
            KeyCode::Digit1 => {
                settings.pipeline = settings.pipeline.switched_to(PipelineKind::Naive)
            }
            KeyCode::Digit2 => {
                settings.pipeline = settings.pipeline.switched_to(PipelineKind::ForwardPlus)
            }
            KeyCode::Digit3 => {
                settings.pipeline = settings.pipeline.switched_to(PipelineKind::Deferred)
            }
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
                if let Ok(pipeline) = settings.pipeline.with_debug_view(next) {
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
                if let Ok(pipeline) = settings.pipeline.with_debug_view(next) {
                    settings.pipeline = pipeline;
                }
            }
            KeyCode::Space => self.ui.paused = !self.ui.paused,
            KeyCode::KeyP => println!("--camera {}", settings.camera.to_argument()),
            KeyCode::F1 => self.ui.show_help = !self.ui.show_help,
            KeyCode::F12 => self.ui.screenshot_requested = true,
            _ => {}
        }
    }

    /// Loads a scene; on failure the error is shown and the current scene stays.
    fn load_scene(&mut self, spec: &str) {
        let loaded = LoadedScene::load(spec)
            .map_err(|e| e.to_string())
            .and_then(|scene| {
                let camera = scene.default_camera();
                let name = scene.name.clone();
                let presets = scene.presets.iter().map(|(n, _)| n.clone()).collect();
                let lights = scene.scene.lights.clone();
                self.renderer.load_scene(scene).map_err(|e| e.to_string())?;
                Ok((camera, name, presets, lights))
            });
        match loaded {
            Ok((camera, name, presets, lights)) => {
                self.settings.camera = camera;
                self.ui.scene_name = name;
                self.ui.scene_lights = lights;
                self.ui.presets = presets;
                self.ui.gbuffer_bytes_per_pixel = gbuffer_bytes_per_pixel(&self.renderer);
                self.ui.load_error = None;
            }
            Err(error) => self.ui.load_error = Some(format!("could not load {spec}: {error}")),
        }
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
        let image = self
            .renderer
            .read_output()
            .context("reading the frame back")?;
        image
            .save(path)
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
        Ok(())
    }

    fn screenshot_name(&self) -> PathBuf {
        let s = &self.settings;
        PathBuf::from(format!(
            "manylights-{}-{:?}-{}lights-{}x{}-t{:.2}.png",
            self.ui.scene_name,
            s.pipeline.describe(),
            s.light_count,
            s.size.0,
            s.size.1,
            s.time
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
        self.advance(dt)?;
        if let Some(reason) = self.render_scene() {
            return self.recover_device(&reason);
        }
        if self.frame > 0 {
            self.ui.frame_clock.tick(f64::from(dt));
        }
        if std::mem::take(&mut self.ui.screenshot_requested) {
            let path = self.screenshot_name();
            if let Err(error) = self.save_screenshot(&path) {
                self.ui.error = Some(format!("{error:#}"));
            }
        }
        let output = self.run_ui();
        if self.present(output)? {
            self.frame += 1;
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
            self.settings.time += step * self.ui.animation_speed;
        }
        self.camera.update(&mut self.settings.camera, dt.min(0.1));
        // Automatic exposure adapts smoothly when a person watches; scripted runs converge
        // every frame, so each of their frames depends on that frame alone and a
        // screenshot equals `manylights render` with the same settings.
        if let Exposure::Auto(auto) = &mut self.settings.exposure {
            *auto = if self.fixed_time_step {
                AutoExposure {
                    compensation_ev: auto.compensation_ev,
                    ..AutoExposure::CONVERGE_NOW
                }
            } else {
                AutoExposure::adapting(auto.compensation_ev, step, EXPOSURE_TIME_CONSTANT_S)
            };
        }
        Ok(())
    }

    /// Renders the scene and keeps its statistics for the UI; the reason, if the device
    /// was lost.
    fn render_scene(&mut self) -> Option<String> {
        // Render the frame (errors in settings are shown, not fatal).
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
        let (settings, ui_state) = (&mut self.settings, &mut self.ui);
        let mut output = self.egui_ctx.run_ui(input, |root| {
            egui::Panel::left("settings")
                .resizable(true)
                .show(root, |ui| {
                    egui::ScrollArea::vertical()
                        .show(ui, |ui| ui::settings_panel(ui, settings, ui_state));
                });
            egui::Panel::right("stats").show(root, |ui| ui::stats_panel(ui, ui_state));
            if ui_state.show_help {
                egui::Window::new("Help").show(root.ctx(), |ui| ui.monospace(ui::HELP));
            }
        });
        self.egui_state
            .handle_platform_output(&self.window, std::mem::take(&mut output.platform_output));
        if let Some(spec) = self.ui.load_requested.take() {
            self.load_scene(&spec);
        }
        if let Some(preset) = self.ui.preset_requested.take()
            && let Some(camera) = self.renderer.scene().preset(&preset)
        {
            self.settings.camera = camera;
        }
        output
    }

    /// Draws the rendered image and the UI into the window; false when nothing was shown
    /// (a surface to reconfigure, or a device recovered instead).
    fn present(&mut self, mut output: egui::FullOutput) -> anyhow::Result<bool> {
        // egui's texture changes apply whether or not this frame presents.
        let context = self.renderer.context();
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
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: output.pixels_per_point,
        };
        let paint_jobs = self
            .egui_ctx
            .tessellate(output.shapes, output.pixels_per_point);
        let mut encoder = context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("present"),
            });
        if let Some(output_view) = self.renderer.output_view() {
            self.blitter
                .copy(&context.device, &mut encoder, output_view, &srgb_target);
        }
        let extra = self.egui_renderer.update_buffers(
            &context.device,
            &context.queue,
            &mut encoder,
            &paint_jobs,
            &screen,
        );
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target,
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
        }
        context
            .queue
            .submit(extra.into_iter().chain([encoder.finish()]));
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
}

/// Bytes per pixel of each G-buffer layout for the renderer's scene (for the UI).
fn gbuffer_bytes_per_pixel(renderer: &Renderer) -> Vec<u32> {
    manylights::GBufferLayout::ALL
        .iter()
        .map(|layout| renderer.gbuffer_bytes_per_pixel(*layout))
        .collect()
}
