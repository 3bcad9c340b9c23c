//! [`GpuListStatistics`]: the lights-per-cluster statistics of [`ClusterStats`] computed
//! on the GPU (`shaders/cluster/stats.wgsl`) and read back without stalling: a frame's
//! statistics arrive a frame or two later, so asking for them never makes the GPU wait
//! for the CPU (an idle GPU drops its clock, and the next frame's timings would measure
//! a cold GPU). `ClusterStats::from_offsets` and `false_positive_ratio` stay as the CPU
//! reference the tests compare with.

use manylights_gpu::binding::ComputePasses;
use manylights_gpu::{
    AsyncReadback, GpuContext, GpuResult, GpuTimer, MaterialVariant, ShaderLibrary, ViewBinding,
    wgpu,
};

use crate::assign::GpuClusters;
use crate::stats_reference::ClusterStats;

/// Histogram buckets on the GPU: empty, then one per power of two up to 2^32.
pub(crate) const HISTOGRAM_BUCKETS: usize = 34;
/// u32 words of `ListStatistics` in the shader (plus one of padding).
const STATISTICS_WORDS: usize = 4 + HISTOGRAM_BUCKETS + 2;
/// Copies that may be in flight at once.
const READBACK_SLOTS: usize = 3;

/// GPU passes and buffers for light-list statistics.
#[derive(Debug)]
pub struct GpuListStatistics {
    layout: wgpu::BindGroupLayout,
    list_statistics: wgpu::ComputePipeline,
    mark_reached: wgpu::ComputePipeline,
    count_false_positives: wgpu::ComputePipeline,
    statistics: wgpu::Buffer,
    /// Bit sets for false positives: (words, buffer), grown on demand.
    reached: Option<(u64, wgpu::Buffer)>,
    occupied: Option<(u64, wgpu::Buffer)>,
    /// An empty depth texture bound when false positives are not asked for.
    no_depth: wgpu::TextureView,
    readback: AsyncReadback,
    frames_recorded: u64,
    recorded: RecordedFrames,
    bind_group: manylights_gpu::binding::CachedBindGroup,
}

