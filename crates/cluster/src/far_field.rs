//! The far field: what lights add beyond their radius, approximated instead of dropped
//! (`shaders/cluster/far_field.wgsl`, `far_nodes.wgsl`).
//!
//! A light's unbounded contribution 1/max(d^2, eps) is split at its radius r into the
//! windowed falloff, window(d)^2/max(d^2, eps), which the cluster lists sum exactly, and
//! its complement, (1 - window(d)^2)/max(d^2, eps), which a far-field method approximates.
//! The two add up to the unbounded falloff, so a far field with tolerance 0 renders the
//! unbounded (inverse-square) image; the radius stays a dial (how much is exact), and the
//! tolerance is the second one (how well the rest is approximated).
//!
//! - [`FarFieldMethod::Tree`] (deterministic): a light tree rebuilt on the GPU every frame
//!   (an octree over the lights' box, 2^levels leaf cells a side, lights sorted by leaf cell
//!   with a stable radix sort; each node the sum of its lights: power, weighted centroid,
//!   box); each occupied cluster chooses a cut of it (lightcuts, Walter et al. 2005): the
//!   node with the largest error bound is split until every bound is at most
//!   `tolerance` x the cut's estimated total or its [`FarField::slots`] are used (the nodes
//!   left stay aggregates, so a pixel's cost is bounded); a leaf that may not be
//!   approximated is evaluated light by light (with tolerance 0, every node: exact).
//!   Bit-reproducible: no float atomics, every sum in a fixed order.
//! - [`FarFieldMethod::Stochastic`] (unbiased): stochastic light culling (Tokuyoshi and
//!   Harada 2016). Each light gets the random range r / sqrt(tolerance x xi) (at least r),
//!   xi uniform in (0, 1] from a hash of (seed, light); lists are built with those ranges;
//!   a listed light adds its complement divided by the probability that its range reaches
//!   the point. The expectation over seeds is the unbounded image; an image is reproducible
//!   for a seed, its error is noise.

use manylights_gpu::{
    GpuContext, GpuError, GpuResult, MaterialVariant, ShaderLibrary, ViewBinding, wgpu,
};
use manylights_lights::{GpuLights, Light};

mod record;
mod settings;
pub(crate) use record::PreparedFarField;
pub use settings::{FarField, FarFieldMethod, OptionalFarField};

/// Workgroups in one row of the cut pass's dispatch (one workgroup per cluster).
const CUT_ROW_WORKGROUPS: u32 = 32_768;

/// The most entries one cluster's cut may hold, whatever [`FarField::slots`] asks
/// (`MAX_CUT_SLOTS` in `shaders/cluster/far_nodes.wgsl`: the cut pass's workgroup arrays).
pub const MAX_FAR_CUT_SLOTS: u32 = 512;

/// The tree's entries per cluster unless chosen ([`FarField::slots`]).
pub const DEFAULT_FAR_CUT_SLOTS: u32 = 64;

/// The most levels the light tree has above its leaves: 64^3 leaf cells, 299,593 nodes.
pub const MAX_TREE_LEVELS: u32 = 6;

/// Threads of a sort workgroup and the lights per sort block (`SORT_THREADS` and `BLOCK` in
/// far_field.wgsl: each thread takes 16), bits per radix digit and the digit's bins. The
/// scan of the per-block histogram is one workgroup, so large blocks keep it short (H200,
/// 1,000,000 lights: the sort took 1.64 ms with 256-light blocks).
pub(crate) const SORT_THREADS: u32 = 256;
pub(crate) const SORT_BLOCK: u32 = SORT_THREADS * 16;
pub(crate) const RADIX_BITS: u32 = 5;
pub(crate) const RADIX_BINS: u64 = 1 << RADIX_BITS;

/// Bytes of a tree node (`FarNode` in far_nodes.wgsl).
const NODE_BYTES: u64 = 80;

/// Levels of the light tree above its leaves for `lights` lights: about two lights per
/// leaf cell, at most [`MAX_TREE_LEVELS`].
pub fn tree_levels(lights: u32) -> u32 {
    let mut levels = 1;
    while levels < MAX_TREE_LEVELS && (1u64 << (3 * levels)) * 2 < u64::from(lights) {
        levels += 1;
    }
    levels
}

