//! GPU light assignment (`shaders/cluster/assign.wgsl`) in a few compute passes, each timed
//! as `assign: <step>`, by one of two designs ([`AssignmentDesign`]): tile masks walked per
//! cluster in light order (lists sorted by construction), or the first design's atomic fill
//! and sort.
//! Lights are tested against each cluster's box: the grid's, or ([`ClusterBoxes`]) the box
//! of the cluster's visible samples, bounded first from the frame's depth
//! (`shaders/cluster/visible_bounds.wgsl`), so clusters no sample falls in list nothing.
//!
//! Growing the index list without waiting: the list buffer starts at
//! [`INITIAL_INDEX_CAPACITY`] entries and the fill writes only what fits. Each frame copies
//! the total into a small ring of mappable buffers; a later frame reads it when the GPU got
//! there ([`GpuClusters::grow_for_earlier_frames`], never blocking) and grows the buffer to
//! the next power of two above it. The frame that overflowed is not dropped or redone:
//! the shading loop sees that a cluster's list was cut short (its end lies past the
//! capacity) and finds that cluster's lights again from all lights, the same set in the same
//! order, so the image is the same, only that frame is slower. Steady frames pay a 4-byte
//! copy.

use manylights_gpu::{
    AsyncReadback, GpuContext, GpuError, GpuResult, GpuTimer, MaterialVariant, ShaderLibrary,
    ViewBinding, timed_compute_pass, wgpu,
};
use manylights_lights::GpuLights;
use manylights_scene::Aabb;

use crate::assign::SpotCulling;
use crate::grid::{ClusterGrid, ZScheme};

/// Entries the light-index list starts with (256 KiB). It grows on demand.
pub const INITIAL_INDEX_CAPACITY: u32 = 1 << 16;

/// With [`AssignmentDesign::AtomicFill`], lists up to this long come out in ascending light
/// order (`sort_lists` in `shaders/cluster/assign.wgsl`, `SORT_LIMIT`); longer lists hold
/// the same lights in the order the fill's atomics gave. Tile masks sort every list.
pub const SORTED_LIST_LIMIT: usize = 256;

/// How the GPU builds the lists. Both give the same set per cluster as the CPU reference
/// ([`crate::assign_lights`]); they differ in order and speed (docs/results/nvidia-h200/
/// assignment measures them side by side).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AssignmentDesign {
    /// Each light (16 lanes sharing its candidate clusters) counts the clusters it meets and
    /// marks their tiles in a per-tile bit mask; after the prefix sum, one workgroup per tile
    /// and group of 8 slices walks the tile's mask in light order, tests each marked light
    /// against those clusters' boxes and writes the hits by an ordered compaction: every
    /// list in ascending light order with no sort and no atomics on the lists. Memory: one
    /// bit per light and tile.
    #[default]
    TileMasks,
    /// The first design: each light counts and then writes itself into its clusters with
    /// atomics, and one thread per cluster insertion-sorts lists up to
    /// [`SORTED_LIST_LIMIT`].
    AtomicFill,
}

impl AssignmentDesign {
    pub const ALL: [AssignmentDesign; 2] =
        [AssignmentDesign::TileMasks, AssignmentDesign::AtomicFill];

    pub fn name(self) -> &'static str {
        match self {
            AssignmentDesign::TileMasks => "tile-masks",
            AssignmentDesign::AtomicFill => "atomic-fill",
        }
    }

    /// Lists up to this long are in ascending light order.
    pub fn sorted_list_limit(self) -> usize {
        match self {
            AssignmentDesign::TileMasks => usize::MAX,
            AssignmentDesign::AtomicFill => SORTED_LIST_LIMIT,
        }
    }
}

impl std::fmt::Display for AssignmentDesign {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for AssignmentDesign {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|design| design.name() == text)
            .ok_or_else(|| format!("unknown assignment design {text:?} (tile-masks, atomic-fill)"))
    }
}

/// Which box each cluster's lights are tested against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ClusterBoxes {
    /// The bounding box of the cluster's visible samples, from the frame's depth, when the
    /// pipeline lays depth down before assignment (deferred, Forward+ with its pre-pass);
    /// empty where no sample falls, so those clusters list nothing. Otherwise the grid's.
    #[default]
    VisibleSamples,
    /// The bounding box of the cluster's whole frustum slab
    /// ([`ClusterGrid::cluster_bounds`]), every cluster listed whether or not anything is
    /// seen in it (the first design; kept to measure against).
    Grid,
}

impl ClusterBoxes {
    pub const ALL: [ClusterBoxes; 2] = [ClusterBoxes::VisibleSamples, ClusterBoxes::Grid];

    pub fn name(self) -> &'static str {
        match self {
            ClusterBoxes::VisibleSamples => "visible",
            ClusterBoxes::Grid => "grid",
        }
    }
}

manylights_gpu::named_choice!(ClusterBoxes, "cluster box");

/// Slices one workgroup of the visible-bounds pass handles (`SLICES_PER_GROUP` in
/// `visible_bounds.wgsl`).
const VISIBLE_BOUNDS_SLICES_PER_GROUP: u32 = 64;

/// Bands of rows each tile's samples are bounded in, by a workgroup each
/// (`BANDS_PER_TILE` in `visible_bounds.wgsl`).
const VISIBLE_BOUNDS_BANDS_PER_TILE: u32 = 8;

