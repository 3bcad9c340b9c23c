//! Long runs without leaks: `manylights soak` renders many frames headless, changing the
//! pipeline, G-buffer layout, lighting path, debug view, depth convention, cluster grid,
//! light count, light source (generated or fixed) and frame size every `phase_frames`
//! frames, and samples resident memory and the GPU allocator after every phase.
//!
//! The schedule repeats every [`SCHEDULE_PERIOD`] phases, so a phase and the same phase a
//! cycle later render with identical settings: their GPU allocations must be identical (any
//! difference is a leak or a cache that never stops growing), and the peak resident memory
//! of the last cycle may exceed the second cycle's by at most `max_rss_growth_mib` (the
//! first cycle warms allocator and driver caches up).

use web_time::Instant;

use glam::Vec3;
use manylights::cluster::TileSpec;
use manylights::lights::{Falloff, Light, LightSet};
use serde::Serialize;

use manylights::{
    ClusterView, DeferredSettings, DeferredView, ForwardPlusSettings, FrameSettings,
    GBufferChannel, GBufferLayout, LightingPath, LoadedScene, NaiveSettings, PipelineSettings,
    Renderer,
};

/// The settings variants one phase picks from.
const VARIANTS: usize = 12;
/// Light counts, cycled independently of the variants (coprime with [`VARIANTS`]).
const LIGHT_COUNTS: [u32; 5] = [0, 1, 64, 700, 2000];
/// Phases after which the schedule repeats: lcm(12, 5).
pub const SCHEDULE_PERIOD: u64 = 60;

/// What to run.
#[derive(Debug, Clone)]
pub struct SoakConfig {
    pub scene: String,
    pub frames: u64,
    /// Frames between settings changes.
    pub phase_frames: u64,
    /// The frame size of even light phases; odd ones add 8 pixels to each side, so
    /// targets are recreated too.
    pub size: (u32, u32),
    /// Growth of the peak resident memory allowed from the second cycle to the last.
    pub max_rss_growth_mib: f64,
    /// Live bytes on the Rust heap, where the program counts them (`stats_alloc` as the
    /// global allocator in the `manylights` binary and the soak test). Unlike resident
    /// memory it excludes the driver's own C allocations, so it isolates leaks in
    /// manylights, wgpu and naga.
    pub heap_bytes: Option<fn() -> u64>,
}

impl Default for SoakConfig {
    fn default() -> Self {
        Self {
            scene: "cornell".into(),
            frames: 100_000,
            phase_frames: 250,
            size: (32, 24),
            max_rss_growth_mib: 16.0,
            heap_bytes: None,
        }
    }
}

/// Memory after one phase.
#[derive(Debug, Clone, Serialize)]
pub struct SoakSample {
    pub phase: u64,
    pub frames_done: u64,
    pub seconds: f64,
    pub settings: String,
    /// Resident set size (Linux `/proc/self/statm`); `None` elsewhere.
    pub rss_bytes: Option<u64>,
    /// Live Rust heap bytes ([`SoakConfig::heap_bytes`]).
    pub heap_bytes: Option<u64>,
    /// wgpu's allocator report (Vulkan, D3D12); `None` where the backend has none.
    pub gpu_allocated_bytes: Option<u64>,
    pub gpu_reserved_bytes: Option<u64>,
    pub gpu_allocations: Option<usize>,
}

/// The outcome: every sample and the verdicts.
#[derive(Debug, Clone, Serialize)]
pub struct SoakReport {
    pub adapter: String,
    pub frames: u64,
    pub phase_frames: u64,
    pub seconds: f64,
    pub samples: Vec<SoakSample>,
    /// Peak resident memory of each complete cycle.
    pub cycle_peak_rss: Vec<u64>,
    /// Last cycle's peak minus the second's (the first warms caches up); needs 3 cycles.
    pub rss_growth_bytes: Option<i64>,
    pub rss_final: Option<u64>,
    /// The same for the live Rust heap, where counted.
    pub cycle_peak_heap: Vec<u64>,
    pub heap_growth_bytes: Option<i64>,
    /// Phases whose GPU allocation differed from the same phase one cycle earlier.
    pub gpu_mismatches: Vec<String>,
    pub max_rss_growth_mib: f64,
    pub passed: bool,
    pub problems: Vec<String>,
}

