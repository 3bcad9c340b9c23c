//! Clustered light assignment for manylights, usable in other engines on its own:
//! [`ClusterGrid`] (tiles x depth slices, three slicing schemes, depth range from the
//! camera or fitted to the scene), the view-space bounds of every cluster, the
//! fragment-to-cluster index, a CPU reference assignment ([`assign_lights`]), exact GPU
//! light lists ([`GpuClusters`]: in ascending light order, no cap, nothing dropped), and
//! per-frame statistics (on the GPU without stalling: [`GpuListStatistics`]). Clustered
//! pipelines import its shading loop and debug views ([`SHADERS`], [`ClusterView`]).
//!
//! ```no_run
//! use manylights_cluster::{ClusterGrid, ClusterSettings, assign_lights, view_spheres};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let (view, lights) = (glam::Mat4::IDENTITY, Vec::new());
//! let projection = glam::camera::rh::proj::directx::perspective(1.0, 16.0 / 9.0, 0.1, 100.0);
//! let grid = ClusterGrid::new(&ClusterSettings::default(), (1920, 1080), projection, 0.1, 100.0, None)?;
//! // The CPU reference: exact lists of the lights whose sphere meets each cluster's box.
//! let lists = assign_lights(&grid, &grid.cluster_bounds(), &view_spheres(&view, &lights));
//! println!("{} clusters, {} entries", lists.cluster_count(), lists.total());
//! # Ok(()) }
//! ```
//! On the GPU, [`GpuClusters`] builds the same lists: `examples/standalone_clusters.rs` does it on
//! a plain wgpu device and checks them against this reference.
//!
//! # In an engine's own renderer
//!
//! What it needs of the device: [`manylights_gpu::DeviceRequirements`], merged into the
//! engine's descriptor (WebGPU's default limits suffice up to about 100,000 lights). What it
//! gives: the lists, and [`ListedLights`], the WGSL and bind group an engine's own shader
//! walks them with, its own BRDF inside the loop ([`ListedLights::wgsl`]) or ours and our
//! loop in one call ([`ListedLights::clustered_radiance_wgsl`]). A frame, in order: the engine's depth pre-pass is recorded first, then
//! [`GpuClusters::prepare`] (CPU side: buffers, the grid's boxes), the assignment recorded
//! into the same encoder after the pre-pass, then the engine's shading pass, which binds
//! [`ListedLights::bind_group`]; after the submission [`GpuClusters::after_submit`], and
//! before a later frame [`GpuClusters::grow_for_earlier_frames`] (lists that outgrew their
//! buffer are grown without waiting; the frame that outgrew them was shaded from every
//! light its clusters' boxes meet, so nothing is dropped).
//!
//! ```no_run
//! # fn frame(
//! #     context: &manylights_gpu::GpuContext,
//! #     (view, projection): (glam::Mat4, glam::Mat4),
//! #     engine_lights: &[manylights_lights::Light],
//! #     (depth, depth_view): (&manylights_gpu::wgpu::Texture, &manylights_gpu::wgpu::TextureView),
//! #     encoder: &mut manylights_gpu::wgpu::CommandEncoder,
//! # ) -> Result<(), Box<dyn std::error::Error>> {
//! use manylights_cluster::{ClusterFrame, ClusterGrid, GpuClusters, ListedLights, VisibleDepth};
//! use manylights_gpu::{ShaderLibrary, ViewBinding, ViewUniform};
//! let library = ShaderLibrary::Embedded;
//! // Once: the camera block the assignment reads, the lights, the lists, the WGSL.
//! let camera = ViewUniform::from_matrices(view, projection, (depth.width(), depth.height()))?;
//! let view_binding = ViewBinding::new(context);
//! view_binding.update(context, &camera);
//! let lights = manylights_lights::GpuLights::new(context, engine_lights)?;
//! let mut clusters = GpuClusters::new(context, &library, &view_binding)?;
//! let listed = ListedLights::new(context, 1); // the engine's group index for the lists
//! let wgsl = listed.wgsl(&library)?; // put before the engine's own WGSL
//! // Each frame, after the engine's depth pre-pass is recorded:
//! let grid = ClusterGrid::for_view(&Default::default(), &camera, None)?;
//! clusters.prepare(context, &ClusterFrame::new(grid), &lights, Some(VisibleDepth::of(depth, depth_view)))?;
//! clusters.assignment()?.record(encoder, &view_binding, None);
//! let group = listed.bind_group(context, &clusters, &lights)?; // the shading pass binds it at 1
//! # let _ = (wgsl, group);
//! # Ok(()) }
//! ```

// Each module that drives a shader is named after it; the CPU references end in
// `_reference`.
mod assign;
mod assign_reference;
mod blended;
mod cluster_lights;
mod far_field;
mod grid;
mod listed_lights;
mod settings;
mod stats;
mod stats_reference;
mod visible_bounds;
pub use visible_bounds::VisibleDepth;

