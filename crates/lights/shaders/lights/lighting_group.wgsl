// manylights' lighting group: every binding a light loop reads, by name, numbered from 0
// with no gaps. manylights' own passes bind them all at group 3 in one bind group
// (`pipeline::FrameLighting`); an engine binds the parts it takes at a group of its own
// (`cluster::ListedLights`, `visibility::ShadowQueries`, `lights::pbr_wgsl`) with the same
// numbers. Each module that declares a binding imports its number from here, and
// `lights::lighting_group` mirrors the table in Rust (its test reads this file).
//
// Who declares each binding:
//   the lists (cluster/listed_lights.wgsl)       GRID .. CLUSTER_BOUNDS, LIGHTS
//   the loop's parameters (cluster/cluster_lights.wgsl, naive/naive.wgsl)  LOOP_PARAMS
//   the far field (cluster/far_terms.wgsl)       FAR_FIELD .. FAR_ORDER
//   the scene's BVH (visibility/bvh.wgsl)        BVH .. COVERAGE_ATLAS
//   PBR's fits (lights/specular_albedo.wgsl)     SPECULAR_TABLES

// The cluster grid (`ClusterParams`).
const GRID_BINDING: u32 = 0u;
// Each cluster's offset into the lists.
const LIST_OFFSETS_BINDING: u32 = 1u;
// The lists' light indices, back to back.
const LIST_INDICES_BINDING: u32 = 2u;
// The lights, in world space.
const LIGHTS_BINDING: u32 = 3u;
// The loop's parameters: the heatmap's scale and the light count.
const LOOP_PARAMS_BINDING: u32 = 4u;
// The lights in view space and the clusters' boxes, as assignment tested them.
const VIEW_LIGHTS_BINDING: u32 = 5u;
const CLUSTER_BOUNDS_BINDING: u32 = 6u;
// The far field's parameters, the light tree's nodes, each cluster's cut and the lights
// in the tree's order.
const FAR_FIELD_BINDING: u32 = 7u;
const FAR_NODES_BINDING: u32 = 8u;
const FAR_LISTS_BINDING: u32 = 9u;
const FAR_ORDER_BINDING: u32 = 10u;
// The scene's BVH: its parameters, its nodes, its triangles and the alpha-masked
// materials' coverage atlas.
const BVH_BINDING: u32 = 11u;
const BVH_NODES_BINDING: u32 = 12u;
const BVH_TRIANGLES_BINDING: u32 = 13u;
const COVERAGE_ATLAS_BINDING: u32 = 14u;
// PBR's specular albedo and LTC tables.
const SPECULAR_TABLES_BINDING: u32 = 15u;
