//! GPU light assignment: [`GpuClusters`] builds each frame's light lists, exact and in
//! ascending light order, from the frame's [`ClusterFrame`].
//!
//! # The frame's lifecycle
//! - [`GpuClusters::prepare`] takes the frame's clustering as one value ([`ClusterFrame`]:
//!   grid, design, boxes, far field, spot culling) with the lights and, when the pipeline lays
//!   it down first, the frame's depth. It compares them with the frame it prepared last and
//!   rebuilds only what changed ([`Rebuilt`]: buffers, the grid's boxes, the parameters, the
//!   bind groups), as Filament's Froxelizer does.
//! - [`GpuClusters::assignment`] then hands out the prepared passes, which record without
//!   failing or building anything and return the proof the shading takes ([`ListsBuilt`]).
//!
//! # The passes, in order (each a compute pass, timed by its name)
//! 1. `far field: light keys`, `far field: sort lights` and `far field: tree nodes` (the
//!    tree) or `far field: random ranges` ([`crate::GpuFarField`], `far_field.wgsl`), when
//!    the frame has a far field: stochastic culling assigns the lights with their random
//!    ranges.
//! 2. `assign: bound visible samples`, `assign: finish visible boxes`
//!    (`visible_bounds.rs`, `visible_bounds.wgsl`), with [`ClusterBoxes::VisibleSamples`]
//!    and the frame's depth: clusters no sample falls in list nothing.
//! 3. The lists (`assign.wgsl`), by one of two designs ([`AssignmentDesign`]):
//!    - tile masks: `assign: mark tiles`, `assign: list offsets`, `assign: fill lists`;
//!    - atomic fill: `assign: count lists`, `assign: list offsets`, `assign: fill lists`,
//!      `assign: sort lists`.
//! 4. `far field: cut clusters`, with the light tree: each occupied cluster's cut.
//! 5. The list total is copied out for a later frame to read (below).
//!
//! # Growing the index list without waiting
//! The list buffer starts at [`INITIAL_INDEX_CAPACITY`] entries and the fill writes only
//! what fits. Each frame copies the total into a small ring of mappable buffers; a later
//! frame reads it when the GPU got there ([`GpuClusters::grow_for_earlier_frames`], never
//! blocking), and the next `prepare` allocates the next power of two above it. The frame
//! that overflowed is not dropped or redone: the shading loop sees that a cluster's list was
//! cut short (its end lies past the capacity) and finds that cluster's lights again from all
//! lights, the same set in the same order, so the image is the same, only that frame is
//! slower. Steady frames pay a 4-byte copy.

use manylights_gpu::binding::EntryPointPipelines;
use manylights_gpu::{
    AsyncReadback, GpuContext, GpuError, GpuResult, MaterialVariant, ReservedSlot, ShaderLibrary,
    ViewBinding, wgpu,
};
use manylights_lights::GpuLights;

use crate::far_field::GpuFarField;
use crate::grid::ClusterGrid;
use crate::visible_bounds::{
    VisibleBoundsGroup, VisibleBoundsPasses, VisibleBoundsTargets, VisibleDepth, tile_slice_groups,
};

mod access;
mod design;
mod gpu_layout;
mod record;

pub use design::{AssignmentDesign, ClusterBoxes, ClusterFrame, Rebuilt};
use gpu_layout::{BOUNDS_BYTES, VIEW_LIGHT_BYTES, upload_bounds, upload_tile_slices};
pub use gpu_layout::{ClusterParamsUniform, MaskLayout, TILE_MASK_BUDGET_BYTES};
pub use record::{ListsBuilt, PreparedAssignment};

/// Entries the light-index list starts with (256 KiB). It grows on demand.
pub const INITIAL_INDEX_CAPACITY: u32 = 1 << 16;

/// With [`AssignmentDesign::AtomicFill`], lists up to this long come out in ascending light
/// order (`sort_lists` in `shaders/cluster/assign.wgsl`, `SORT_LIMIT`); longer lists hold
/// the same lights in the order the fill's atomics gave. Tile masks sort every list.
pub const SORTED_LIST_LIMIT: usize = 256;

