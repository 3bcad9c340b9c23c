//! Per-pass GPU time from timestamp queries. Each pass asks for its timestamp writes by
//! name; frames later, without waiting, [`GpuTimer::latest`] returns milliseconds per pass
//! of the newest finished frame. Without timestamp support the timer says so
//! ([`GpuTimings::Unsupported`]) instead of zeros.

use crate::context::GpuContext;
use crate::error::GpuResult;
use crate::readback::AsyncReadback;

/// The name a pass is timed under: a constant declared once by the crate that records the
/// pass, and compared by value wherever timings are read (the lab's clock probe, the
/// assignment's total), so renaming a pass cannot leave a reader looking for the old name.
/// Steps of one stage share its prefix (`assign: mark tiles` is a step of
/// [`PassName::stage`] `assign`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PassName(&'static str);

impl PassName {
    pub const fn new(name: &'static str) -> Self {
        Self(name)
    }

    pub const fn as_str(self) -> &'static str {
        self.0
    }

    /// The stage a step belongs to: the part before `: `, or the whole name.
    pub fn stage(self) -> &'static str {
        stage_of(self.0)
    }
}

/// The stage of a pass named `name` ([`PassName::stage`]), for names kept as text (a
/// report's).
pub fn stage_of(name: &str) -> &str {
    name.split_once(": ").map_or(name, |(stage, _)| stage)
}

impl std::fmt::Display for PassName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // `pad`: widths and alignment apply (the CLI prints names in a column).
        f.pad(self.0)
    }
}

/// Time one pass took on the GPU.
#[derive(Debug, Clone, PartialEq)]
pub struct PassTiming {
    pub name: PassName,
    pub milliseconds: f64,
}

/// The GPU times of one frame.
#[derive(Debug, Clone, PartialEq)]
pub enum GpuTimings {
    Measured(Vec<PassTiming>),
    /// The adapter has no timestamp queries.
    Unsupported,
}

impl GpuTimings {
    pub fn get(&self, name: PassName) -> Option<f64> {
        match self {
            GpuTimings::Measured(passes) => passes
                .iter()
                .find(|p| p.name == name)
                .map(|p| p.milliseconds),
            GpuTimings::Unsupported => None,
        }
    }

    /// The summed time of the steps of `stage` (e.g. the steps `assign: ...` of the light
    /// assignment, [`PassName::stage`]); `None` when no pass matches.
    pub fn total_of(&self, stage: &str) -> Option<f64> {
        match self {
            GpuTimings::Measured(passes) => {
                let matching: Vec<f64> = passes
                    .iter()
                    .filter(|p| p.name.stage() == stage)
                    .map(|p| p.milliseconds)
                    .collect();
                (!matching.is_empty()).then(|| matching.iter().sum())
            }
            GpuTimings::Unsupported => None,
        }
    }

    pub fn total(&self) -> Option<f64> {
        match self {
            GpuTimings::Measured(passes) => Some(passes.iter().map(|p| p.milliseconds).sum()),
            GpuTimings::Unsupported => None,
        }
    }
}

impl std::fmt::Display for GpuTimings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GpuTimings::Unsupported => write!(
                f,
                "GPU timings unavailable (adapter has no timestamp queries)"
            ),
            GpuTimings::Measured(passes) => {
                for (i, pass) in passes.iter().enumerate() {
                    if i > 0 {
                        write!(f, ", ")?;
                    }
                    write!(f, "{} {:.3} ms", pass.name, pass.milliseconds)?;
                }
                Ok(())
            }
        }
    }
}

/// A frame's timestamp queries, in sets of [`PASSES_PER_SET`] passes, made before a frame is
/// recorded ([`GpuTimer::prepare`]): recording creates nothing. They hold the most passes
/// any frame asked for; a frame that asks for more than they hold times what fits, says
/// which passes it left untimed, and the next frame's `prepare` grows them.
#[derive(Debug)]
struct Queries {
    device: wgpu::Device,
    sets: Vec<wgpu::QuerySet>,
    /// The resolve buffer and its readback, sized for every set; rebuilt when a set is added.
    resolved: Option<Resolved>,
}

#[derive(Debug)]
struct Resolved {
    buffer: wgpu::Buffer,
    /// Each frame's resolved ticks, read back frames later without waiting.
    readback: AsyncReadback,
}

/// Passes per query set: two timestamps of 8 bytes each, so a set resolves into 256 bytes,
/// the offset alignment `resolve_query_set` requires of each set after the first.
const PASSES_PER_SET: u32 = 16;
const SET_BYTES: u64 = PASSES_PER_SET as u64 * 2 * 8;
const _: () = assert!(SET_BYTES.is_multiple_of(wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT));

/// Frames whose timestamps may be in flight at once (a GPU up to two frames behind).
const READBACK_SLOTS: usize = 3;

/// Passes the query sets hold before any frame asked for more: two sets, above the most a
/// frame of this renderer times (about 25: the far field's tree, the visible boxes, the
/// assignment's steps, the shadow filter, blended surfaces, statistics and post).
const INITIAL_PASSES: u32 = 2 * PASSES_PER_SET;