/// Frames whose list totals may be in flight at once.
const TOTAL_READBACK_SLOTS: usize = 3;

/// Lights one workgroup of `mark_tiles` handles (`MARK_LIGHTS_PER_GROUP`: 16 lanes each).
const MARK_LIGHTS_PER_GROUP: u32 = 4;

/// Workgroups one dispatch dimension may hold (wgpu's default limit).
const MAX_WORKGROUPS_PER_DIMENSION: u32 = 65_535;

/// The `mark_tiles` dispatch for `light_count` lights: a row of workgroups, folded into a
/// second dimension past [`MAX_WORKGROUPS_PER_DIMENSION`] (1,000,000 lights need 250,000).
fn mark_tiles_dispatch(light_count: u32) -> [u32; 3] {
    let groups = light_count.div_ceil(MARK_LIGHTS_PER_GROUP);
    let x = groups.clamp(1, MAX_WORKGROUPS_PER_DIMENSION);
    [x, groups.div_ceil(x), 1]
}

/// Mask words one window of the walk scans (`WALK_THREADS` in assign.wgsl).
const WALK_WINDOW_WORDS: u32 = 256;

/// Slices one tile walk handles (`SLICES_PER_WALK` in assign.wgsl).
const SLICES_PER_WALK: u32 = 8;

/// Threads per workgroup of the light and cluster dispatches.
const WORKGROUP_SIZE: u32 = 64;

/// Mirrors `ClusterParams` in `shaders/cluster/cluster_index.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ClusterParamsUniform {
    pub dims: [u32; 4],
    pub tile_and_screen: [f32; 4],
    pub z_params: [f32; 4],
    pub scheme_lights_capacity: [u32; 4],
    /// Tile-mask design: walk groups (of 8 slices) sharing one mask, masks per tile.
    pub mask_layout: [u32; 4],
    /// x: [`SpotCulling::shader_value`].
    pub light_shapes: [u32; 4],
}

/// How the tile-mask design lays out its masks: one bit per light in each mask, a mask per
/// tile and group of [`MaskLayout::walk_groups_per_mask`] walk groups (8 slices each), so
/// that each walk reads only the lights that meet its own slices. Groups share a mask when
/// one per group would pass the memory budget ([`TILE_MASK_BUDGET_BYTES`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MaskLayout {
    /// Words (of 32 lights) in one mask.
    pub words: u32,
    pub walk_groups_per_mask: u32,
    pub masks_per_tile: u32,
    /// Words of window marks per mask: one bit per window of 256 words (8,192 lights) that
    /// holds a marked light, so the walk skips empty windows.
    pub window_mark_words: u32,
}

/// The most the tile masks may take (a mask per tile and walk group takes 108 MiB at
/// 1,000,000 lights on the default 16x9x48 grid; groups then share masks).
pub const TILE_MASK_BUDGET_BYTES: u64 = 64 << 20;

impl MaskLayout {
    /// The finest layout for `lights` on `grid` within `budget` bytes (at worst one mask
    /// per tile, whatever the budget).
    pub fn for_grid(grid: &ClusterGrid, lights: u32, budget: u64) -> Self {
        let words = lights.div_ceil(32);
        let tiles = u64::from(grid.dims.x) * u64::from(grid.dims.y);
        let walk_groups = grid.dims.z.div_ceil(SLICES_PER_WALK);
        let mut walk_groups_per_mask = 1;
        while walk_groups_per_mask < walk_groups
            && tiles * u64::from(walk_groups.div_ceil(walk_groups_per_mask)) * u64::from(words) * 4
                > budget
        {
            walk_groups_per_mask += 1;
        }
        Self {
            words,
            walk_groups_per_mask,
            masks_per_tile: walk_groups.div_ceil(walk_groups_per_mask),
            window_mark_words: words.div_ceil(WALK_WINDOW_WORDS * 32),
        }
    }

    /// Bytes of the window marks.
    pub fn window_mark_bytes(&self, grid: &ClusterGrid) -> u64 {
        u64::from(grid.dims.x)
            * u64::from(grid.dims.y)
            * u64::from(self.masks_per_tile)
            * u64::from(self.window_mark_words)
            * 4
    }

    pub fn bytes(&self, grid: &ClusterGrid) -> u64 {
        u64::from(grid.dims.x)
            * u64::from(grid.dims.y)
            * u64::from(self.masks_per_tile)
            * u64::from(self.words)
            * 4
    }
}

impl ClusterParamsUniform {
    /// `masks`: the tile masks' layout (tile-mask design; zero for the atomic fill).
    pub fn new(
        grid: &ClusterGrid,
        light_count: u32,
        capacity: u32,
        masks: MaskLayout,
        spot_culling: SpotCulling,
    ) -> Self {
        let slices = grid.dims.z as f32;
        let (scheme, first_far, scale) = match grid.scheme {
            ZScheme::Linear => (0, 0.0, slices / (grid.z_far - grid.z_near)),
            ZScheme::Logarithmic => (1, 0.0, slices / (grid.z_far / grid.z_near).ln()),
            ZScheme::LogarithmicWithNearSlice { first_slice_far } => (
                2,
                first_slice_far,
                (slices - 1.0) / (grid.z_far / first_slice_far).ln(),
            ),
        };
        Self {
            dims: [grid.dims.x, grid.dims.y, grid.dims.z, grid.cluster_count()],
            tile_and_screen: [
                grid.tile_size.0,
                grid.tile_size.1,
                grid.screen.0 as f32,
                grid.screen.1 as f32,
            ],
            z_params: [grid.z_near, grid.z_far, first_far, scale],
            scheme_lights_capacity: [scheme, light_count, capacity, masks.words],
            mask_layout: [
                masks.walk_groups_per_mask,
                masks.masks_per_tile,
                masks.window_mark_words,
                0,
            ],
            light_shapes: [spot_culling.shader_value(), 0, 0, 0],
        }
    }
}