/// Frames whose list totals may be in flight at once.
const TOTAL_READBACK_SLOTS: usize = 3;

/// Lights one workgroup of `mark_tiles` handles (`MARK_LIGHTS_PER_GROUP`: 16 lanes each).
pub(crate) const MARK_LIGHTS_PER_GROUP: u32 = 4;

/// Workgroups one dispatch dimension may hold (wgpu's default limit).
const MAX_WORKGROUPS_PER_DIMENSION: u32 = 65_535;

/// The `mark_tiles` dispatch for `light_count` lights: a row of workgroups, folded into a
/// second dimension past [`MAX_WORKGROUPS_PER_DIMENSION`] (1,000,000 lights need 250,000).
fn mark_tiles_dispatch(light_count: u32) -> [u32; 3] {
    let groups = light_count.div_ceil(MARK_LIGHTS_PER_GROUP);
    let x = groups.clamp(1, MAX_WORKGROUPS_PER_DIMENSION);
    [x, groups.div_ceil(x), 1]
}

/// Threads of the workgroup-wide prefix sum (`SCAN_THREADS` in scan.wgsl), shared by the
/// list offsets, the tile walk and the far field's sort.
pub(crate) const SCAN_THREADS: u32 = 256;

/// Mask words one window of the walk scans (`WALK_THREADS` in assign.wgsl).
const WALK_WINDOW_WORDS: u32 = SCAN_THREADS;

/// Slices one tile walk handles (`SLICES_PER_WALK` in assign.wgsl).
pub(crate) const SLICES_PER_WALK: u32 = 8;

/// Threads per workgroup of the light and cluster dispatches.
pub(crate) const WORKGROUP_SIZE: u32 = 64;

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
    /// Each light's view-space sphere and spot cone (`ViewLight` in `bounds.wgsl`: two
    /// vec4s; a cone's w = -1 for point lights).
    view_lights: wgpu::Buffer,
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

impl Buffers {
    /// Whether these buffers serve `grid` and `lights` lights with `capacity` entries by
    /// `design`.
    fn fit(
        &self,
        grid: &ClusterGrid,
        lights: u32,
        capacity: u32,
        design: AssignmentDesign,
    ) -> bool {
        self.clusters == grid.cluster_count()
            && self.tiles == grid.dims.x * grid.dims.y
            && self.lights >= lights.max(1)
            && self.capacity == capacity
            && self.design == design
    }

    /// The boxes a frame tests (`ClusterBounds` in `shaders/cluster/bounds.wgsl`) and the
    /// tiles' slice ranges that go with them.
    fn tested(&self, boxes: ClusterBoxes) -> (&wgpu::Buffer, &wgpu::Buffer) {
        match boxes {
            ClusterBoxes::VisibleSamples => (&self.visible_bounds, &self.visible_tile_slices),
            ClusterBoxes::Grid => (&self.bounds, &self.tile_slices),
        }
    }
}

/// What the bind groups were built from: they are rebuilt when any of it changes.
#[derive(Debug, PartialEq)]
struct BoundResources {
    /// Counts the buffer allocations: new buffers, new bind groups.
    buffers: u64,
    /// The lights the assignment reads (the frame's, or the far field's random ranges).
    assigned_lights: wgpu::Buffer,
    /// The depth the visible samples are bounded from, and its samples a pixel.
    visible_depth: Option<(wgpu::TextureView, u32)>,
    /// The blended objects' view-space boxes ([`GpuClusters::set_blended_bounds`]).
    blended: wgpu::Buffer,
}

/// The prepared frame's bind groups (group 1; group 0 is the view).
#[derive(Debug)]
struct BindGroups {
    bound: BoundResources,
    /// One per assignment entry point ([`AssignEntry`] order).
    assign: [wgpu::BindGroup; 6],
    /// With visible-sample boxes.
    visible: Option<VisibleBoundsGroup>,
}