/// Timestamp queries for every pass of a frame, read back without stalling:
/// [`GpuTimer::latest`] returns the newest frame the GPU has finished (usually the one
/// before), [`GpuTimer::wait_latest`] waits for the last one (reports and tests). The query
/// sets are made in [`GpuTimer::prepare`], before a frame is recorded, for the most passes a
/// frame has timed so far.
#[derive(Debug)]
pub struct GpuTimer {
    queries: Option<Queries>,
    names: Vec<PassName>,
    /// The passes of the frame being recorded that found the query sets full.
    untimed: Vec<PassName>,
    /// The most passes one frame has asked to time (what `prepare` sizes the sets for).
    most_passes: u32,
    /// The pass names of the frames whose readback is in flight, by frame number.
    names_in_flight: Vec<(u64, Vec<PassName>)>,
    /// The times of the newest frame read back so far, by whichever call read them.
    newest: Option<GpuTimings>,
    frame: u64,
    period_ns: f64,
}

impl GpuTimer {
    pub fn new(context: &GpuContext) -> Self {
        let queries = context.summary.timestamps.then(|| Queries {
            device: context.device.clone(),
            sets: Vec::new(),
            resolved: None,
        });
        let mut timer = Self {
            queries,
            names: Vec::new(),
            untimed: Vec::new(),
            most_passes: INITIAL_PASSES,
            names_in_flight: Vec::new(),
            newest: None,
            frame: 0,
            period_ns: context.queue.get_timestamp_period() as f64,
        };
        timer.prepare();
        timer
    }