/// The settings of phase `phase` (see the module docs).
fn phase_settings(base: &FrameSettings, config: &SoakConfig, phase: u64) -> (FrameSettings, bool) {
    let mut settings = base.clone();
    let variant = (phase % VARIANTS as u64) as usize;
    let light_phase = (phase % LIGHT_COUNTS.len() as u64) as usize;
    settings.lights.count = LIGHT_COUNTS[light_phase];
    let grow = if light_phase % 2 == 1 { 8 } else { 0 };
    settings.view.size = (config.size.0 + grow, config.size.1 + grow);
    settings.view.camera.reverse_z = false;
    let naive = |falloff| PipelineSettings::Naive(NaiveSettings { falloff });
    let forward_plus = |depth_prepass, debug_view| {
        PipelineSettings::ForwardPlus(ForwardPlusSettings {
            depth_prepass,
            debug_view,
            ..Default::default()
        })
    };
    let deferred = |layout, lighting, debug_view| {
        PipelineSettings::Deferred(DeferredSettings {
            layout,
            lighting,
            debug_view,
            ..Default::default()
        })
    };
    let mut fixed_lights = false;
    settings.pipeline = match variant {
        0 => naive(Falloff::WindowedInverseSquare),
        1 => forward_plus(true, None),
        2 => forward_plus(false, None),
        3..=6 => {
            let (layout, lighting) = [
                (GBufferLayout::Full, LightingPath::Compute),
                (GBufferLayout::Compact, LightingPath::Tiles),
                (GBufferLayout::Visibility, LightingPath::Fragment),
                (GBufferLayout::Compact, LightingPath::Fragment),
            ][variant - 3];
            deferred(layout, lighting, None)
        }
        7 => forward_plus(true, Some(ClusterView::Heatmap { max_lights: 64.0 })),
        8 => deferred(
            GBufferLayout::Compact,
            LightingPath::Compute,
            Some(DeferredView::GBuffer(GBufferChannel::Albedo)),
        ),
        9 => {
            settings.view.camera.reverse_z = true;
            naive(Falloff::InverseSquare)
        }
        10 => {
            settings.view.camera.reverse_z = true;
            let mut pipeline = forward_plus(true, None);
            if let Some(clustering) = pipeline.clustering_mut() {
                clustering.grid.tiles = TileSpec::Count { x: 8, y: 4 };
                clustering.grid.z_slices = 16;
            }
            pipeline
        }
        _ => {
            fixed_lights = true;
            deferred(GBufferLayout::Packed, LightingPath::Compute, None)
        }
    };
    (settings, fixed_lights)
}

fn describe(settings: &FrameSettings, fixed_lights: bool) -> String {
    format!(
        "{} {} reverse_z={} {} lights{} {}x{}",
        settings.pipeline.describe(),
        settings.pipeline.falloff(),
        settings.view.camera.reverse_z,
        settings.lights.count,
        if fixed_lights { " (fixed)" } else { "" },
        settings.view.size.0,
        settings.view.size.1
    )
}

/// A fixed light set of `count` lights on a ring in the scene's light box.
fn ring_lights(scene: &LoadedScene, count: u32) -> LightSet {
    let center = scene.light_box.center();
    let extent = scene.light_box.size() * 0.4;
    LightSet {
        lights: (0..count)
            .map(|i| {
                let angle = i as f32 / count.max(1) as f32 * std::f32::consts::TAU;
                Light::point(
                    center + Vec3::new(angle.cos() * extent.x, 0.0, angle.sin() * extent.z),
                    2.0,
                    Vec3::new(1.0, 0.9, 0.8),
                    0.3,
                )
            })
            .collect(),
    }
}

/// Live heap bytes from a `stats_alloc` global allocator's counters (a reallocation is
/// already in both totals), for [`SoakConfig::heap_bytes`].
pub fn live_heap_bytes(stats: stats_alloc::Stats) -> u64 {
    stats
        .bytes_allocated
        .saturating_sub(stats.bytes_deallocated) as u64
}

/// Resident set size of this process, from `/proc/self/statm` (Linux).
pub fn resident_bytes() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    // The page size is 4 KiB on every Linux target this runs on (x86_64, aarch64 default).
    Some(pages * 4096)
}