/// The frame [`GpuClusters::prepare`] prepared last.
#[derive(Debug, Clone, Copy)]
struct PreparedFrame {
    frame: ClusterFrame,
    light_count: u32,
    /// The boxes the frame tests: visible ones only if asked for and the depth was given.
    boxes_used: ClusterBoxes,
    params: ClusterParamsUniform,
}

/// The assignment's entry points (`assign.wgsl`, both designs'), in pipeline order.
#[derive(Debug, Clone, Copy)]
enum AssignEntry {
    Count,
    Prefix,
    Fill,
    Sort,
    MarkTiles,
    FillWalk,
}

const ASSIGN_ENTRIES: [&str; 6] = [
    "count_lights",
    "prefix_sum",
    "fill_lists",
    "sort_lists",
    "mark_tiles",
    "fill_cluster_lists",
];

/// The assignment's pipelines. Their eleven bindings (ten storage buffers) are more than
/// the 8 storage buffers WebGPU guarantees a stage: on such a device each entry point's
/// layout holds only the bindings it uses.
#[derive(Debug)]
struct AssignmentPasses {
    pipelines: EntryPointPipelines<6>,
}

impl AssignmentPasses {
    fn new(context: &GpuContext, library: &ShaderLibrary, view: &ViewBinding) -> GpuResult<Self> {
        use manylights_gpu::binding::{storage_entry, uniform_entry};
        let composed = library.compose(&crate::assign_program(), MaterialVariant::default())?;
        let compute = wgpu::ShaderStages::COMPUTE;
        let read_only = [1, 2, 9];
        let storage_bindings = 1..=10;
        let table: Vec<wgpu::BindGroupLayoutEntry> = std::iter::once(uniform_entry(0, compute))
            .chain(
                storage_bindings
                    .clone()
                    .map(|binding| storage_entry(binding, compute, read_only.contains(&binding))),
            )
            .collect();
        // One layout of every binding where the device allows that many storage buffers a
        // stage (every native adapter here); a layout of only its bindings for each entry
        // point where it does not (WebGPU's 8). Not trimmed everywhere: six layouts of
        // different shapes, rebuilt with the light buffers, made lavapipe's resident
        // memory grow about 85 MiB per soak cycle (tests/soak.rs; the Rust heap and the
        // GPU allocations stayed flat), and one shape does not.
        let limit = context.device.limits().max_storage_buffers_per_shader_stage as usize;
        let used = if storage_bindings.count() <= limit {
            ASSIGN_ENTRIES.map(|_| table.iter().map(|entry| entry.binding).collect())
        } else {
            composed.bindings_used(ASSIGN_ENTRIES, 1)?
        };
        let module = library.create_composed_module(context, composed)?;
        let pipelines = context.scoped("creating the cluster assignment pipelines", || {
            EntryPointPipelines::new(
                context,
                "cluster assignment",
                &[&view.layout],
                &module,
                &table,
                ASSIGN_ENTRIES,
                used,
            )
        })?;
        Ok(Self { pipelines })
    }
}

fn not_prepared() -> GpuError {
    GpuError::Unsupported("the cluster frame was not prepared (GpuClusters::prepare)".into())
}

/// The GPU light lists of the current frame, and the passes that build them.
#[derive(Debug)]
pub struct GpuClusters {
    assignment: AssignmentPasses,
    visible_bounds: VisibleBoundsPasses,
    /// What lights add beyond their radius, if anything (recorded around the assignment).
    far_field: GpuFarField,
    params: wgpu::Buffer,
    /// Each frame's list total, read back frames later without waiting.
    total_readback: AsyncReadback,
    /// The slot the prepared frame copies its list total into (`None` with every slot in
    /// flight: that frame is not read back).
    total_slot: Option<ReservedSlot>,
    frame_number: u64,
    /// The index-list capacity the next allocation uses.
    capacity: u32,
    /// The most the tile masks may take ([`TILE_MASK_BUDGET_BYTES`] unless set).
    mask_budget: u64,
    buffers: Option<Buffers>,
    /// Counts the allocations of `buffers`.
    buffers_allocated: u64,
    bind_groups: Option<BindGroups>,
    prepared: Option<PreparedFrame>,
    /// The blended objects' view-space boxes the clusters' boxes are grown by.
    blended: BlendedBounds,
}