/// Entries per tile of the tile slice ranges: one per group of 64 slices.
fn tile_slice_groups(grid: &ClusterGrid) -> u32 {
    grid.dims.z.div_ceil(VISIBLE_BOUNDS_SLICES_PER_GROUP)
}

/// Writes the grid's tile slice ranges: every slice of every group (first | last << 16).
fn upload_tile_slices(context: &GpuContext, buffer: &wgpu::Buffer, grid: &ClusterGrid) {
    let groups = tile_slice_groups(grid);
    let ranges: Vec<u32> = (0..grid.dims.x * grid.dims.y)
        .flat_map(|_| {
            (0..groups).map(|group| {
                let first = group * VISIBLE_BOUNDS_SLICES_PER_GROUP;
                let last = (first + VISIBLE_BOUNDS_SLICES_PER_GROUP - 1).min(grid.dims.z - 1);
                first | (last << 16)
            })
        })
        .collect();
    context
        .queue
        .write_buffer(buffer, 0, bytemuck::cast_slice(&ranges));
}

/// Writes the view-space bounds of every cluster of `grid` (`ClusterGrid::cluster_bounds`),
/// each flagged as holding something (`ClusterBounds` in `shaders/cluster/bounds.wgsl`).
fn upload_bounds(context: &GpuContext, buffer: &wgpu::Buffer, grid: &ClusterGrid) {
    let bounds: Vec<[f32; 8]> = grid
        .cluster_bounds()
        .iter()
        .map(|b| {
            [
                b.min.x, b.min.y, b.min.z, 1.0, b.max.x, b.max.y, b.max.z, 0.0,
            ]
        })
        .collect();
    context
        .queue
        .write_buffer(buffer, 0, bytemuck::cast_slice(&bounds));
}

/// Buffers sized for one grid and light count.
#[derive(Debug)]
struct Buffers {
    clusters: u32,
    /// Tiles across times tiles down: the tile masks' count.
    tiles: u32,
    lights: u32,
    capacity: u32,
    /// The grid's boxes (uploaded when the grid changes) and this frame's visible ones.
    bounds: wgpu::Buffer,
    visible_bounds: wgpu::Buffer,
    /// Per tile and group of 64 slices, the first and last slice holding anything: all of
    /// them for the grid's boxes, the occupied ones for the visible samples'.
    tile_slices: wgpu::Buffer,
    visible_tile_slices: wgpu::Buffer,
    /// The visible boxes as order-preserving codes, combined across a tile's bands.
    visible_box_codes: wgpu::Buffer,
    view_lights: wgpu::Buffer,
    /// Spot lights' view-space axes and outer sines (w = -1 for point lights).
    view_cones: wgpu::Buffer,
    counts: wgpu::Buffer,
    offsets: wgpu::Buffer,
    indices: wgpu::Buffer,
    /// Tile-mask design: one bit per light and tile, and each light's candidate slices.
    /// A single word each with the atomic design, which reads neither.
    tile_masks: wgpu::Buffer,
    window_marks: wgpu::Buffer,
    masks: MaskLayout,
    light_slices: wgpu::Buffer,
    design: AssignmentDesign,
}

/// The GPU light lists of the current frame, and the passes that build them.
#[derive(Debug)]
pub struct GpuClusters {
    layout: wgpu::BindGroupLayout,
    count: wgpu::ComputePipeline,
    prefix: wgpu::ComputePipeline,
    fill: wgpu::ComputePipeline,
    sort: wgpu::ComputePipeline,
    mark_tiles: wgpu::ComputePipeline,
    fill_walk: wgpu::ComputePipeline,
    visible_layout: wgpu::BindGroupLayout,
    bound_visible: wgpu::ComputePipeline,
    finish_visible: wgpu::ComputePipeline,
    design: AssignmentDesign,
    boxes: ClusterBoxes,
    /// The boxes the recorded frame tested (visible ones only where depth was given).
    boxes_used: ClusterBoxes,
    params: wgpu::Buffer,
    /// Each frame's list total, read back frames later without waiting.
    total_readback: AsyncReadback,
    frame: u64,
    buffers: Option<Buffers>,
    grid: Option<ClusterGrid>,
    /// The index-list capacity the next allocation uses.
    capacity: u32,
    /// The most the tile masks may take ([`TILE_MASK_BUDGET_BYTES`] unless set).
    mask_budget: u64,
    /// What lights add beyond their radius, if anything (recorded around the assignment).
    far_field: crate::GpuFarField,
    spot_culling: SpotCulling,
    far_field_wanted: Option<crate::FarField>,
}