/// Runs the soak; `progress` is called after every phase.
pub fn run(
    config: &SoakConfig,
    mut progress: impl FnMut(&SoakSample),
) -> anyhow::Result<SoakReport> {
    anyhow::ensure!(config.phase_frames > 0, "phase_frames must be at least 1");
    let scene = LoadedScene::load(&config.scene)?;
    let mut base = FrameSettings::for_scene(&scene);
    base.view.size = config.size;
    let ring = |count| ring_lights(&scene, count);
    let fixed_sets: Vec<LightSet> = LIGHT_COUNTS.iter().map(|&n| ring(n)).collect();
    let context = manylights::gpu::GpuContext::new_headless()?;
    let adapter = context.summary.to_string();
    let mut renderer = Renderer::new(context, scene.clone())?;

    let started = Instant::now();
    let mut samples = Vec::new();
    let mut frame = 0u64;
    let mut phase = 0u64;
    while frame < config.frames {
        let (mut settings, fixed_lights) = phase_settings(&base, config, phase);
        if fixed_lights {
            let light_phase = (phase % LIGHT_COUNTS.len() as u64) as usize;
            renderer.set_fixed_lights(&fixed_sets[light_phase])?;
        } else {
            renderer.use_generated_lights();
        }
        let phase_end = (frame + config.phase_frames).min(config.frames);
        while frame < phase_end {
            settings.lights.time = frame as f32 / 60.0;
            renderer.render_frame(&settings).map_err(|e| {
                anyhow::anyhow!("frame {frame} ({}): {e}", describe(&settings, fixed_lights))
            })?;
            frame += 1;
        }
        renderer.context().wait_idle("finishing a soak phase")?;
        let report = renderer.context().device.generate_allocator_report();
        let sample = SoakSample {
            phase,
            frames_done: frame,
            seconds: started.elapsed().as_secs_f64(),
            settings: describe(&settings, fixed_lights),
            rss_bytes: resident_bytes(),
            heap_bytes: config.heap_bytes.map(|live| live()),
            gpu_allocated_bytes: report.as_ref().map(|r| r.total_allocated_bytes),
            gpu_reserved_bytes: report.as_ref().map(|r| r.total_reserved_bytes),
            gpu_allocations: report.as_ref().map(|r| r.allocations.len()),
        };
        progress(&sample);
        samples.push(sample);
        phase += 1;
    }
    Ok(judge(
        config,
        adapter,
        started.elapsed().as_secs_f64(),
        frame,
        samples,
    ))
}

/// Byte difference allowed between GPU allocations at identical settings.
pub const GPU_STAGING_SLACK_BYTES: u64 = 64 * 1024;
/// Growth allowed of the Rust heap's peak from the second cycle to the last.
pub const MAX_HEAP_GROWTH_BYTES: i64 = 1024 * 1024;

/// The peak of `value` in each complete cycle of the schedule.
fn cycle_peaks(samples: &[SoakSample], value: impl Fn(&SoakSample) -> Option<u64>) -> Vec<u64> {
    let period = SCHEDULE_PERIOD as usize;
    samples
        .chunks(period)
        .filter(|cycle| cycle.len() == period)
        .filter_map(|cycle| cycle.iter().filter_map(&value).max())
        .collect()
}

/// Last complete cycle's peak minus the second's (needs three cycles).
fn growth_of_cycle_peaks(
    samples: &[SoakSample],
    value: impl Fn(&SoakSample) -> Option<u64>,
) -> Option<i64> {
    let peaks = cycle_peaks(samples, value);
    match (peaks.get(1), peaks.last()) {
        (Some(second), Some(last)) if peaks.len() > 2 => Some(*last as i64 - *second as i64),
        _ => None,
    }
}

/// Same settings one cycle apart (the first cycle warms caches up) must make the same
/// number of GPU allocations, their bytes within [`GPU_STAGING_SLACK_BYTES`] (wgpu's staging
/// memory for queue writes still in flight varies by a few KiB): the phases where not.
fn gpu_mismatches(samples: &[SoakSample]) -> Vec<String> {
    let period = SCHEDULE_PERIOD as usize;
    let mut mismatches = Vec::new();
    for (later, earlier) in samples
        .iter()
        .skip(2 * period)
        .zip(samples.iter().skip(period))
    {
        let bytes_differ = match (later.gpu_allocated_bytes, earlier.gpu_allocated_bytes) {
            (Some(a), Some(b)) => a.abs_diff(b) > GPU_STAGING_SLACK_BYTES,
            (a, b) => a != b,
        };
        if bytes_differ || later.gpu_allocations != earlier.gpu_allocations {
            mismatches.push(format!(
                "phase {} ({}): {:?} bytes in {:?} allocations, one cycle earlier {:?} in {:?}",
                later.phase,
                later.settings,
                later.gpu_allocated_bytes,
                later.gpu_allocations,
                earlier.gpu_allocated_bytes,
                earlier.gpu_allocations
            ));
        }
    }
    mismatches
}