/// The view-space boxes of a scene's blended objects (`ClusterBounds` each, unused room
/// empty), which the visible samples' boxes are grown by (`visible_bounds.wgsl`).
#[derive(Debug)]
struct BlendedBounds {
    buffer: wgpu::Buffer,
    /// Boxes the buffer holds.
    capacity: usize,
}

impl BlendedBounds {
    fn new(context: &GpuContext, capacity: usize) -> Self {
        let capacity = capacity.max(1);
        Self {
            buffer: context.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("blended objects' view-space boxes"),
                size: (capacity * std::mem::size_of::<[[f32; 4]; 2]>()) as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            capacity,
        }
    }
}

impl GpuClusters {
    /// The view-space boxes (`(min, max)`) of the scene's blended objects this frame (none
    /// for most scenes): a blended surface lies in front of the depth the frame laid down,
    /// so with [`ClusterBoxes::VisibleSamples`] each cluster's box is grown by the part of
    /// its grid box inside any of them, and its lights reach the blended surfaces too.
    /// Called before [`GpuClusters::prepare`]; kept until called again.
    pub fn set_blended_bounds(&mut self, context: &GpuContext, boxes: &[(glam::Vec3, glam::Vec3)]) {
        if boxes.len() > self.blended.capacity {
            self.blended = BlendedBounds::new(context, boxes.len().next_power_of_two());
        }
        // Unused room stays empty (min.w 0): nothing meets it.
        let mut data = vec![[[0.0f32; 4]; 2]; self.blended.capacity];
        for (entry, (min, max)) in data.iter_mut().zip(boxes) {
            *entry = [min.extend(1.0).to_array(), max.extend(0.0).to_array()];
        }
        context
            .queue
            .write_buffer(&self.blended.buffer, 0, bytemuck::cast_slice(&data));
    }

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
        Ok(Self {
            assignment: AssignmentPasses::new(context, library, view)?,
            visible_bounds: VisibleBoundsPasses::new(context, library, view)?,
            far_field: GpuFarField::new(context, library, view)?,
            params: manylights_gpu::binding::uniform_buffer(
                &context.device,
                "cluster params",
                std::mem::size_of::<ClusterParamsUniform>(),
            ),
            total_readback: AsyncReadback::new(
                context,
                "cluster list total",
                4,
                TOTAL_READBACK_SLOTS,
            ),
            total_slot: None,
            frame_number: 0,
            capacity: capacity.max(1),
            mask_budget: TILE_MASK_BUDGET_BYTES,
            buffers: None,
            buffers_allocated: 0,
            bind_groups: None,
            prepared: None,
            blended: BlendedBounds::new(context, 1),
        })
    }

    /// Prepares the next recorded frame: `frame`'s clustering of `lights`, with
    /// `visible_depth` (the frame's depth, holding its visible surfaces before the
    /// assignment, when the pipeline lays it down first). Rebuilds only what differs from
    /// the frame prepared last, and says what that was. Depth of another size than the
    /// grid's screen is refused ([`GpuError::InvalidInput`](manylights_gpu::GpuError),
    /// naming both sizes), leaving the last prepared frame as it was.
    pub fn prepare(
        &mut self,
        context: &GpuContext,
        frame: &ClusterFrame,
        lights: &GpuLights,
        visible_depth: Option<VisibleDepth>,
    ) -> GpuResult<Rebuilt> {
        let grid = &frame.grid;
        // Before anything changes: a refused frame leaves the last one prepared.
        if let Some(depth) = &visible_depth {
            depth.check_against(grid)?;
        }
        let light_count = lights.count;
        let last = self.prepared.take();
        let mut rebuilt = Rebuilt::default();
        let buffers = self.buffers_fitting(context, frame, light_count, &mut rebuilt)?;
        // The grid's boxes depend on the grid alone (its projection, size, range and
        // slicing): uploaded when it changes, not every frame.
        if rebuilt.buffers || last.is_none_or(|last| last.frame.grid != *grid) {
            rebuilt.grid_boxes = true;
            upload_bounds(context, &buffers.bounds, grid);
            upload_tile_slices(context, &buffers.tile_slices, grid);
        }
        let params = ClusterParamsUniform::new(
            grid,
            light_count,
            buffers.capacity,
            buffers.masks,
            frame.spot_culling,
        );
        if last.is_none_or(|last| last.params != params) {
            rebuilt.params = true;
            let bytes = bytemuck::bytes_of(&params);
            context.queue.write_buffer(&self.params, 0, bytes);
        }
        if let Some(depth) = visible_depth {
            self.visible_bounds.prepare(context, depth)?;
        }
        let boxes_used = match (frame.boxes, visible_depth) {
            (ClusterBoxes::VisibleSamples, Some(_)) => ClusterBoxes::VisibleSamples,
            _ => ClusterBoxes::Grid,
        };
        let (tested_bounds, _) = buffers.tested(boxes_used);
        rebuilt.bind_groups |= self.far_field.prepare(
            context,
            frame.far_field,
            lights,
            grid.cluster_count(),
            tested_bounds,
        )?;
        let bound = BoundResources {
            buffers: self.buffers_allocated,
            assigned_lights: self.far_field.assignment_lights(lights).buffer.clone(),
            visible_depth: visible_depth
                .filter(|_| boxes_used == ClusterBoxes::VisibleSamples)
                .map(|depth| (depth.view.clone(), depth.samples)),
            blended: self.blended.buffer.clone(),
        };
        if self
            .bind_groups
            .as_ref()
            .is_none_or(|groups| groups.bound != bound)
        {
            rebuilt.bind_groups = true;
            self.bind_groups = Some(self.bind_groups_for(context, &buffers, bound, boxes_used));
        }
        self.buffers = Some(buffers);
        self.reserve_list_total();
        self.prepared = Some(PreparedFrame {
            frame: *frame,
            light_count,
            boxes_used,
            params,
        });
        Ok(rebuilt)
    }

    /// Takes the list total's readback slot now, so that recording holds the clusters
    /// shared; a frame prepared again before it was submitted keeps its slot.
    fn reserve_list_total(&mut self) {
        if self.total_slot.is_none() {
            self.frame_number += 1;
            self.total_slot = self.total_readback.reserve(self.frame_number);
        }
    }

    fn bind_groups_for(
        &self,
        context: &GpuContext,
        buffers: &Buffers,
        bound: BoundResources,
        boxes_used: ClusterBoxes,
    ) -> BindGroups {
        let (tested_bounds, tested_tile_slices) = buffers.tested(boxes_used);
        let table: Vec<(u32, wgpu::BindingResource)> = manylights_gpu::binding::buffers_in_order([
            &self.params,
            tested_bounds,
            &bound.assigned_lights,
            &buffers.view_lights,
            &buffers.counts,
            &buffers.offsets,
            &buffers.indices,
            &buffers.tile_masks,
            &buffers.light_slices,
            tested_tile_slices,
            &buffers.window_marks,
        ])
        .collect();
        let assign = self
            .assignment
            .pipelines
            .bind_groups(context, "cluster assignment", &table);
        let visible = bound.visible_depth.as_ref().map(|(view, samples)| {
            self.visible_bounds.bind_group(
                context,
                view,
                *samples,
                VisibleBoundsTargets {
                    params: &self.params,
                    boxes: &buffers.visible_bounds,
                    tile_slices: &buffers.visible_tile_slices,
                    box_codes: &buffers.visible_box_codes,
                    grid_bounds: &buffers.bounds,
                    blended: &bound.blended,
                },
            )
        });
        BindGroups {
            bound,
            assign,
            visible,
        }
    }

    /// The last frame's buffers where they fit `frame` and `light_count`, else new ones
    /// (said in `rebuilt`).
    fn buffers_fitting(
        &mut self,
        context: &GpuContext,
        frame: &ClusterFrame,
        light_count: u32,
        rebuilt: &mut Rebuilt,
    ) -> GpuResult<Buffers> {
        match self.buffers.take() {
            Some(buffers) if buffers.fit(&frame.grid, light_count, self.capacity, frame.design) => {
                Ok(buffers)
            }
            _ => {
                rebuilt.buffers = true;
                self.buffers_allocated += 1;
                self.allocate(context, &frame.grid, light_count.max(1), frame.design)
            }
        }
    }

    fn allocate(
        &self,
        context: &GpuContext,
        grid: &ClusterGrid,
        lights: u32,
        design: AssignmentDesign,
    ) -> GpuResult<Buffers> {
        let clusters = grid.cluster_count();
        let tiles = grid.dims.x as u64 * grid.dims.y as u64;
        let masks = match design {
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
            bounds: buffer("cluster bounds", clusters as u64 * BOUNDS_BYTES, copy)?,
            visible_bounds: buffer(
                "visible cluster bounds",
                clusters as u64 * BOUNDS_BYTES,
                copy,
            )?,
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
            view_lights: buffer("view-space lights", lights as u64 * VIEW_LIGHT_BYTES, copy)?,
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
                match design {
                    AssignmentDesign::TileMasks => lights as u64 * 4,
                    AssignmentDesign::AtomicFill => 4,
                },
                copy,
            )?,
            design,
        })
    }

    /// The prepared frame and what was built for it, or the error a frame recorded or read
    /// before any `prepare` gets.
    fn prepared(&self) -> GpuResult<(&PreparedFrame, &Buffers, &BindGroups)> {
        match (&self.prepared, &self.buffers, &self.bind_groups) {
            (Some(frame), Some(buffers), Some(groups)) => Ok((frame, buffers, groups)),
            _ => Err(not_prepared()),
        }
    }

    /// Call after the submission that holds the recorded assignment: asks for its list
    /// total to be mapped (read by a later [`GpuClusters::grow_for_earlier_frames`]).
    pub fn after_submit(&mut self) {
        self.total_slot = None;
        self.total_readback.request_maps();
    }

    /// Before a frame, never waiting for the GPU: reads the list totals of earlier frames
    /// that finished; if one needed more entries than the index buffer holds, returns the
    /// capacity (the next power of two above it) the next `prepare` grows the buffer to.
    /// (The frame that overflowed was shaded correctly anyway, from all lights where its
    /// lists were cut short.)
    pub fn grow_for_earlier_frames(&mut self, context: &GpuContext) -> GpuResult<Option<u32>> {
        let Some((_, bytes)) = self.total_readback.try_newest(context)? else {
            return Ok(None);
        };
        Ok(self.grow_to_hold(&bytes))
    }

    /// As [`GpuClusters::grow_for_earlier_frames`], waiting for the frames in flight
    /// (tests, and tools that must know a frame's lists fitted).
    pub fn wait_and_grow(&mut self, context: &GpuContext) -> GpuResult<Option<u32>> {
        manylights_gpu::block_on(self.wait_and_grow_async(context))
    }

    /// [`GpuClusters::wait_and_grow`] without blocking.
    pub async fn wait_and_grow_async(&mut self, context: &GpuContext) -> GpuResult<Option<u32>> {
        let Some((_, bytes)) = self.total_readback.wait_newest_async(context).await? else {
            return Ok(None);
        };
        Ok(self.grow_to_hold(&bytes))
    }

    fn grow_to_hold(&mut self, bytes: &[u8]) -> Option<u32> {
        let total = bytemuck::pod_read_unaligned::<u32>(&bytes[..4]);
        if total <= self.capacity {
            return None;
        }
        let grown = total.checked_next_power_of_two().unwrap_or(u32::MAX);
        log::info!(
            "light index list: {total} entries needed, growing from {} to {grown}",
            self.capacity
        );
        self.capacity = grown;
        Some(grown)
    }
}