/// Index of each level's first node (level 0, the leaves, first) and the node count last.
fn level_firsts(levels: u32) -> Vec<u32> {
    let mut firsts = vec![0u32];
    for level in 0..=levels {
        let nodes = 1u32 << (3 * (levels - level));
        firsts.push(firsts[level as usize] + nodes);
    }
    firsts
}

/// Mirrors `FarFieldParams` in far_nodes.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FarFieldUniform {
    setup: [u32; 4],
    sizes: [u32; 4],
    tolerance: [f32; 4],
    level_first: [u32; 8],
}

/// Mirrors `PassConstants` in far_field.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct PassConstants {
    value: u32,
    _pad: [u32; 3],
}

#[derive(Debug)]
struct TreeBuffers {
    lights: u32,
    levels: u32,
    clusters: u32,
    /// Entries a cluster's row of `far_lists` holds after its count.
    slots: u32,
    /// Sort keys and values, ping-pong pairs.
    keys: [wgpu::Buffer; 2],
    values: [wgpu::Buffer; 2],
    histogram: wgpu::Buffer,
    nodes: wgpu::Buffer,
    bounds_codes: wgpu::Buffer,
    far_lists: wgpu::Buffer,
    /// One small uniform per sort pass (its digit) and per inner level.
    sort_constants: Vec<wgpu::Buffer>,
    level_constants: Vec<wgpu::Buffer>,
}

impl TreeBuffers {
    fn sort_passes(&self) -> u32 {
        (3 * self.levels).div_ceil(RADIX_BITS)
    }

    /// The pair holding the sorted lights.
    fn sorted(&self) -> usize {
        (self.sort_passes() % 2) as usize
    }
}

/// The far field's GPU state: pipelines, parameters and (for the method in use) buffers.
/// Owned by [`crate::GpuClusters`], which records it around the assignment.
#[derive(Debug)]
pub struct GpuFarField {
    passes: FarFieldPasses,
    params: wgpu::Buffer,
    /// Bound when there is no tree (wgpu refuses absent bindings).
    placeholder: wgpu::Buffer,
    settings: Option<FarField>,
    /// The prepared frame's light count.
    light_count: u32,
    tree: Option<TreeBuffers>,
    cull_lights: Option<GpuLights>,
    /// Counts the allocations of `tree` and `cull_lights`.
    allocations: u64,
    /// The prepared frame's bind groups, with what they were built from.
    groups: Option<(FarBound, FarBindGroups)>,
}

/// What the far field's bind groups were built from: rebuilt when any of it changes.
#[derive(Debug, PartialEq)]
struct FarBound {
    method: Option<FarFieldMethod>,
    allocations: u64,
    lights: wgpu::Buffer,
    cluster_bounds: wgpu::Buffer,
}

/// The bind groups (group 1) of the far-field method in use.
#[derive(Debug)]
enum FarBindGroups {
    None,
    Stochastic(wgpu::BindGroup),
    Tree {
        keys: wgpu::BindGroup,
        sort_passes: Vec<wgpu::BindGroup>,
        leaves: wgpu::BindGroup,
        levels: Vec<wgpu::BindGroup>,
        cuts: wgpu::BindGroup,
    },
}

