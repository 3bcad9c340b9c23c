// The directional albedo of PBR's specular lobe, fitted (`lights::specular_albedo`, which
// generates the fit from the f64 twin's integrals and evaluates it the same way): what
// the diffuse term weights itself by to conserve energy (`surface_for_loop` in
// brdf.wgsl).
//
// E(mu) = F0 A(mu) + B(mu) at cos angle mu and perceptual roughness r, A and B each a sum
// of six functions of mu, 1, mu, p^2, p^4, p^8 and p^16 with p = 1 - mu, with
// coefficients per roughness row (uniform in r over [0.045, 1]) interpolated linearly.
// A row is three texels of f32 bits: A's six coefficients, then B's six. A pixel reads
// its two rows once; a light then costs a few multiply-adds (`LitSurface`).

#import manylights::lights::lighting_group::SPECULAR_TABLES_BINDING

// Bound at group 3 beside the lights by every lighting pass (`lights::SpecularTables`;
// in an engine, at its group: `lights::pbr_wgsl`),
// with the linearly transformed cosines' matrices after each row's albedo (`ltc_entries`).
@group(#SPECULAR_TABLES_GROUP) @binding(SPECULAR_TABLES_BINDING) var specular_tables: texture_2d<u32>;

const ROUGHNESS_CELLS: u32 = #SPECULAR_ALBEDO_ROUGHNESS_CELLS;
const LTC_VIEW_CELLS: u32 = #LTC_VIEW_CELLS;
const LTC_FIRST_TEXEL: u32 = #LTC_FIRST_TEXEL;
// The first row's roughness: GGX's floor (`lights::specular_albedo::ROUGHNESS_LOW`).
const ROUGHNESS_LOW: f32 = 0.045;

// A's and B's coefficients at one roughness: the first four of each, then the last two.
struct AlbedoFit {
    a_first: vec4<f32>,
    a_last: vec2<f32>,
    b_first: vec4<f32>,
    b_last: vec2<f32>,
}

// The basis functions at `mu`: the first four, then the last two.
struct AlbedoBasis {
    first: vec4<f32>,
    last: vec2<f32>,
}

// The row at or below perceptual roughness `roughness` (both fits share the rows) and the
// position towards the next.
struct RoughnessCell {
    row: u32,
    t: f32,
}

fn roughness_cell(roughness: f32) -> RoughnessCell {
    let y = saturate((roughness - ROUGHNESS_LOW) / (1.0 - ROUGHNESS_LOW)) * f32(ROUGHNESS_CELLS);
    let row = min(u32(y), ROUGHNESS_CELLS - 1u);
    return RoughnessCell(row, y - f32(row));
}

// The coefficients at perceptual roughness `roughness`, between its two rows.
fn albedo_fit(roughness: f32) -> AlbedoFit {
    let at = roughness_cell(roughness);
    let row = at.row;
    let t = at.t;
    let low_0 = bitcast<vec4<f32>>(textureLoad(specular_tables, vec2<u32>(0u, row), 0));
    let low_1 = bitcast<vec4<f32>>(textureLoad(specular_tables, vec2<u32>(1u, row), 0));
    let low_2 = bitcast<vec4<f32>>(textureLoad(specular_tables, vec2<u32>(2u, row), 0));
    let high_0 = bitcast<vec4<f32>>(textureLoad(specular_tables, vec2<u32>(0u, row + 1u), 0));
    let high_1 = bitcast<vec4<f32>>(textureLoad(specular_tables, vec2<u32>(1u, row + 1u), 0));
    let high_2 = bitcast<vec4<f32>>(textureLoad(specular_tables, vec2<u32>(2u, row + 1u), 0));
    let texel_0 = low_0 + (high_0 - low_0) * t;
    let texel_1 = low_1 + (high_1 - low_1) * t;
    let texel_2 = low_2 + (high_2 - low_2) * t;
    return AlbedoFit(texel_0, texel_1.xy, vec4<f32>(texel_1.zw, texel_2.xy), texel_2.zw);
}

fn albedo_basis(mu: f32) -> AlbedoBasis {
    let p = 1.0 - saturate(mu);
    let p2 = p * p;
    let p4 = p2 * p2;
    let p8 = p4 * p4;
    return AlbedoBasis(vec4<f32>(1.0, saturate(mu), p2, p4), vec2<f32>(p8, p8 * p8));
}

// Each basis function's cosine-weighted average, 2 int f(mu) mu dmu
// (`lights::specular_albedo::BASIS_AVERAGES`).
const BASIS_AVERAGES_FIRST: vec4<f32> = vec4<f32>(1.0, 2.0 / 3.0, 2.0 / 12.0, 2.0 / 30.0);
const BASIS_AVERAGES_LAST: vec2<f32> = vec2<f32>(2.0 / 90.0, 2.0 / 306.0);

// E(mu) per channel for specular colour `f0`.
fn specular_albedo(f0: vec3<f32>, mu: f32, fit: AlbedoFit) -> vec3<f32> {
    let at = albedo_basis(mu);
    let a = dot(fit.a_first, at.first) + dot(fit.a_last, at.last);
    let b = dot(fit.b_first, at.first) + dot(fit.b_last, at.last);
    return f0 * a + b;
}

// E_avg per channel for specular colour `f0`: the fit's own average, exactly.
fn specular_albedo_average(f0: vec3<f32>, fit: AlbedoFit) -> vec3<f32> {
    let a = dot(fit.a_first, BASIS_AVERAGES_FIRST) + dot(fit.a_last, BASIS_AVERAGES_LAST);
    let b = dot(fit.b_first, BASIS_AVERAGES_FIRST) + dot(fit.b_last, BASIS_AVERAGES_LAST);
    return f0 * a + b;
}

// The linearly transformed cosines' M^-1 (`lights::ltc`) at cos view angle `mu` and
// perceptual roughness `roughness`, as its entries (m00, m02, m20, m22; m11 = 1): bilinear
// between the four nodes around it, the columns uniform in sqrt(1 - mu), after the
// albedo's texels in each row. Read once per pixel (`LitSurface.to_cosine`).
fn ltc_entries(mu: f32, roughness: f32) -> vec4<f32> {
    let at = roughness_cell(roughness);
    let row = at.row;
    let x = sqrt(saturate(1.0 - mu)) * f32(LTC_VIEW_CELLS);
    let column = min(u32(x), LTC_VIEW_CELLS - 1u);
    let t = x - f32(column);
    let first = LTC_FIRST_TEXEL + column;
    let low_near = bitcast<vec4<f32>>(textureLoad(specular_tables, vec2<u32>(first, row), 0));
    let low_far = bitcast<vec4<f32>>(textureLoad(specular_tables, vec2<u32>(first + 1u, row), 0));
    let high_near = bitcast<vec4<f32>>(textureLoad(specular_tables, vec2<u32>(first, row + 1u), 0));
    let high_far = bitcast<vec4<f32>>(textureLoad(specular_tables, vec2<u32>(first + 1u, row + 1u), 0));
    return mix(mix(low_near, low_far, t), mix(high_near, high_far, t), at.t);
}