    /// Before a frame is recorded: makes the query sets, and the buffer they resolve into,
    /// hold the most passes any frame has asked to time. Nothing is made while recording.
    /// When the sets grow, the frames still in flight in the old buffer are forgotten
    /// (their times were older than the next frame's anyway).
    pub fn prepare(&mut self) {
        let Some(queries) = &mut self.queries else {
            return;
        };
        let sets = self.most_passes.div_ceil(PASSES_PER_SET) as usize;
        while queries.sets.len() < sets {
            queries
                .sets
                .push(queries.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: PASSES_PER_SET * 2,
                }));
        }
        let bytes = queries.sets.len() as u64 * SET_BYTES;
        if queries
            .resolved
            .as_ref()
            .is_none_or(|resolved| resolved.buffer.size() < bytes)
        {
            queries.resolved = Some(Resolved {
                buffer: queries.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp resolve"),
                    size: bytes,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                readback: AsyncReadback::new_on(
                    &queries.device,
                    "timestamp readback",
                    bytes,
                    READBACK_SLOTS,
                ),
            });
            self.names_in_flight.clear();
        }
    }

    pub fn supported(&self) -> bool {
        self.queries.is_some()
    }

    /// Starts a frame: forgets the previous frame's passes.
    pub fn begin_frame(&mut self) {
        self.names.clear();
        self.untimed.clear();
        self.frame += 1;
    }

    /// The passes of the frame recorded last that found the query sets full (the next
    /// [`GpuTimer::prepare`] makes room for them); empty when every pass was timed.
    pub fn untimed(&self) -> &[PassName] {
        &self.untimed
    }

    /// The number of the frame being recorded (counted by [`GpuTimer::begin_frame`]).
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Passes the query sets hold now (they grow in `prepare` after a frame needed more).
    pub fn capacity(&self) -> u32 {
        self.queries
            .as_ref()
            .map_or(0, |queries| queries.sets.len() as u32 * PASSES_PER_SET)
    }

    /// Reserves a begin/end pair for a pass; `None` without timestamp support, or when the
    /// frame's passes fill the sets `prepare` made (the pass is then listed as untimed).
    fn reserve(&mut self, name: PassName) -> Option<(&wgpu::QuerySet, u32)> {
        let queries = self.queries.as_ref()?;
        let index = self.names.len() as u32;
        let asked = index + self.untimed.len() as u32 + 1;
        self.most_passes = self.most_passes.max(asked);
        let set = (index / PASSES_PER_SET) as usize;
        let Some(query_set) = queries.sets.get(set) else {
            self.untimed.push(name);
            return None;
        };
        self.names.push(name);
        Some((query_set, (index % PASSES_PER_SET) * 2))
    }

    pub fn render_pass(&mut self, name: PassName) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.reserve(name)
            .map(|(query_set, first)| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(first),
                end_of_pass_write_index: Some(first + 1),
            })
    }

    pub fn compute_pass(&mut self, name: PassName) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.reserve(name)
            .map(|(query_set, first)| wgpu::ComputePassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(first),
                end_of_pass_write_index: Some(first + 1),
            })
    }

    /// Records the resolve of this frame's queries and their copy into a free readback
    /// slot; call once after the last timed pass. (With every slot in flight, the GPU
    /// three frames behind, this frame is not timed.) A frame that left passes untimed
    /// says which.
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let Some(queries) = &mut self.queries else {
            return;
        };
        if !self.untimed.is_empty() {
            log::warn!(
                "frame {}: {} passes found the timer's queries full and are untimed ({}); \
                 the next frame's queries hold {}",
                self.frame,
                self.untimed.len(),
                self.untimed
                    .iter()
                    .map(|name| name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
                self.most_passes
            );
        }
        if self.names.is_empty() {
            return;
        }
        let Some(resolved) = &mut queries.resolved else {
            return;
        };
        let passes = self.names.len() as u32;
        for (set_index, set) in queries.sets.iter().enumerate() {
            let first_pass = set_index as u32 * PASSES_PER_SET;
            if first_pass >= passes {
                break;
            }
            let in_set = (passes - first_pass).min(PASSES_PER_SET);
            encoder.resolve_query_set(
                set,
                0..in_set * 2,
                &resolved.buffer,
                set_index as u64 * SET_BYTES,
            );
        }
        if resolved
            .readback
            .record_copy(encoder, &resolved.buffer, 0, self.frame)
        {
            self.names_in_flight.push((self.frame, self.names.clone()));
        }
    }

    /// Call after the submission that holds [`GpuTimer::resolve`].
    pub fn after_submit(&mut self) {
        if let Some(resolved) = self.queries.as_mut().and_then(|q| q.resolved.as_mut()) {
            resolved.readback.request_maps();
        }
    }

    /// The newest frame the GPU has finished, with its number, without waiting; `None`
    /// while no timed frame has finished since the last call.
    pub fn latest(&mut self, context: &GpuContext) -> GpuResult<Option<(u64, GpuTimings)>> {
        let Some(queries) = &mut self.queries else {
            return Ok(Some((self.frame, GpuTimings::Unsupported)));
        };
        let Some(resolved) = &mut queries.resolved else {
            return Ok(None);
        };
        let newest = resolved.readback.try_newest(context)?;
        Ok(newest.map(|(frame, bytes)| (frame, self.timings_of(frame, &bytes))))
    }

    /// Waits for every frame in flight and returns the last one's times (the newest
    /// frame's; after the submit that contains its [`GpuTimer::resolve`]). A frame the GPU
    /// finished before [`GpuTimer::latest`] read it is no longer in flight: its times are
    /// still the newest, and returned.
    pub fn wait_latest(&mut self, context: &GpuContext) -> GpuResult<GpuTimings> {
        crate::block_on(self.wait_latest_async(context))
    }

    /// [`GpuTimer::wait_latest`] without blocking (the page's lab awaits it).
    pub async fn wait_latest_async(&mut self, context: &GpuContext) -> GpuResult<GpuTimings> {
        let Some(queries) = &mut self.queries else {
            return Ok(GpuTimings::Unsupported);
        };
        if let Some(resolved) = &mut queries.resolved
            && let Some((frame, bytes)) = resolved.readback.wait_newest_async(context).await?
        {
            self.timings_of(frame, &bytes);
        }
        Ok(self
            .newest
            .clone()
            .unwrap_or(GpuTimings::Measured(Vec::new())))
    }

    /// Decodes a frame's ticks (kept as the newest times), and forgets the names of that
    /// frame and older ones.
    fn timings_of(&mut self, frame: u64, bytes: &[u8]) -> GpuTimings {
        let names = self
            .names_in_flight
            .iter()
            .find(|(tagged, _)| *tagged == frame)
            .map(|(_, names)| names.clone())
            .unwrap_or_default();
        self.names_in_flight.retain(|(tagged, _)| *tagged > frame);
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(bytes);
        let timings = GpuTimings::Measured(
            names
                .iter()
                .enumerate()
                .map(|(i, name)| PassTiming {
                    name: *name,
                    milliseconds: ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64
                        * self.period_ns
                        / 1e6,
                })
                .collect(),
        );
        self.newest = Some(timings.clone());
        timings
    }
}

/// Begins a compute pass labelled `name`, timed under that name when a timer is given:
/// the one way the crates open a compute pass, so labels and timings agree.
pub fn timed_compute_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    timer: Option<&mut GpuTimer>,
    name: PassName,
) -> wgpu::ComputePass<'e> {
    let timestamp_writes = timer.and_then(|timer| timer.compute_pass(name));
    encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(name.as_str()),
        timestamp_writes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_belongs_to_its_stage_and_totals_sum_only_that_stage() {
        let mark = PassName::new("assign: mark tiles");
        let fill = PassName::new("assign: fill lists");
        let gbuffer = PassName::new("g-buffer");
        assert_eq!((mark.stage(), gbuffer.stage()), ("assign", "g-buffer"));
        let timings = GpuTimings::Measured(
            [(mark, 0.25), (gbuffer, 1.0), (fill, 0.5)]
                .map(|(name, milliseconds)| PassTiming { name, milliseconds })
                .to_vec(),
        );
        assert_eq!(timings.total_of("assign"), Some(0.75));
        assert_eq!(timings.total_of("assig"), None);
        assert_eq!(timings.get(gbuffer), Some(1.0));
        // The CLI prints names in a column: widths apply.
        assert_eq!(format!("[{gbuffer:<10}]"), "[g-buffer  ]");
    }
}