impl GpuClusters {
    pub fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        view: &ViewBinding,
    ) -> GpuResult<Self> {
        Self::with_capacity(context, library, view, INITIAL_INDEX_CAPACITY)
    }

    /// As [`GpuClusters::new`] with a chosen initial index capacity (tests start small to
    /// force growth).
    pub fn with_capacity(
        context: &GpuContext,
        library: &ShaderLibrary,
        view: &ViewBinding,
        capacity: u32,
    ) -> GpuResult<Self> {
        let device = &context.device;
        let module = library.create_module(
            context,
            &crate::assign_program(),
            MaterialVariant::default(),
        )?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cluster assignment layout"),
            entries: &[
                manylights_gpu::binding::uniform_entry(0, wgpu::ShaderStages::COMPUTE),
                manylights_gpu::binding::storage_entry(1, wgpu::ShaderStages::COMPUTE, true),
                manylights_gpu::binding::storage_entry(2, wgpu::ShaderStages::COMPUTE, true),
                manylights_gpu::binding::storage_entry(3, wgpu::ShaderStages::COMPUTE, false),
                manylights_gpu::binding::storage_entry(4, wgpu::ShaderStages::COMPUTE, false),
                manylights_gpu::binding::storage_entry(5, wgpu::ShaderStages::COMPUTE, false),
                manylights_gpu::binding::storage_entry(6, wgpu::ShaderStages::COMPUTE, false),
                manylights_gpu::binding::storage_entry(7, wgpu::ShaderStages::COMPUTE, false),
                manylights_gpu::binding::storage_entry(8, wgpu::ShaderStages::COMPUTE, false),
                manylights_gpu::binding::storage_entry(9, wgpu::ShaderStages::COMPUTE, true),
                manylights_gpu::binding::storage_entry(10, wgpu::ShaderStages::COMPUTE, false),
                manylights_gpu::binding::storage_entry(11, wgpu::ShaderStages::COMPUTE, false),
            ],
        });
        let [count, prefix, fill, sort, mark_tiles, fill_walk] =
            context.scoped("creating the cluster assignment pipelines", || {
                manylights_gpu::binding::compute_pipelines(
                    device,
                    "cluster assignment",
                    &[&view.layout, &layout],
                    &module,
                    [
                        "count_lights",
                        "prefix_sum",
                        "fill_lists",
                        "sort_lists",
                        "mark_tiles",
                        "fill_cluster_lists",
                    ],
                )
            })?;
        let visible_module = library.create_module(
            context,
            &crate::visible_bounds_program(),
            MaterialVariant::default(),
        )?;
        let visible_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("visible cluster bounds layout"),
            entries: &[
                manylights_gpu::binding::uniform_entry(0, wgpu::ShaderStages::COMPUTE),
                manylights_gpu::binding::storage_entry(1, wgpu::ShaderStages::COMPUTE, false),
                manylights_gpu::binding::depth_texture_entry(2, wgpu::ShaderStages::COMPUTE),
                manylights_gpu::binding::storage_entry(3, wgpu::ShaderStages::COMPUTE, false),
                manylights_gpu::binding::storage_entry(4, wgpu::ShaderStages::COMPUTE, false),
            ],
        });
        let [bound_visible, finish_visible] =
            context.scoped("creating the visible-bounds pipeline", || {
                manylights_gpu::binding::compute_pipelines(
                    device,
                    "visible cluster bounds",
                    &[&view.layout, &visible_layout],
                    &visible_module,
                    ["bound_visible_samples", "finish_visible_bounds"],
                )
            })?;
        let params = manylights_gpu::binding::uniform_buffer(
            device,
            "cluster params",
            std::mem::size_of::<ClusterParamsUniform>(),
        );
        let total_readback =
            AsyncReadback::new(context, "cluster list total", 4, TOTAL_READBACK_SLOTS);
        Ok(Self {
            layout,
            count,
            prefix,
            fill,
            sort,
            mark_tiles,
            fill_walk,
            visible_layout,
            bound_visible,
            finish_visible,
            design: AssignmentDesign::default(),
            boxes: ClusterBoxes::default(),
            boxes_used: ClusterBoxes::Grid,
            params,
            total_readback,
            frame: 0,
            buffers: None,
            grid: None,
            capacity: capacity.max(1),
            mask_budget: TILE_MASK_BUDGET_BYTES,
            far_field: crate::GpuFarField::new(context, library, view)?,
            far_field_wanted: None,
            spot_culling: SpotCulling::default(),
        })
    }

    /// How the next frames cull spot lights (by their cone, the default, or by their
    /// range sphere, to measure what the cone saves); takes effect at the next `prepare`.
    pub fn set_spot_culling(&mut self, spot_culling: SpotCulling) {
        self.spot_culling = spot_culling;
    }

    /// Chooses the far field of the next frames (None: lights end at their radius); takes
    /// effect at the next `prepare`.
    pub fn set_far_field(&mut self, far_field: Option<crate::FarField>) {
        self.far_field_wanted = far_field;
    }

    /// The far field: its settings, the shading passes' buffers, its read-backs.
    pub fn far_field(&self) -> &crate::GpuFarField {
        &self.far_field
    }

    /// Chooses the design the next frames assign with (buffers are resized by `prepare`).
    pub fn set_design(&mut self, design: AssignmentDesign) {
        self.design = design;
    }

    /// Sets the most the tile masks may take (tests use a tiny budget so that walk groups
    /// share masks); applies from the next allocation.
    pub fn set_mask_budget(&mut self, bytes: u64) {
        self.mask_budget = bytes;
        self.buffers = None;
    }

    /// The tile masks' layout of the current buffers (`None` before `prepare`).
    pub fn mask_layout(&self) -> Option<MaskLayout> {
        self.buffers.as_ref().map(|buffers| buffers.masks)
    }

    /// Chooses the boxes the next frames test lights against.
    pub fn set_boxes(&mut self, boxes: ClusterBoxes) {
        self.boxes = boxes;
    }

    /// The boxes the last recorded frame tested: [`ClusterBoxes::VisibleSamples`] only if
    /// chosen and the frame's depth was given.
    pub fn boxes_used(&self) -> ClusterBoxes {
        self.boxes_used
    }

    /// Whether the next frames bound clusters by their visible samples when given depth.
    pub fn wants_visible_bounds(&self) -> bool {
        self.boxes == ClusterBoxes::VisibleSamples
    }

    /// The design the next `prepare` builds for.
    pub fn design(&self) -> AssignmentDesign {
        self.design
    }

    /// The design the current buffers and passes assign with (`None` before `prepare`):
    /// what a frame recorded now measures, whatever was asked since.
    pub fn prepared_design(&self) -> Option<AssignmentDesign> {
        self.buffers.as_ref().map(|buffers| buffers.design)
    }

    /// Sets this frame's grid (uploading the cluster bounds) and sizes the buffers for it
    /// and `light_count` lights.
    pub fn prepare(
        &mut self,
        context: &GpuContext,
        grid: &ClusterGrid,
        light_count: u32,
    ) -> GpuResult<()> {
        let clusters = grid.cluster_count();
        let needs_new = self.buffers.as_ref().is_none_or(|b| {
            b.clusters != clusters
                || b.tiles != grid.dims.x * grid.dims.y
                || b.lights < light_count.max(1)
                || b.capacity != self.capacity
                || b.design != self.design
        });
        if needs_new {
            self.buffers = Some(self.allocate(context, grid, light_count.max(1))?);
        }
        let Some(buffers) = &self.buffers else {
            return Err(GpuError::Unsupported("cluster buffers missing".into()));
        };
        // The bounds depend on the grid alone (its projection, size, range and slicing):
        // rebuilt and uploaded only when it changes, not every frame.
        if needs_new || self.grid != Some(*grid) {
            upload_bounds(context, &buffers.bounds, grid);
            upload_tile_slices(context, &buffers.tile_slices, grid);
        }
        let params = ClusterParamsUniform::new(
            grid,
            light_count,
            buffers.capacity,
            buffers.masks,
            self.spot_culling,
        );
        context
            .queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        self.grid = Some(*grid);
        self.far_field
            .prepare(context, self.far_field_wanted, light_count, clusters)
    }

    fn allocate(
        &self,
        context: &GpuContext,
        grid: &ClusterGrid,
        lights: u32,
    ) -> GpuResult<Buffers> {
        let clusters = grid.cluster_count();
        let tiles = grid.dims.x as u64 * grid.dims.y as u64;
        let masks = match self.design {
            AssignmentDesign::TileMasks => MaskLayout::for_grid(
                grid,
                lights,
                self.mask_budget
                    .min(context.device.limits().max_storage_buffer_binding_size),
            ),
            AssignmentDesign::AtomicFill => MaskLayout::default(),
        };
        let buffer =
            |label: &str, bytes: u64, extra: wgpu::BufferUsages| -> GpuResult<wgpu::Buffer> {
                context.check_buffer_size(label, bytes, true)?;
                context.scoped(&format!("allocating {label}"), || {
                    context.device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(label),
                        size: bytes.max(4),
                        usage: wgpu::BufferUsages::STORAGE | extra,
                        mapped_at_creation: false,
                    })
                })
            };
        let copy = wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC;
        Ok(Buffers {
            clusters,
            tiles: tiles as u32,
            lights,
            capacity: self.capacity,
            bounds: buffer("cluster bounds", clusters as u64 * 32, copy)?,
            visible_bounds: buffer("visible cluster bounds", clusters as u64 * 32, copy)?,
            tile_slices: buffer(
                "tile slice ranges",
                tiles * tile_slice_groups(grid) as u64 * 4,
                copy,
            )?,
            visible_tile_slices: buffer(
                "visible tile slice ranges",
                tiles * tile_slice_groups(grid) as u64 * 4,
                copy,
            )?,
            visible_box_codes: buffer("visible box codes", clusters as u64 * 24, copy)?,
            view_lights: buffer("view-space lights", lights as u64 * 16, copy)?,
            view_cones: buffer("view-space spot cones", lights as u64 * 16, copy)?,
            counts: buffer("cluster counts", clusters as u64 * 4, copy)?,
            offsets: buffer("cluster offsets", (clusters as u64 + 1) * 4, copy)?,
            indices: buffer(
                &format!("light index list ({} entries)", self.capacity),
                self.capacity as u64 * 4,
                copy,
            )?,
            tile_masks: buffer("tile light masks", masks.bytes(grid), copy)?,
            window_marks: buffer(
                "tile mask window marks",
                masks.window_mark_bytes(grid),
                copy,
            )?,
            masks,
            light_slices: buffer(
                "light candidate slices",
                match self.design {
                    AssignmentDesign::TileMasks => lights as u64 * 4,
                    AssignmentDesign::AtomicFill => 4,
                },
                copy,
            )?,
            design: self.design,
        })
    }

    fn buffers(&self) -> GpuResult<&Buffers> {
        self.buffers
            .as_ref()
            .ok_or_else(|| GpuError::Unsupported("GpuClusters::prepare was not called".into()))
    }

    pub fn grid(&self) -> Option<&ClusterGrid> {
        self.grid.as_ref()
    }

    /// Records the assignment pass for the lights (the frame's view must be uploaded).
    /// `visible_depth`: the frame's depth buffer, already holding its visible surfaces
    /// (the G-buffer or a depth pre-pass was recorded before); with it and
    /// [`ClusterBoxes::VisibleSamples`], clusters are first bounded by their samples. Each
    /// step is a compute pass of its own, timed by `timer` when given (`assign: ...`).
    pub fn record(
        &mut self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        view: &ViewBinding,
        lights: &GpuLights,
        visible_depth: Option<&wgpu::TextureView>,
        mut timer: Option<&mut GpuTimer>,
    ) -> GpuResult<()> {
        let visible_depth = visible_depth.filter(|_| self.wants_visible_bounds());
        self.boxes_used = if visible_depth.is_some() {
            ClusterBoxes::VisibleSamples
        } else {
            ClusterBoxes::Grid
        };
        // The far field's light tree or random ranges come first: stochastic culling assigns
        // the lights with their random ranges.
        self.far_field
            .record_lights(context, encoder, view, lights, timer.as_deref_mut())?;
        let assigned_lights = self.far_field.assignment_lights(lights);
        let buffers = self.buffers()?;
        let tested_bounds = self.bounds_buffer()?;
        let visible_group = visible_depth.map(|depth| {
            context
                .device
                .create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("visible cluster bounds"),
                    layout: &self.visible_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: self.params.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: buffers.visible_bounds.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::TextureView(depth),
                        },
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: buffers.visible_tile_slices.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 4,
                            resource: buffers.visible_box_codes.as_entire_binding(),
                        },
                    ],
                })
        });
        let bind_group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("cluster assignment"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: self.params.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: tested_bounds.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: assigned_lights.buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: buffers.view_lights.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: buffers.counts.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: buffers.offsets.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: buffers.indices.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 7,
                        resource: buffers.tile_masks.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 8,
                        resource: buffers.light_slices.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 9,
                        resource: match self.boxes_used {
                            ClusterBoxes::VisibleSamples => &buffers.visible_tile_slices,
                            ClusterBoxes::Grid => &buffers.tile_slices,
                        }
                        .as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 10,
                        resource: buffers.window_marks.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 11,
                        resource: buffers.view_cones.as_entire_binding(),
                    },
                ],
            });
        encoder.clear_buffer(&buffers.counts, 0, None);
        if visible_group.is_some() {
            encoder.clear_buffer(&buffers.visible_box_codes, 0, None);
        }
        if buffers.design == AssignmentDesign::TileMasks {
            encoder.clear_buffer(&buffers.tile_masks, 0, None);
            encoder.clear_buffer(&buffers.window_marks, 0, None);
        }
        let grid = self
            .grid
            .ok_or_else(|| GpuError::Unsupported("GpuClusters::prepare was not called".into()))?;
        let light_groups = lights.count.div_ceil(WORKGROUP_SIZE);
        // Each step is a compute pass of its own, timed by name ("assign: ..."): what the
        // assignment costs, step by step, is what this crate is measured by.
        let mut step = |name: &str,
                        pipeline: &wgpu::ComputePipeline,
                        group: &wgpu::BindGroup,
                        workgroups: [u32; 3]| {
            let mut pass = timed_compute_pass(encoder, timer.as_deref_mut(), name);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &view.bind_group, &[]);
            pass.set_bind_group(1, group, &[]);
            let [x, y, z] = workgroups;
            pass.dispatch_workgroups(x, y, z);
        };
        if let Some(visible_group) = &visible_group {
            // One workgroup per band of a tile and group of slices, then one per tile and
            // group of slices writes every cluster's box.
            let slice_groups = grid.dims.z.div_ceil(VISIBLE_BOUNDS_SLICES_PER_GROUP);
            step(
                "assign: bound visible samples",
                &self.bound_visible,
                visible_group,
                [
                    grid.dims.x,
                    grid.dims.y * VISIBLE_BOUNDS_BANDS_PER_TILE,
                    slice_groups,
                ],
            );
            step(
                "assign: finish visible boxes",
                &self.finish_visible,
                visible_group,
                [grid.dims.x, grid.dims.y, slice_groups],
            );
        }
        let lights_dispatch = [light_groups, 1, 1];
        match buffers.design {
            AssignmentDesign::TileMasks => {
                // One workgroup per tile and group of slices (each far below the 65,535
                // workgroups a dispatch dimension allows).
                let walks = [
                    grid.dims.x,
                    grid.dims.y,
                    grid.dims.z.div_ceil(SLICES_PER_WALK),
                ];
                if light_groups > 0 {
                    step(
                        "assign: mark tiles",
                        &self.mark_tiles,
                        &bind_group,
                        mark_tiles_dispatch(lights.count),
                    );
                }
                step("assign: list offsets", &self.prefix, &bind_group, [1, 1, 1]);
                if light_groups > 0 {
                    step("assign: fill lists", &self.fill_walk, &bind_group, walks);
                }
            }
            AssignmentDesign::AtomicFill => {
                let cluster_groups = buffers.clusters.div_ceil(WORKGROUP_SIZE);
                if light_groups > 0 {
                    step(
                        "assign: count lists",
                        &self.count,
                        &bind_group,
                        lights_dispatch,
                    );
                }
                step("assign: list offsets", &self.prefix, &bind_group, [1, 1, 1]);
                if light_groups > 0 {
                    step(
                        "assign: fill lists",
                        &self.fill,
                        &bind_group,
                        lights_dispatch,
                    );
                    step(
                        "assign: sort lists",
                        &self.sort,
                        &bind_group,
                        [cluster_groups, 1, 1],
                    );
                }
            }
        }
        self.far_field
            .record_cuts(context, encoder, view, tested_bounds, timer)?;
        let frame = self.frame + 1;
        let total_at = buffers.clusters as u64 * 4;
        let Some(buffers) = &self.buffers else {
            return Err(GpuError::Unsupported(
                "GpuClusters::prepare was not called".into(),
            ));
        };
        self.total_readback
            .record_copy(encoder, &buffers.offsets, total_at, frame);
        self.frame = frame;
        Ok(())
    }

    /// Call after the submission that holds the recorded assignment: asks for its list
    /// total to be mapped (read by a later [`GpuClusters::grow_for_earlier_frames`]).
    pub fn after_submit(&mut self) {
        self.total_readback.request_maps();
    }

    /// Before a frame, never waiting for the GPU: reads the list totals of earlier frames
    /// that finished; if one needed more entries than the index buffer holds, grows the
    /// buffer to the next power of two above it and returns the new capacity. (The frame
    /// that overflowed was shaded correctly anyway, from all lights where its lists were cut
    /// short.)
    pub fn grow_for_earlier_frames(&mut self, context: &GpuContext) -> GpuResult<Option<u32>> {
        let Some((_, bytes)) = self.total_readback.try_newest(context)? else {
            return Ok(None);
        };
        self.grow_to_hold(context, &bytes)
    }

    /// As [`GpuClusters::grow_for_earlier_frames`], waiting for the frames in flight
    /// (tests, and tools that must know a frame's lists fitted).
    pub fn wait_and_grow(&mut self, context: &GpuContext) -> GpuResult<Option<u32>> {
        let Some((_, bytes)) = self.total_readback.wait_newest(context)? else {
            return Ok(None);
        };
        self.grow_to_hold(context, &bytes)
    }

    fn grow_to_hold(&mut self, context: &GpuContext, bytes: &[u8]) -> GpuResult<Option<u32>> {
        let total = bytemuck::pod_read_unaligned::<u32>(&bytes[..4]);
        if total <= self.capacity {
            return Ok(None);
        }
        let grown = total.checked_next_power_of_two().unwrap_or(u32::MAX);
        log::info!(
            "light index list: {total} entries needed, growing from {} to {grown}",
            self.capacity
        );
        self.capacity = grown;
        if let (Some(grid), Some(buffers)) = (self.grid, &self.buffers) {
            let lights = buffers.lights;
            let buffers = self.allocate(context, &grid, lights)?;
            let params = ClusterParamsUniform::new(
                &grid,
                lights,
                self.capacity,
                buffers.masks,
                self.spot_culling,
            );
            // The new bounds buffers start empty.
            upload_bounds(context, &buffers.bounds, &grid);
            upload_tile_slices(context, &buffers.tile_slices, &grid);
            self.buffers = Some(buffers);
            // The light count in the uniform is rewritten by the next `prepare`.
            context
                .queue
                .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        }
        Ok(Some(grown))
    }

    /// Current capacity of the light index list, in entries.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Resources the shading passes read: params, offsets, indices.
    pub fn params_buffer(&self) -> &wgpu::Buffer {
        &self.params
    }

    /// The boxes the last recorded frame tested its lights against (see
    /// [`GpuClusters::boxes_used`]): `ClusterBounds` in `shaders/cluster/bounds.wgsl`.
    pub fn bounds_buffer(&self) -> GpuResult<&wgpu::Buffer> {
        let buffers = self.buffers()?;
        Ok(match self.boxes_used {
            ClusterBoxes::VisibleSamples => &buffers.visible_bounds,
            ClusterBoxes::Grid => &buffers.bounds,
        })
    }

    /// The boxes the last frame tested, read back ([`Aabb::EMPTY`] for a cluster no visible
    /// sample falls in): the CPU reference's input for that frame.
    pub fn read_bounds(&self, context: &GpuContext) -> GpuResult<Vec<Aabb>> {
        let raw: Vec<[f32; 8]> =
            manylights_gpu::targets::read_buffer(context, self.bounds_buffer()?)?;
        Ok(raw
            .into_iter()
            .take(self.buffers()?.clusters as usize)
            .map(|b| {
                if b[3] == 0.0 {
                    Aabb::EMPTY
                } else {
                    Aabb::new(
                        glam::Vec3::new(b[0], b[1], b[2]),
                        glam::Vec3::new(b[4], b[5], b[6]),
                    )
                }
            })
            .collect())
    }

    pub fn offsets_buffer(&self) -> GpuResult<&wgpu::Buffer> {
        Ok(&self.buffers()?.offsets)
    }

    pub fn indices_buffer(&self) -> GpuResult<&wgpu::Buffer> {
        Ok(&self.buffers()?.indices)
    }

    /// Each light in view space (xyz) with its radius (w), as assignment tested it.
    pub fn view_lights_buffer(&self) -> GpuResult<&wgpu::Buffer> {
        Ok(&self.buffers()?.view_lights)
    }

    /// Spot lights' view-space axes and outer sines, as the last assignment wrote them.
    pub fn view_cones_buffer(&self) -> GpuResult<&wgpu::Buffer> {
        Ok(&self.buffers()?.view_cones)
    }

    /// Every light's volume as the last assignment tested it (tests: the CPU reference
    /// assigns the same volumes).
    pub fn read_light_volumes(
        &self,
        context: &GpuContext,
        count: u32,
    ) -> GpuResult<Vec<crate::assign::LightVolume>> {
        let buffers = self.buffers()?;
        let spheres: Vec<[f32; 4]> =
            manylights_gpu::targets::read_buffer(context, &buffers.view_lights)?;
        let cones: Vec<[f32; 4]> =
            manylights_gpu::targets::read_buffer(context, &buffers.view_cones)?;
        Ok(spheres
            .into_iter()
            .zip(cones)
            .take(count as usize)
            .map(|(sphere, cone)| crate::assign::LightVolume::from_vec4s(sphere, cone))
            .collect())
    }

    /// The lists as built on the GPU (tests, statistics).
    pub fn read_lists(&self, context: &GpuContext) -> GpuResult<crate::assign::LightLists> {
        let buffers = self.buffers()?;
        let offsets: Vec<u32> = manylights_gpu::targets::read_buffer(context, &buffers.offsets)?;
        let offsets = offsets[..=buffers.clusters as usize].to_vec();
        let total = *offsets.last().unwrap_or(&0) as usize;
        if total > buffers.capacity as usize {
            return Err(GpuError::Unsupported(format!(
                "the last frame's lists ({total} entries) overflowed the index buffer ({} entries) and were cut short; the buffer has grown since, render again to read them",
                buffers.capacity
            )));
        }
        let mut indices: Vec<u32> =
            manylights_gpu::targets::read_buffer(context, &buffers.indices)?;
        indices.truncate(total);
        Ok(crate::assign::LightLists { offsets, indices })
    }

    /// The per-cluster list offsets only (statistics).
    pub fn read_offsets(&self, context: &GpuContext) -> GpuResult<Vec<u32>> {
        let buffers = self.buffers()?;
        let mut offsets: Vec<u32> =
            manylights_gpu::targets::read_buffer(context, &buffers.offsets)?;
        offsets.truncate(buffers.clusters as usize + 1);
        Ok(offsets)
    }

    /// The view-space spheres the GPU assigned (the CPU reference's exact input).
    pub fn read_view_lights(
        &self,
        context: &GpuContext,
        count: u32,
    ) -> GpuResult<Vec<crate::assign::ViewSphere>> {
        let buffers = self.buffers()?;
        let raw: Vec<[f32; 4]> =
            manylights_gpu::targets::read_buffer(context, &buffers.view_lights)?;
        Ok(raw
            .into_iter()
            .take(count as usize)
            .map(crate::assign::ViewSphere::from_vec4)
            .collect())
    }
}