/// The lights with their stochastic ranges: rewritten from the animated lights each frame.
fn allocate_cull_lights(context: &GpuContext, lights: u32) -> GpuResult<GpuLights> {
    let bytes = u64::from(lights.max(1)) * std::mem::size_of::<Light>() as u64;
    context.check_buffer_size("stochastic light ranges", bytes, true)?;
    let buffer = context.scoped("allocating the stochastic light ranges", || {
        context.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lights with stochastic ranges"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    })?;
    Ok(GpuLights {
        buffer,
        count: lights,
        // Never animated: rewritten from the animated lights every frame.
        animated: 0,
        // Assignment's copy: no shading program is chosen by it.
        kinds: manylights_lights::LightKinds::ANY,
    })
}

/// The tree build's entry points, in the order they run.
const TREE_BUILD_PASSES: [&str; 7] = [
    "light_bounds",
    "light_keys",
    "sort_histogram",
    "sort_scan",
    "sort_scatter",
    "leaf_nodes",
    "inner_nodes",
];

/// The far field's compute passes: the tree's build (bounds, keys, the radix sort, leaves,
/// inner nodes), its cut per cluster, and stochastic culling's random ranges, each group
/// with its own layout after the view's.
#[derive(Debug)]
struct FarFieldPasses {
    build_layout: wgpu::BindGroupLayout,
    cut_layout: wgpu::BindGroupLayout,
    stochastic_layout: wgpu::BindGroupLayout,
    light_bounds: wgpu::ComputePipeline,
    light_keys: wgpu::ComputePipeline,
    sort_histogram: wgpu::ComputePipeline,
    sort_scan: wgpu::ComputePipeline,
    sort_scatter: wgpu::ComputePipeline,
    leaf_nodes: wgpu::ComputePipeline,
    inner_nodes: wgpu::ComputePipeline,
    cut_clusters: wgpu::ComputePipeline,
    stochastic_ranges: wgpu::ComputePipeline,
}

impl FarFieldPasses {
    fn new(context: &GpuContext, library: &ShaderLibrary, view: &ViewBinding) -> GpuResult<Self> {
        use manylights_gpu::binding::{ComputePasses, storage_entry, uniform_entry};
        let module = library.create_module(
            context,
            &crate::far_field_program(),
            MaterialVariant::default(),
        )?;
        let compute = wgpu::ShaderStages::COMPUTE;
        let shared = [&view.layout];
        let read = |binding| storage_entry(binding, compute, true);
        let write = |binding| storage_entry(binding, compute, false);
        let ComputePasses {
            layout: build_layout,
            pipelines:
                [
                    light_bounds,
                    light_keys,
                    sort_histogram,
                    sort_scan,
                    sort_scatter,
                    leaf_nodes,
                    inner_nodes,
                ],
        } = ComputePasses::new(
            context,
            &module,
            "far-field tree build",
            &shared,
            &[uniform_entry(0, compute), uniform_entry(1, compute)]
                .into_iter()
                .chain([2, 3, 4].map(read))
                .chain([5, 6, 7, 8, 9].map(write))
                .collect::<Vec<_>>(),
            TREE_BUILD_PASSES,
        )?;
        let cut_entries = [uniform_entry(0, compute), write(8), read(10), write(11)];
        let ComputePasses {
            layout: cut_layout,
            pipelines: [cut_clusters],
        } = ComputePasses::new(
            context,
            &module,
            "far-field cuts",
            &shared,
            &cut_entries,
            ["cut_clusters"],
        )?;
        let stochastic_entries = [uniform_entry(0, compute), read(2), write(12)];
        let ComputePasses {
            layout: stochastic_layout,
            pipelines: [stochastic_ranges],
        } = ComputePasses::new(
            context,
            &module,
            "far-field stochastic ranges",
            &shared,
            &stochastic_entries,
            ["stochastic_ranges"],
        )?;
        Ok(Self {
            build_layout,
            cut_layout,
            stochastic_layout,
            light_bounds,
            light_keys,
            sort_histogram,
            sort_scan,
            sort_scatter,
            leaf_nodes,
            inner_nodes,
            cut_clusters,
            stochastic_ranges,
        })
    }
}

impl GpuFarField {
    pub fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        view: &ViewBinding,
    ) -> GpuResult<Self> {
        let device = &context.device;
        let params = manylights_gpu::binding::uniform_buffer(
            device,
            "far-field params",
            std::mem::size_of::<FarFieldUniform>(),
        );
        let placeholder = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("far-field placeholder"),
            size: NODE_BYTES,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        Ok(Self {
            passes: FarFieldPasses::new(context, library, view)?,
            params,
            placeholder,
            settings: None,
            light_count: 0,
            tree: None,
            cull_lights: None,
            allocations: 0,
            groups: None,
        })
    }

    /// The far field of the frames recorded next (None: lights end at their radius).
    pub fn settings(&self) -> Option<FarField> {
        self.settings
    }

    /// Sizes the buffers for `settings`, `lights` and `clusters`, uploads the parameters
    /// and builds the bind groups (the cuts read `cluster_bounds`, the boxes the frame
    /// tests). Returns whether the bind groups were rebuilt (new buffers, lights or boxes).
    pub fn prepare(
        &mut self,
        context: &GpuContext,
        settings: Option<FarField>,
        lights: &GpuLights,
        clusters: u32,
        cluster_bounds: &wgpu::Buffer,
    ) -> GpuResult<bool> {
        if let Some(far) = &settings {
            far.validate().map_err(GpuError::Unsupported)?;
        }
        let light_count = lights.count;
        self.settings = settings;
        self.light_count = light_count;
        let method = settings.map(|s| s.method);
        let levels = tree_levels(light_count);
        if let Some(far) = settings.filter(|far| far.method == FarFieldMethod::Tree) {
            let fits = self.tree.as_ref().is_some_and(|tree| {
                tree.lights >= light_count.max(1)
                    && tree.levels == levels
                    && tree.clusters == clusters
                    && tree.slots == far.slots
            });
            if !fits {
                self.tree = Some(self.allocate_tree(
                    context,
                    light_count.max(1),
                    levels,
                    clusters,
                    far.slots,
                )?);
                self.allocations += 1;
            }
        } else {
            self.tree = None;
        }
        if method == Some(FarFieldMethod::Stochastic) {
            if self
                .cull_lights
                .as_ref()
                .is_none_or(|c| c.count != light_count)
            {
                self.cull_lights = Some(allocate_cull_lights(context, light_count)?);
                self.allocations += 1;
            }
        } else {
            self.cull_lights = None;
        }
        self.write_params(context, settings, light_count, levels);
        let bound = FarBound {
            method,
            allocations: self.allocations,
            lights: lights.buffer.clone(),
            cluster_bounds: cluster_bounds.clone(),
        };
        if self.groups.as_ref().is_some_and(|(last, _)| *last == bound) {
            return Ok(false);
        }
        let groups = self.bind_groups(context, &bound)?;
        self.groups = Some((bound, groups));
        Ok(true)
    }

    fn write_params(
        &self,
        context: &GpuContext,
        settings: Option<FarField>,
        lights: u32,
        levels: u32,
    ) {
        let firsts = level_firsts(levels);
        let mut level_first = [0u32; 8];
        for (slot, first) in level_first.iter_mut().zip(&firsts) {
            *slot = *first;
        }
        let uniform = FarFieldUniform {
            setup: [
                settings.map_or(FarFieldMethod::OFF_CODE, |s| s.method.shader_code()),
                lights,
                levels,
                settings.map_or(DEFAULT_FAR_CUT_SLOTS, |s| s.slots) + 1,
            ],
            sizes: [
                lights.div_ceil(SORT_BLOCK),
                firsts[levels as usize + 1],
                settings.map_or(0, |s| s.seed),
                (3 * levels).div_ceil(RADIX_BITS),
            ],
            tolerance: [settings.map_or(0.0, |s| s.tolerance), 0.0, 0.0, 0.0],
            level_first,
        };
        context
            .queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&uniform));
    }

    /// The bind groups of the method in use: the stochastic ranges', or the tree build's
    /// (writing pair 0 of keys, each sort pass reading one pair and writing the other, the
    /// node passes reading the sorted pair) and the cuts'.
    fn bind_groups(&self, context: &GpuContext, bound: &FarBound) -> GpuResult<FarBindGroups> {
        let bind_group =
            |label: &str, layout: &wgpu::BindGroupLayout, buffers: &[(u32, &wgpu::Buffer)]| {
                manylights_gpu::binding::bind_group(
                    context,
                    label,
                    layout,
                    buffers
                        .iter()
                        .map(|(binding, buffer)| (*binding, buffer.as_entire_binding())),
                )
            };
        match bound.method {
            None => Ok(FarBindGroups::None),
            Some(FarFieldMethod::Stochastic) => {
                let cull = self.cull_lights.as_ref().ok_or_else(not_prepared)?;
                Ok(FarBindGroups::Stochastic(bind_group(
                    "far-field stochastic ranges",
                    &self.passes.stochastic_layout,
                    &[(0, &self.params), (2, &bound.lights), (12, &cull.buffer)],
                )))
            }
            Some(FarFieldMethod::Tree) => {
                let tree = self.tree.as_ref().ok_or_else(not_prepared)?;
                let build_group = |read: usize, constants: &wgpu::Buffer| {
                    bind_group(
                        "far-field tree build",
                        &self.passes.build_layout,
                        &[
                            (0, &self.params),
                            (1, constants),
                            (2, &bound.lights),
                            (3, &tree.keys[read]),
                            (4, &tree.values[read]),
                            (5, &tree.keys[1 - read]),
                            (6, &tree.values[1 - read]),
                            (7, &tree.histogram),
                            (8, &tree.nodes),
                            (9, &tree.bounds_codes),
                        ],
                    )
                };
                let first_constants = tree
                    .sort_constants
                    .first()
                    .or(tree.level_constants.first())
                    .ok_or_else(not_prepared)?;
                let sorted = tree.sorted();
                Ok(FarBindGroups::Tree {
                    keys: build_group(1, first_constants),
                    sort_passes: (tree.sort_constants.iter().enumerate())
                        .map(|(pass, constants)| build_group(pass % 2, constants))
                        .collect(),
                    leaves: build_group(sorted, first_constants),
                    levels: (tree.level_constants.iter())
                        .map(|constants| build_group(sorted, constants))
                        .collect(),
                    cuts: bind_group(
                        "far-field cuts",
                        &self.passes.cut_layout,
                        &[
                            (0, &self.params),
                            (8, &tree.nodes),
                            (10, &bound.cluster_bounds),
                            (11, &tree.far_lists),
                        ],
                    ),
                })
            }
        }
    }

    fn allocate_tree(
        &self,
        context: &GpuContext,
        lights: u32,
        levels: u32,
        clusters: u32,
        slots: u32,
    ) -> GpuResult<TreeBuffers> {
        let buffer = |label: &str, bytes: u64| -> GpuResult<wgpu::Buffer> {
            context.check_buffer_size(label, bytes, true)?;
            context.scoped(&format!("allocating {label}"), || {
                context.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes.max(4),
                    usage: wgpu::BufferUsages::STORAGE
                        | wgpu::BufferUsages::COPY_DST
                        | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                })
            })
        };
        let constants = |label: &str, values: Vec<u32>| -> Vec<wgpu::Buffer> {
            values
                .into_iter()
                .map(|value| {
                    let buffer = manylights_gpu::binding::uniform_buffer(
                        &context.device,
                        label,
                        std::mem::size_of::<PassConstants>(),
                    );
                    let constants = PassConstants {
                        value,
                        _pad: [0; 3],
                    };
                    context
                        .queue
                        .write_buffer(&buffer, 0, bytemuck::bytes_of(&constants));
                    buffer
                })
                .collect()
        };
        let light_bytes = u64::from(lights) * 4;
        let blocks = u64::from(lights.div_ceil(SORT_BLOCK));
        let nodes = u64::from(level_firsts(levels)[levels as usize + 1]);
        let passes = (3 * levels).div_ceil(RADIX_BITS);
        Ok(TreeBuffers {
            lights,
            levels,
            clusters,
            slots,
            keys: [
                buffer("far-field sort keys", light_bytes)?,
                buffer("far-field sort keys (other)", light_bytes)?,
            ],
            values: [
                buffer("far-field light order", light_bytes)?,
                buffer("far-field light order (other)", light_bytes)?,
            ],
            histogram: buffer("far-field sort histogram", RADIX_BINS * blocks * 4)?,
            nodes: buffer("far-field tree nodes", nodes * NODE_BYTES)?,
            bounds_codes: buffer("far-field light box", 32)?,
            far_lists: buffer(
                "far-field cuts",
                u64::from(clusters) * u64::from(slots + 1) * 4,
            )?,
            sort_constants: constants(
                "far-field sort digit",
                (0..passes).map(|p| p * RADIX_BITS).collect(),
            ),
            level_constants: constants("far-field tree level", (1..=levels).collect()),
        })
    }

    /// The lights the assignment tests: with stochastic culling, the lights with their
    /// random ranges as radii; otherwise the lights themselves.
    pub fn assignment_lights<'a>(&'a self, lights: &'a GpuLights) -> &'a GpuLights {
        match (&self.settings, &self.cull_lights) {
            (Some(far), Some(cull)) if far.method == FarFieldMethod::Stochastic => cull,
            _ => lights,
        }
    }

    fn prepared_groups(&self) -> GpuResult<&FarBindGroups> {
        self.groups
            .as_ref()
            .map(|(_, groups)| groups)
            .ok_or_else(not_prepared)
    }

    /// What the shading passes bind (`far_field`, `far_nodes`, `far_lists`, `far_order` in
    /// cluster_lights.wgsl): placeholders when there is no tree.
    pub fn shading_buffers(&self) -> [&wgpu::Buffer; 4] {
        match &self.tree {
            Some(tree) if self.settings.is_some() => [
                &self.params,
                &tree.nodes,
                &tree.far_lists,
                &tree.values[tree.sorted()],
            ],
            _ => [
                &self.params,
                &self.placeholder,
                &self.placeholder,
                &self.placeholder,
            ],
        }
    }

    /// Each cluster's cut as the last frame chose it: entries (node index, exact flag in the
    /// top bit) per cluster (tests, statistics).
    pub fn read_cuts(&self, context: &GpuContext) -> GpuResult<Vec<Vec<u32>>> {
        let tree = self.tree.as_ref().ok_or_else(not_prepared)?;
        let raw: Vec<u32> = manylights_gpu::targets::read_buffer(context, &tree.far_lists)?;
        let row = (tree.slots + 1) as usize;
        Ok(raw
            .chunks(row)
            .take(tree.clusters as usize)
            .map(|chunk| chunk[1..=(chunk[0] as usize).min(row - 1)].to_vec())
            .collect())
    }

    /// The light tree's nodes as the last frame built them (tests).
    pub fn read_nodes(&self, context: &GpuContext) -> GpuResult<Vec<FarNode>> {
        let tree = self.tree.as_ref().ok_or_else(not_prepared)?;
        manylights_gpu::targets::read_buffer(context, &tree.nodes)
    }

    /// The lights in the tree's order, each with its leaf cell's Morton key (tests): the
    /// sort's output.
    pub fn read_order(&self, context: &GpuContext) -> GpuResult<Vec<(u32, u32)>> {
        let tree = self.tree.as_ref().ok_or_else(not_prepared)?;
        let read = |buffer: &wgpu::Buffer| -> GpuResult<Vec<u32>> {
            let mut values: Vec<u32> = manylights_gpu::targets::read_buffer(context, buffer)?;
            values.truncate(tree.lights as usize);
            Ok(values)
        };
        let keys = read(&tree.keys[tree.sorted()])?;
        let lights = read(&tree.values[tree.sorted()])?;
        Ok(keys.into_iter().zip(lights).collect())
    }

    /// Levels above the leaves of the tree in use (None without one).
    pub fn levels(&self) -> Option<u32> {
        self.tree.as_ref().map(|tree| tree.levels)
    }
}