impl GpuListStatistics {
    pub fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        view: &ViewBinding,
    ) -> GpuResult<Self> {
        let device = &context.device;
        let module = library.create_module(
            context,
            &crate::statistics_program(),
            MaterialVariant::default(),
        )?;
        let compute = wgpu::ShaderStages::COMPUTE;
        use manylights_gpu::binding::{storage_entry, uniform_entry};
        let ComputePasses {
            layout,
            pipelines: [list_statistics, mark_reached, count_false_positives],
        } = ComputePasses::new(
            context,
            &module,
            "cluster statistics",
            &[&view.layout],
            &[
                uniform_entry(0, compute),
                storage_entry(1, compute, true),
                storage_entry(2, compute, true),
                storage_entry(3, compute, true),
                storage_entry(4, compute, false),
                storage_entry(5, compute, false),
                storage_entry(6, compute, false),
                manylights_gpu::binding::depth_texture_entry(7, compute),
            ],
            ["list_statistics", "mark_reached", "count_false_positives"],
        )?;
        let statistics_bytes = (STATISTICS_WORDS * 4) as u64;
        let statistics = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("cluster statistics"),
            size: statistics_bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let no_depth = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("no depth (statistics without false positives)"),
                size: wgpu::Extent3d {
                    width: 1,
                    height: 1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: manylights_gpu::DEPTH_FORMAT,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
            .create_view(&Default::default());
        Ok(Self {
            layout,
            list_statistics,
            mark_reached,
            count_false_positives,
            statistics,
            reached: None,
            occupied: None,
            no_depth,
            readback: AsyncReadback::new(
                context,
                "cluster statistics readback",
                statistics_bytes,
                READBACK_SLOTS,
            ),
            frames_recorded: 0,
            recorded: RecordedFrames::default(),
            bind_group: Default::default(),
        })
    }

    /// A bit-set buffer of at least `bits` bits, grown (to a power of two) when needed.
    fn bit_set(
        context: &GpuContext,
        slot: &mut Option<(u64, wgpu::Buffer)>,
        label: &str,
        bits: u64,
    ) -> GpuResult<()> {
        let words = bits.div_ceil(32).max(1);
        if slot.as_ref().is_none_or(|(have, _)| *have < words) {
            let words = words.next_power_of_two();
            context.check_buffer_size(label, words * 4, true)?;
            let buffer = context.scoped(&format!("allocating {label}"), || {
                context.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: words * 4,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            })?;
            *slot = Some((words, buffer));
        }
        Ok(())
    }

    /// Prepares the statistics of the lists `clusters` will build this frame; with `depth`
    /// (the frame's depth buffer, drawn before the statistics run) also the false-positive
    /// ratio. `None` while the clusters have no grid.
    pub fn prepare<'a>(
        &'a mut self,
        context: &GpuContext,
        clusters: &GpuClusters,
        depth: Option<&wgpu::TextureView>,
    ) -> GpuResult<Option<PreparedStatistics<'a>>> {
        let Some(grid) = clusters.grid() else {
            return Ok(None);
        };
        let cluster_count = grid.cluster_count();
        Self::bit_set(
            context,
            &mut self.reached,
            "listed-light reached bits",
            u64::from(clusters.capacity()),
        )?;
        Self::bit_set(
            context,
            &mut self.occupied,
            "occupied-cluster bits",
            u64::from(cluster_count),
        )?;
        let (Some((_, reached)), Some((_, occupied))) = (&self.reached, &self.occupied) else {
            return Ok(None);
        };
        let bind_group = self.bind_group.get(
            context,
            "cluster statistics",
            &self.layout,
            [
                (0, clusters.params_buffer().as_entire_binding()),
                (1, clusters.offsets_buffer()?.as_entire_binding()),
                (2, clusters.indices_buffer()?.as_entire_binding()),
                (3, clusters.view_lights_buffer()?.as_entire_binding()),
                (4, self.statistics.as_entire_binding()),
                (5, reached.as_entire_binding()),
                (6, occupied.as_entire_binding()),
                (
                    7,
                    wgpu::BindingResource::TextureView(depth.unwrap_or(&self.no_depth)),
                ),
            ],
        );
        let (reached, occupied) = (reached.clone(), occupied.clone());
        Ok(Some(PreparedStatistics {
            bind_group,
            reached,
            occupied,
            cluster_count,
            screen: grid.screen,
            false_positives: depth.is_some(),
            statistics: self,
        }))
    }

    /// Call after the submission that holds the recorded pass.
    pub fn after_submit(&mut self) {
        self.readback.request_maps();
    }

    /// The newest statistics the GPU has finished, without waiting (`None` while none
    /// arrived since the last call).
    pub fn poll(&mut self, context: &GpuContext) -> GpuResult<Option<ClusterStats>> {
        let newest = self.readback.try_newest(context)?;
        Ok(self.decode(newest))
    }

    /// Waits for the statistics of the last recorded frame (reports, tests).
    pub fn wait(&mut self, context: &GpuContext) -> GpuResult<Option<ClusterStats>> {
        manylights_gpu::block_on(self.wait_async(context))
    }

    /// [`GpuListStatistics::wait`] without blocking.
    pub async fn wait_async(&mut self, context: &GpuContext) -> GpuResult<Option<ClusterStats>> {
        let newest = self.readback.wait_newest_async(context).await?;
        Ok(self.decode(newest))
    }

    fn decode(&mut self, newest: Option<(u64, Vec<u8>)>) -> Option<ClusterStats> {
        let (frame, bytes) = newest?;
        let (clusters, false_positives) = self.recorded.take(frame)?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        Some(stats_from_words(&words, clusters, false_positives))
    }
}

/// What each frame whose statistics are in flight was recorded with: (frame tag, clusters,
/// with false positives).
#[derive(Debug, Default)]
struct RecordedFrames(Vec<(u64, u32, bool)>);

impl RecordedFrames {
    fn push(&mut self, frame: u64, clusters: u32, false_positives: bool) {
        self.0.push((frame, clusters, false_positives));
    }

    /// The record of `frame`, forgetting it and every older one (their readbacks were
    /// dropped in favour of this newer one), so the list stays as short as the readbacks
    /// in flight.
    fn take(&mut self, frame: u64) -> Option<(u32, bool)> {
        let found = self.0.iter().find(|r| r.0 == frame).map(|r| (r.1, r.2));
        self.0.retain(|r| r.0 > frame);
        found
    }
}

