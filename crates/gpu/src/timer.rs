//! Per-pass GPU time from timestamp queries. Each pass asks for its timestamp writes by
//! name; after submission [`GpuTimer::read`] returns milliseconds per pass. Without
//! timestamp support the timer says so ([`GpuTimings::Unsupported`]) instead of zeros.

use crate::context::GpuContext;
use crate::error::GpuResult;
use crate::targets::map_read;

/// Time one pass took on the GPU.
#[derive(Debug, Clone, PartialEq)]
pub struct PassTiming {
    pub name: String,
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
    pub fn get(&self, name: &str) -> Option<f64> {
        match self {
            GpuTimings::Measured(passes) => passes
                .iter()
                .find(|p| p.name == name)
                .map(|p| p.milliseconds),
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

#[derive(Debug)]
struct Queries {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
}

/// Timestamp queries for up to `capacity` passes per frame.
#[derive(Debug)]
pub struct GpuTimer {
    queries: Option<Queries>,
    capacity: u32,
    names: Vec<String>,
    period_ns: f64,
}

impl GpuTimer {
    pub fn new(context: &GpuContext, capacity: u32) -> Self {
        let queries = context.summary.timestamps.then(|| {
            let count = capacity * 2;
            let bytes = count as u64 * 8;
            Queries {
                set: context.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count,
                }),
                resolve: context.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp resolve"),
                    size: bytes,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                readback: context.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp readback"),
                    size: bytes,
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                }),
            }
        });
        Self {
            queries,
            capacity,
            names: Vec::new(),
            period_ns: context.queue.get_timestamp_period() as f64,
        }
    }

    pub fn supported(&self) -> bool {
        self.queries.is_some()
    }

    /// Forgets the previous frame's passes.
    pub fn begin_frame(&mut self) {
        self.names.clear();
    }

    /// Reserves a begin/end pair for a pass; `None` without timestamp support or when
    /// more than `capacity` passes were asked for (logged).
    fn reserve(&mut self, name: &str) -> Option<(&wgpu::QuerySet, u32)> {
        let queries = self.queries.as_ref()?;
        if self.names.len() as u32 >= self.capacity {
            log::warn!(
                "GPU timer full ({} passes); pass '{name}' is not timed",
                self.capacity
            );
            return None;
        }
        self.names.push(name.to_string());
        Some((&queries.set, (self.names.len() as u32 - 1) * 2))
    }

    pub fn render_pass(&mut self, name: &str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.reserve(name)
            .map(|(query_set, first)| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(first),
                end_of_pass_write_index: Some(first + 1),
            })
    }

    pub fn compute_pass(&mut self, name: &str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.reserve(name)
            .map(|(query_set, first)| wgpu::ComputePassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(first),
                end_of_pass_write_index: Some(first + 1),
            })
    }

    /// Records the resolve of this frame's queries; call once after the last timed pass.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(queries) = &self.queries
            && !self.names.is_empty()
        {
            let count = self.names.len() as u32 * 2;
            encoder.resolve_query_set(&queries.set, 0..count, &queries.resolve, 0);
            encoder.copy_buffer_to_buffer(
                &queries.resolve,
                0,
                &queries.readback,
                0,
                count as u64 * 8,
            );
        }
    }

    /// Waits for the frame and returns each pass's time (after the submit that contains
    /// [`GpuTimer::resolve`]).
    pub fn read(&self, context: &GpuContext) -> GpuResult<GpuTimings> {
        let Some(queries) = &self.queries else {
            return Ok(GpuTimings::Unsupported);
        };
        if self.names.is_empty() {
            return Ok(GpuTimings::Measured(Vec::new()));
        }
        let bytes = map_read(context, &queries.readback, "reading GPU timestamps")?;
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes);
        Ok(GpuTimings::Measured(
            self.names
                .iter()
                .enumerate()
                .map(|(i, name)| PassTiming {
                    name: name.clone(),
                    milliseconds: ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64
                        * self.period_ns
                        / 1e6,
                })
                .collect(),
        ))
    }
}
