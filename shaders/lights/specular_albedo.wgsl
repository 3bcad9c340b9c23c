// The directional albedo of PBR's specular lobe, tabulated (`lights::specular_albedo`, which
// generates the table from the f64 twin's integrals and reads it back the same way): what
// the diffuse term weights itself by to conserve energy (`pbr_brdf` in shading.wgsl).
//
// E(mu) = F0 A + B at cos angle mu and perceptual roughness r, (A, B) interpolated
// bilinearly between nodes uniform in mu over [0, 1] and in r over [0.045, 1]. One texel a
// cell: its four corners' (A, B) as f16 pairs, so a lookup is one load; the last column
// holds the rows' cosine-weighted averages E_avg.

// Bound at group 3 beside the lights by every lighting pass (`lights::SpecularAlbedoTexture`).
@group(3) @binding(16) var specular_albedo_table: texture_2d<u32>;

const MU_CELLS: u32 = #SPECULAR_ALBEDO_MU_CELLS;
const ROUGHNESS_CELLS: u32 = #SPECULAR_ALBEDO_ROUGHNESS_CELLS;
// The first row's roughness: GGX's floor (`lights::specular_albedo::ROUGHNESS_LOW`).
const ROUGHNESS_LOW: f32 = 0.045;

// A roughness's row of the table and its position between that row and the next.
struct TableRow {
    row: u32,
    t: f32,
}

fn table_row(roughness: f32) -> TableRow {
    let y = saturate((roughness - ROUGHNESS_LOW) / (1.0 - ROUGHNESS_LOW)) * f32(ROUGHNESS_CELLS);
    let row = min(u32(y), ROUGHNESS_CELLS - 1u);
    return TableRow(row, y - f32(row));
}

// E(mu) per channel for specular colour `f0` on the row `at`.
fn specular_albedo(f0: vec3<f32>, mu: f32, at: TableRow) -> vec3<f32> {
    let x = saturate(mu) * f32(MU_CELLS);
    let column = min(u32(x), MU_CELLS - 1u);
    let s = x - f32(column);
    let corners = textureLoad(specular_albedo_table, vec2<u32>(column, at.row), 0);
    let low = mix(unpack2x16float(corners.x), unpack2x16float(corners.y), s);
    let high = mix(unpack2x16float(corners.z), unpack2x16float(corners.w), s);
    let terms = mix(low, high, at.t);
    return f0 * terms.x + terms.y;
}

// E_avg per channel for specular colour `f0` on the row `at`.
fn specular_albedo_average(f0: vec3<f32>, at: TableRow) -> vec3<f32> {
    let rows = textureLoad(specular_albedo_table, vec2<u32>(MU_CELLS, at.row), 0);
    let terms = mix(unpack2x16float(rows.x), unpack2x16float(rows.y), at.t);
    return f0 * terms.x + terms.y;
}