/// `ListStatistics` as read back, in the shape of [`ClusterStats::from_offsets`]: the
/// histogram keeps at least two buckets and ends at the last non-empty one.
fn stats_from_words(words: &[u32], clusters: u32, false_positives: bool) -> ClusterStats {
    let total_entries = u64::from(words[0]);
    let (visible, useless) = (words[2], words[3]);
    let mut histogram = words[4..4 + HISTOGRAM_BUCKETS].to_vec();
    while histogram.len() > 2 && histogram.last() == Some(&0) {
        histogram.pop();
    }
    ClusterStats {
        clusters,
        total_entries,
        mean_lights: if clusters == 0 {
            0.0
        } else {
            total_entries as f64 / f64::from(clusters)
        },
        max_lights: words[1],
        histogram,
        false_positive_ratio: false_positives.then(|| {
            if visible == 0 {
                0.0
            } else {
                f64::from(useless) / f64::from(visible)
            }
        }),
    }
}

/// One frame's list statistics, prepared: recording replays the passes and queues the
/// read-back.
#[derive(Debug)]
pub struct PreparedStatistics<'a> {
    statistics: &'a mut GpuListStatistics,
    bind_group: wgpu::BindGroup,
    /// The false-positive bit sets (cleared before the passes that set them).
    reached: wgpu::Buffer,
    occupied: wgpu::Buffer,
    cluster_count: u32,
    screen: (u32, u32),
    /// Whether the frame's depth is bound (the false-positive passes run).
    false_positives: bool,
}

impl PreparedStatistics<'_> {
    /// Records the statistics of the lists the frame's assignment just built.
    pub fn record(
        self,
        encoder: &mut wgpu::CommandEncoder,
        view: &ViewBinding,
        timer: Option<&mut GpuTimer>,
    ) {
        let stats = self.statistics;
        encoder.clear_buffer(&stats.statistics, 0, None);
        if self.false_positives {
            encoder.clear_buffer(&self.reached, 0, None);
            encoder.clear_buffer(&self.occupied, 0, None);
        }
        {
            let mut pass = crate::view_pass(encoder, view, timer, crate::passes::STATISTICS);
            pass.set_bind_group(1, &self.bind_group, &[]);
            let cluster_groups = self.cluster_count.div_ceil(crate::assign::WORKGROUP_SIZE);
            pass.set_pipeline(&stats.list_statistics);
            pass.dispatch_workgroups(cluster_groups, 1, 1);
            if self.false_positives {
                let (width, height) = self.screen;
                pass.set_pipeline(&stats.mark_reached);
                let tile = manylights_gpu::SCREEN_TILE;
                pass.dispatch_workgroups(width.div_ceil(tile), height.div_ceil(tile), 1);
                pass.set_pipeline(&stats.count_false_positives);
                pass.dispatch_workgroups(cluster_groups, 1, 1);
            }
        }
        let frame = stats.frames_recorded;
        stats.frames_recorded += 1;
        if stats
            .readback
            .record_copy(encoder, &stats.statistics, 0, frame)
        {
            stats
                .recorded
                .push(frame, self.cluster_count, self.false_positives);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_taken_frame_forgets_itself_and_older_ones() {
        let mut recorded = RecordedFrames::default();
        for frame in 0..4 {
            recorded.push(frame, 10 + frame as u32, frame % 2 == 1);
        }
        assert_eq!(recorded.take(2), Some((12, false)));
        assert_eq!(recorded.0, vec![(3, 13, true)]);
        assert_eq!(recorded.take(1), None, "older frames are gone");
        assert_eq!(recorded.take(3), Some((13, true)));
        assert!(recorded.0.is_empty());
    }

    #[test]
    fn read_back_words_decode_like_offsets() {
        // Counts 0, 1, 3, 4, 9 (as in stats::tests): total 17, max 9.
        let mut words = vec![0u32; STATISTICS_WORDS];
        words[0] = 17;
        words[1] = 9;
        words[2] = 10;
        words[3] = 4;
        for bucket in 0..5 {
            words[4 + bucket] = 1;
        }
        let gpu = stats_from_words(&words, 5, true);
        let mut cpu = ClusterStats::from_offsets(&[0, 0, 1, 4, 8, 17]);
        cpu.false_positive_ratio = Some(0.4);
        assert_eq!(gpu, cpu);
        // All clusters empty: two buckets, as from_offsets gives.
        let mut empty = vec![0u32; STATISTICS_WORDS];
        empty[4] = 3;
        assert_eq!(
            stats_from_words(&empty, 3, false),
            ClusterStats::from_offsets(&[0, 0, 0, 0])
        );
    }
}
