//! manylights' lighting group: every binding a light loop reads, by name, numbered from 0
//! with no gaps. manylights' own passes bind them all at [`crate::MANYLIGHTS_GROUP`] in one
//! bind group (`manylights_pipeline::FrameLighting`); an engine binds the parts it takes at
//! a group of its own with the same numbers (the cluster crate's `ListedLights`, the
//! visibility crate's `ShadowQueries`, [`crate::pbr_wgsl`]'s [`SPECULAR_TABLES`]).
//!
//! The numbers are declared once, in WGSL (`shaders/lights/lighting_group.wgsl`, whose
//! `NAME_BINDING` constants every module that declares one of these bindings imports);
//! this module mirrors them for the layouts, and its test reads that file.

/// The cluster grid's parameters (uniform).
pub const GRID: u32 = 0;
/// Each cluster's offset into the lists (storage).
pub const LIST_OFFSETS: u32 = 1;
/// The lists' light indices, back to back (storage).
pub const LIST_INDICES: u32 = 2;
/// The lights in world space, [`crate::GpuLights`] (storage).
pub const LIGHTS: u32 = 3;
/// The loop's parameters: the heatmap's scale and the light count (uniform).
pub const LOOP_PARAMS: u32 = 4;
/// The lights in view space, as assignment tested them (storage).
pub const VIEW_LIGHTS: u32 = 5;
/// The clusters' boxes (storage).
pub const CLUSTER_BOUNDS: u32 = 6;
/// The far field's parameters (uniform).
pub const FAR_FIELD: u32 = 7;
/// The light tree's nodes (storage).
pub const FAR_NODES: u32 = 8;
/// Each cluster's cut of the tree (storage).
pub const FAR_LISTS: u32 = 9;
/// The lights in the tree's order (storage).
pub const FAR_ORDER: u32 = 10;
/// The scene BVH's parameters (uniform); its three textures follow.
pub const BVH: u32 = 11;
/// The BVH's nodes (texture).
pub const BVH_NODES: u32 = 12;
/// The BVH's triangles (texture).
pub const BVH_TRIANGLES: u32 = 13;
/// The alpha-masked materials' coverage atlas (texture).
pub const COVERAGE_ATLAS: u32 = 14;
/// PBR's specular albedo and LTC tables, [`crate::SpecularTables`] (texture).
pub const SPECULAR_TABLES: u32 = 15;

/// Every binding of the group with its WGSL name (without `_BINDING`), in number order.
pub const ALL: [(&str, u32); 16] = [
    ("GRID", GRID),
    ("LIST_OFFSETS", LIST_OFFSETS),
    ("LIST_INDICES", LIST_INDICES),
    ("LIGHTS", LIGHTS),
    ("LOOP_PARAMS", LOOP_PARAMS),
    ("VIEW_LIGHTS", VIEW_LIGHTS),
    ("CLUSTER_BOUNDS", CLUSTER_BOUNDS),
    ("FAR_FIELD", FAR_FIELD),
    ("FAR_NODES", FAR_NODES),
    ("FAR_LISTS", FAR_LISTS),
    ("FAR_ORDER", FAR_ORDER),
    ("BVH", BVH),
    ("BVH_NODES", BVH_NODES),
    ("BVH_TRIANGLES", BVH_TRIANGLES),
    ("COVERAGE_ATLAS", COVERAGE_ATLAS),
    ("SPECULAR_TABLES", SPECULAR_TABLES),
];

/// The far field's bindings, which a loop without a far field never reads.
pub const FAR_FIELD_BINDINGS: [u32; 4] = [FAR_FIELD, FAR_NODES, FAR_LISTS, FAR_ORDER];

#[cfg(test)]
mod tests {
    /// The WGSL table and this one name the same bindings with the same numbers, and the
    /// numbers run from 0 with no gaps.
    #[test]
    fn the_wgsl_table_and_the_rust_one_agree_and_leave_no_gap() {
        let source = include_str!("../shaders/lights/lighting_group.wgsl");
        let module = naga::front::wgsl::parse_str(source).expect("lighting_group.wgsl parses");
        let mut declared: Vec<(String, u32)> = module
            .constants
            .iter()
            .map(|(_, constant)| {
                let name = constant.name.clone().expect("a named constant");
                let value = match module.global_expressions[constant.init] {
                    naga::Expression::Literal(naga::Literal::U32(value)) => value,
                    ref other => panic!("{name} is not a u32 literal: {other:?}"),
                };
                (name, value)
            })
            .collect();
        declared.sort_by_key(|(_, value)| *value);
        let expected: Vec<(String, u32)> = super::ALL
            .iter()
            .map(|(name, value)| (format!("{name}_BINDING"), *value))
            .collect();
        assert_eq!(declared, expected);
        for (index, (name, value)) in super::ALL.iter().enumerate() {
            assert_eq!(*value, index as u32, "{name} leaves a gap");
        }
    }
}