pub use assign::{
    AssignmentDesign, ClusterBoxes, ClusterFrame, ClusterParamsUniform, GpuClusters,
    INITIAL_INDEX_CAPACITY, ListsBuilt, MaskLayout, PreparedAssignment, Rebuilt, SORTED_LIST_LIMIT,
    TILE_MASK_BUDGET_BYTES,
};
pub use assign_reference::{
    LightLists, LightVolume, SpotCulling, ViewCone, ViewSphere, assign_light_volumes,
    assign_lights, candidate_range, compare_volumes_with_reference, compare_with_reference,
    sphere_box_margin, sphere_intersects_box, view_spheres, view_volumes,
};
pub use blended::blended_program;
pub use cluster_lights::{ClusterView, FIRST_PIPELINE_VIEW_CODE, LightLoop, ShadingOutput};
pub use far_field::{
    DEFAULT_FAR_CUT_SLOTS, FAR_ENTRY_EXACT, FarField, FarFieldMethod, FarNode, GpuFarField,
    MAX_FAR_CUT_SLOTS, MAX_TREE_LEVELS, OptionalFarField, tree_levels,
};
pub use grid::{
    ClusterGrid, ClusterSettings, DEFAULT_FIRST_SLICE_FAR, DEPTH_BOUNDS_INFLATION, GridError,
    MAX_CLUSTERS, TileSpec, ZRange, ZScheme,
};
pub use listed_lights::{ListedLights, MANYLIGHTS_GROUP, WGSL_PREFIX};
pub use settings::ClusteringSettings;
pub use stats::{GpuListStatistics, PreparedStatistics};

use manylights_gpu::{Program, ShaderDef, ShaderModules, shader_files};

/// This crate's WGSL: the grid and fragment-to-cluster index (`cluster_index.wgsl`), the
/// lists' bindings and their walk (`listed_lights.wgsl`, for any shader: [`ListedLights`]), the
/// shading loop over a cluster's list and the cluster debug views that clustered pipelines
/// import (`cluster_lights.wgsl`) and its tile-shared form for compute passes
/// (`tile_lights.wgsl`), the far field's terms (`far_terms.wgsl`, `far_shading.wgsl`), an
/// engine's one-call radiance (`clustered_radiance.wgsl`), the assignment and the
/// statistics.
pub static SHADERS: ShaderModules = ShaderModules {
    owner: "cluster",
    files: shader_files![
        "cluster/cluster_index.wgsl",
        "cluster/listed_lights.wgsl",
        "cluster/cluster_lights.wgsl",
        "cluster/tile_lights.wgsl",
        "cluster/bounds.wgsl",
        "cluster/scan.wgsl",
        "cluster/assign.wgsl",
        "cluster/visible_bounds.wgsl",
        "cluster/stats.wgsl",
        "cluster/far_nodes.wgsl",
        "cluster/far_terms.wgsl",
        "cluster/far_shading.wgsl",
        "cluster/clustered_radiance.wgsl",
        "cluster/far_field.wgsl",
        "cluster/blended.wgsl",
    ],
    uses: &[&manylights_lights::SHADERS, &manylights_visibility::SHADERS],
    constants: shader_constants,
};

/// The timed names of this crate's passes. The light assignment's steps are the stage
/// [`ASSIGN_STAGE`](passes::ASSIGN_STAGE) (`assign: ...`), the far field's `far field: ...`.
pub mod passes {
    use manylights_gpu::PassName;

    /// The stage every step of the light assignment belongs to ([`PassName::stage`]).
    pub const ASSIGN_STAGE: &str = "assign";
    pub const BOUND_VISIBLE_SAMPLES: PassName = PassName::new("assign: bound visible samples");
    pub const FINISH_VISIBLE_BOXES: PassName = PassName::new("assign: finish visible boxes");
    pub const MARK_TILES: PassName = PassName::new("assign: mark tiles");
    pub const COUNT_LISTS: PassName = PassName::new("assign: count lists");
    pub const LIST_OFFSETS: PassName = PassName::new("assign: list offsets");
    pub const FILL_LISTS: PassName = PassName::new("assign: fill lists");
    pub const SORT_LISTS: PassName = PassName::new("assign: sort lists");
    pub const FAR_FIELD_RANGES: PassName = PassName::new("far field: random ranges");
    /// The light tree's build, in three timed steps.
    pub const FAR_FIELD_KEYS: PassName = PassName::new("far field: light keys");
    pub const FAR_FIELD_SORT: PassName = PassName::new("far field: sort lights");
    pub const FAR_FIELD_NODES: PassName = PassName::new("far field: tree nodes");
    pub const FAR_FIELD_CUTS: PassName = PassName::new("far field: cut clusters");
    pub const STATISTICS: PassName = PassName::new("cluster statistics");
}

/// A compute pass of this crate, timed as `name` when a timer is given, with the view bound
/// at group 0, where every program here reads it.
pub(crate) fn view_pass<'e>(
    encoder: &'e mut manylights_gpu::wgpu::CommandEncoder,
    view: &manylights_gpu::ViewBinding,
    timer: Option<&mut manylights_gpu::GpuTimer>,
    name: manylights_gpu::PassName,
) -> manylights_gpu::wgpu::ComputePass<'e> {
    let mut pass = manylights_gpu::timed_compute_pass(encoder, timer, name);
    pass.set_bind_group(0, &view.bind_group, &[]);
    pass
}