/// A node of the light tree (`FarNode` in far_nodes.wgsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FarNode {
    pub centroid: [f32; 3],
    pub weight: f32,
    pub power: [f32; 3],
    pub radius: f32,
    pub box_min: [f32; 3],
    pub first: u32,
    pub box_max: [f32; 3],
    pub count: u32,
    pub dipole: [f32; 3],
    pub _pad: u32,
}

/// The flag of a cut entry evaluated light by light (`FAR_ENTRY_EXACT`).
pub const FAR_ENTRY_EXACT: u32 = 0x8000_0000;

fn not_prepared() -> GpuError {
    GpuError::Unsupported("GpuFarField::prepare was not called for this method".into())
}

#[cfg(test)]
mod layout_tests {
    use super::{FarFieldUniform, FarNode, NODE_BYTES, PassConstants};
    use manylights_gpu::assert_wgsl_layout;

    #[test]
    fn far_field_structs_match_wgsl() {
        let program = crate::far_field_program();
        assert_wgsl_layout!(
            program,
            "cluster/far_nodes.wgsl",
            FarFieldParams
                == FarFieldUniform {
                    setup: setup,
                    sizes: sizes,
                    tolerance: tolerance,
                    level_first: level_first,
                }
        );
        assert_wgsl_layout!(
            program,
            "cluster/far_nodes.wgsl",
            FarNode
                == FarNode {
                    centroid: centroid,
                    weight: weight,
                    power: power,
                    radius: radius,
                    box_min: box_min,
                    first: first,
                    box_max: box_max,
                    count: count,
                    dipole: dipole,
                    _pad: _pad,
                }
        );
        assert_eq!(NODE_BYTES as usize, std::mem::size_of::<FarNode>());
        assert_wgsl_layout!(
            program,
            "cluster/far_field.wgsl",
            PassConstants
                == PassConstants {
                    value: value,
                    _pad0: _pad,
                    _pad1: _pad + 4,
                    _pad2: _pad + 8,
                }
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_keep_about_two_lights_per_leaf_up_to_the_cap() {
        assert_eq!(tree_levels(0), 1);
        assert_eq!(tree_levels(16), 1);
        assert_eq!(tree_levels(17), 2);
        assert_eq!(tree_levels(5_000), 4);
        assert_eq!(tree_levels(100_000), 6);
        assert_eq!(tree_levels(1_000_000), MAX_TREE_LEVELS);
        assert_eq!(level_firsts(2), vec![0, 64, 72, 73]);
    }
}