fn judge(
    config: &SoakConfig,
    adapter: String,
    seconds: f64,
    frames: u64,
    samples: Vec<SoakSample>,
) -> SoakReport {
    let period = SCHEDULE_PERIOD as usize;
    let mut problems = Vec::new();
    if samples.len() < 3 * period {
        problems.push(format!(
            "only {} phases: three cycles ({} phases, {} frames) are needed to compare",
            samples.len(),
            3 * period,
            3 * SCHEDULE_PERIOD * config.phase_frames
        ));
    }
    let gpu_mismatches = gpu_mismatches(&samples);
    if !gpu_mismatches.is_empty() {
        problems.push(format!(
            "GPU allocations differ between cycles in {} phases",
            gpu_mismatches.len()
        ));
    }
    let heap_growth_bytes = growth_of_cycle_peaks(&samples, |s| s.heap_bytes);
    if let Some(growth) = heap_growth_bytes
        && growth > MAX_HEAP_GROWTH_BYTES
    {
        problems.push(format!(
            "the Rust heap's peak grew by {:.1} KiB from the second cycle to the last (limit {} KiB)",
            growth as f64 / 1024.0,
            MAX_HEAP_GROWTH_BYTES / 1024
        ));
    }
    // Resident memory per cycle: its peak (lavapipe's "GPU" memory is host memory, so RSS
    // swings with the settings; the peak of a whole cycle is what must not rise).
    let cycle_peak_rss = cycle_peaks(&samples, |s| s.rss_bytes);
    let rss_growth_bytes = growth_of_cycle_peaks(&samples, |s| s.rss_bytes);
    let cycle_peak_heap = cycle_peaks(&samples, |s| s.heap_bytes);
    if let Some(growth) = rss_growth_bytes {
        let growth_mib = growth as f64 / (1024.0 * 1024.0);
        if growth_mib > config.max_rss_growth_mib {
            problems.push(format!(
                "resident memory peak grew by {growth_mib:.1} MiB from the second cycle to the last (limit {} MiB)",
                config.max_rss_growth_mib
            ));
        }
    }
    SoakReport {
        adapter,
        frames,
        phase_frames: config.phase_frames,
        seconds,
        rss_final: samples.last().and_then(|s| s.rss_bytes),
        samples,
        cycle_peak_rss,
        rss_growth_bytes,
        cycle_peak_heap,
        heap_growth_bytes,
        gpu_mismatches,
        max_rss_growth_mib: config.max_rss_growth_mib,
        passed: problems.is_empty(),
        problems,
    }
}

impl SoakReport {
    /// A few lines for the terminal and for notes.
    pub fn summary(&self) -> String {
        let mib = |b: Option<u64>| {
            b.map(|b| format!("{:.1} MiB", b as f64 / (1024.0 * 1024.0)))
                .unwrap_or_else(|| "n/a".into())
        };
        let gpu: Vec<u64> = self
            .samples
            .iter()
            .filter_map(|s| s.gpu_allocated_bytes)
            .collect();
        let gpu_range = match (gpu.iter().min(), gpu.iter().max()) {
            (Some(lo), Some(hi)) => format!("{} .. {}", mib(Some(*lo)), mib(Some(*hi))),
            _ => "n/a".into(),
        };
        let mut out = format!(
            "soak on {}: {} frames in {} phases of {} frames, {:.0} s ({:.0} frames/s)\n\
             resident memory peak per cycle: {}; growth from the second cycle to the last: {} (limit {} MiB); {} at the end\n\
             Rust heap peak per cycle: {}; growth: {} (limit {} KiB)\n\
             GPU allocations: {gpu_range} across settings; {} phase(s) differ from the same settings one cycle earlier\n",
            self.adapter,
            self.frames,
            self.samples.len(),
            self.phase_frames,
            self.seconds,
            self.frames as f64 / self.seconds.max(1e-9),
            self.cycle_peak_rss
                .iter()
                .map(|&b| format!("{:.1}", b as f64 / (1024.0 * 1024.0)))
                .collect::<Vec<_>>()
                .join(", ")
                + " MiB",
            self.rss_growth_bytes
                .map(|b| format!("{:+.1} MiB", b as f64 / (1024.0 * 1024.0)))
                .unwrap_or_else(|| "n/a (fewer than 3 cycles)".into()),
            self.max_rss_growth_mib,
            mib(self.rss_final),
            if self.cycle_peak_heap.is_empty() {
                "not counted".to_string()
            } else {
                self.cycle_peak_heap
                    .iter()
                    .map(|&b| format!("{:.2}", b as f64 / (1024.0 * 1024.0)))
                    .collect::<Vec<_>>()
                    .join(", ")
                    + " MiB"
            },
            self.heap_growth_bytes
                .map(|b| format!("{:+.1} KiB", b as f64 / 1024.0))
                .unwrap_or_else(|| "n/a".into()),
            MAX_HEAP_GROWTH_BYTES / 1024,
            self.gpu_mismatches.len(),
        );
        out += if self.passed {
            "PASSED\n".to_string()
        } else {
            format!("FAILED: {}\n", self.problems.join("; "))
        }
        .as_str();
        out
    }
}