// `tile_lights.wgsl` keeps a tile's kept candidates a bit a thread in two 32-bit masks.
const _: () = assert!(manylights_gpu::SCREEN_TILE * manylights_gpu::SCREEN_TILE == 64);

/// The constants this crate's WGSL reads (`#NAME`), each from its one Rust definition.
fn shader_constants() -> Vec<(String, ShaderDef)> {
    use ShaderDef::UInt;
    let constants = [
        ("LISTED_LIGHTS_GROUP", MANYLIGHTS_GROUP),
        ("CLUSTER_WORKGROUP_SIZE", assign::WORKGROUP_SIZE),
        ("SCAN_THREADS", assign::SCAN_THREADS),
        ("SORTED_LIST_LIMIT", SORTED_LIST_LIMIT as u32),
        ("MARK_LIGHTS_PER_GROUP", assign::MARK_LIGHTS_PER_GROUP),
        ("SLICES_PER_WALK", assign::SLICES_PER_WALK),
        ("TILE_SLICE_GROUP", visible_bounds::SLICES_PER_GROUP),
        ("Z_SCHEME_LINEAR", ZScheme::LINEAR_CODE),
        ("Z_SCHEME_LOGARITHMIC", ZScheme::LOGARITHMIC_CODE),
        ("Z_SCHEME_LOG_NEAR_SLICE", ZScheme::LOG_NEAR_SLICE_CODE),
        ("SPOT_CULLING_CONE", SpotCulling::Cone.shader_value()),
        ("FAR_FIELD_OFF", FarFieldMethod::OFF_CODE),
        ("FAR_FIELD_TREE", FarFieldMethod::Tree.shader_code()),
        (
            "FAR_FIELD_STOCHASTIC",
            FarFieldMethod::Stochastic.shader_code(),
        ),
        ("FAR_ENTRY_EXACT", FAR_ENTRY_EXACT),
        ("MAX_FAR_CUT_SLOTS", far_field::MAX_FAR_CUT_SLOTS),
        ("FAR_SORT_BLOCK", far_field::SORT_BLOCK),
        ("FAR_SORT_THREADS", far_field::SORT_THREADS),
        ("FAR_RADIX_BITS", far_field::RADIX_BITS),
        ("FAR_RADIX_BINS", far_field::RADIX_BINS as u32),
        (
            "STATISTICS_HISTOGRAM_BUCKETS",
            stats::HISTOGRAM_BUCKETS as u32,
        ),
    ];
    constants
        .into_iter()
        .map(|(name, value)| (name.to_string(), UInt(value)))
        .chain(ClusterView::shader_defs())
        .collect()
}

/// Light assignment (both designs' entry points).
pub fn assign_program() -> Program {
    Program::new("assign_lights", &SHADERS, "cluster/assign.wgsl")
}

/// The boxes of the clusters' visible samples, from the frame's depth.
pub fn visible_bounds_program() -> Program {
    Program::new("visible_bounds", &SHADERS, "cluster/visible_bounds.wgsl")
}

/// The visible-bounds passes over multisampled depth (MSAA): every sample of a pixel.
pub fn multisampled_visible_bounds_program() -> Program {
    Program::new(
        "visible_bounds_multisampled",
        &SHADERS,
        "cluster/visible_bounds.wgsl",
    )
    .with_def("MULTISAMPLED", manylights_gpu::ShaderDef::Bool(true))
}

/// The far field's passes: the light tree and its cuts, stochastic ranges.
pub fn far_field_program() -> Program {
    Program::new("far_field", &SHADERS, "cluster/far_field.wgsl")
}

/// Light-list statistics on the GPU.
pub fn statistics_program() -> Program {
    Program::new("cluster_stats", &SHADERS, "cluster/stats.wgsl")
}

/// Every program of this crate, in every variant (what `cargo xtask validate-shaders`
/// validates). The shading module is validated through the pipelines that import it.
pub fn programs() -> Vec<Program> {
    vec![
        assign_program(),
        visible_bounds_program(),
        multisampled_visible_bounds_program(),
        statistics_program(),
        far_field_program(),
        Program::new("listed_lights", &SHADERS, "cluster/listed_lights.wgsl"),
        Program::new("far_terms", &SHADERS, "cluster/far_terms.wgsl"),
        listed_lights::clustered_radiance_program(1, false, 2),
        listed_lights::clustered_radiance_program(1, true, 2),
        blended_program(LightLoop::plain()),
        blended_program(LightLoop::plain().with_shadows(manylights_visibility::Shadows::Exact)),
        blended_program(LightLoop::plain().with_shadows(manylights_visibility::Shadows::Rays(1))),
    ]
}
pub use stats_reference::{ClusterStats, false_positive_ratio};