#[cfg(test)]
mod layout_tests {
    use super::ClusterParamsUniform;
    use manylights_gpu::assert_wgsl_layout;

    #[test]
    fn cluster_params_match_wgsl() {
        assert_wgsl_layout!(
            crate::assign_program(),
            "cluster/cluster_index.wgsl",
            ClusterParams
                == ClusterParamsUniform {
                    dims: dims,
                    tile_and_screen: tile_and_screen,
                    z_params: z_params,
                    scheme_lights_capacity: scheme_lights_capacity,
                    mask_layout: mask_layout,
                    light_shapes: light_shapes,
                }
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ClusterSettings, TileSpec, ZRange};

    fn grid(slices: u32) -> ClusterGrid {
        let settings = ClusterSettings {
            tiles: TileSpec::Count { x: 16, y: 9 },
            z_slices: slices,
            z_scheme: ZScheme::Logarithmic,
            z_range: ZRange::Camera,
        };
        let projection = glam::camera::rh::proj::directx::perspective(1.0, 16.0 / 9.0, 0.1, 100.0);
        ClusterGrid::new(&settings, (1920, 1080), projection, 0.1, 100.0, None).expect("grid")
    }

    #[test]
    fn masks_are_per_walk_group_until_the_budget_makes_groups_share() {
        let grid = grid(48);
        // 5,000 lights: 157 words, 6 groups, 144 tiles: 0.5 MiB, one mask per group.
        let fine = MaskLayout::for_grid(&grid, 5_000, TILE_MASK_BUDGET_BYTES);
        assert_eq!(
            (fine.words, fine.walk_groups_per_mask, fine.masks_per_tile),
            (157, 1, 6)
        );
        assert_eq!(fine.window_mark_words, 1);
        assert_eq!(fine.bytes(&grid), 144 * 6 * 157 * 4);
        // 1,000,000 lights: 108 MiB per group would pass 64 MiB; pairs of groups share.
        let paired = MaskLayout::for_grid(&grid, 1_000_000, TILE_MASK_BUDGET_BYTES);
        assert_eq!((paired.walk_groups_per_mask, paired.masks_per_tile), (2, 3));
        assert!(paired.bytes(&grid) <= TILE_MASK_BUDGET_BYTES);
        // No budget at all still leaves one mask per tile.
        let coarsest = MaskLayout::for_grid(&grid, 1_000_000, 0);
        assert_eq!(
            (coarsest.walk_groups_per_mask, coarsest.masks_per_tile),
            (6, 1)
        );
    }
}
