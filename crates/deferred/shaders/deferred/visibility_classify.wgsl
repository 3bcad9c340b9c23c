// The visibility buffer's classification: which 8x8 tiles each material covers, so that
// the resolve runs once per material (with that material's bind group: WebGPU has no
// bindless textures) over only its tiles. Four dispatches, in order:
//   cs_reset  (a thread per material): zero the counts, set the dispatch's y and z to 1;
//   cs_count  (a workgroup per tile): each material seen in the tile counts the tile once;
//   cs_offsets (one thread): each material's first slot in the tile list;
//   cs_fill   (a workgroup per tile): each material seen in the tile appends it.
// A material's record starts with its indirect dispatch's arguments (x: its tile count).
// No pass writes the G-buffer where no surface was drawn: lighting reads coverage from
// depth and never reads the G-buffer there.

#import manylights::deferred::visibility_geometry::instance_material

// The raster's output: instance and triangle, NO_SURFACE where nothing was drawn.
@group(0) @binding(0) var visibility: texture_2d<u32>;
@group(0) @binding(1) var<storage, read_write> material_tiles: array<MaterialTiles>;
// Every material's tiles, material after material; a tile as x | y << 16.
@group(0) @binding(2) var<storage, read_write> tile_list: array<u32>;

// 32 bytes a material (`MATERIAL_TILES_STRIDE` in the crate).
struct MaterialTiles {
    // The indirect dispatch's arguments: one workgroup per tile.
    tile_count: atomic<u32>,
    dispatch_y: u32,
    dispatch_z: u32,
    // The material's first entry in `tile_list`.
    first: u32,
    // Entries appended so far by cs_fill.
    filled: atomic<u32>,
    // Pads the record to 32 bytes (a vec3 here would align to 16 and make it 48).
    padding: array<u32, 3>,
}

const NO_SURFACE: u32 = 0xffffffffu;
const NO_MATERIAL: u32 = 0xffffffffu;

@compute @workgroup_size(64)
fn cs_reset(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&material_tiles) {
        return;
    }
    atomicStore(&material_tiles[id.x].tile_count, 0u);
    material_tiles[id.x].dispatch_y = 1u;
    material_tiles[id.x].dispatch_z = 1u;
    material_tiles[id.x].first = 0u;
    atomicStore(&material_tiles[id.x].filled, 0u);
}

// The material seen at each pixel of the tile.
var<workgroup> tile_materials: array<u32, 64>;

// This pixel's material, and whether it is the first pixel of the tile (in row order)
// with it: the one that counts or appends the tile for the material.
fn first_of_its_material(pixel: vec2<u32>, index: u32) -> u32 {
    let size = textureDimensions(visibility);
    var material = NO_MATERIAL;
    if all(pixel < size) {
        let instance = textureLoad(visibility, pixel, 0).x;
        if instance != NO_SURFACE {
            material = instance_material(instance);
        }
    }
    tile_materials[index] = material;
    workgroupBarrier();
    if material == NO_MATERIAL {
        return NO_MATERIAL;
    }
    for (var earlier = 0u; earlier < index; earlier += 1u) {
        if tile_materials[earlier] == material {
            return NO_MATERIAL;
        }
    }
    return material;
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_count(
    @builtin(workgroup_id) tile: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
    @builtin(global_invocation_id) pixel: vec3<u32>,
) {
    let material = first_of_its_material(pixel.xy, index);
    if material != NO_MATERIAL {
        atomicAdd(&material_tiles[material].tile_count, 1u);
    }
}

@compute @workgroup_size(1)
fn cs_offsets() {
    var first = 0u;
    for (var material = 0u; material < arrayLength(&material_tiles); material += 1u) {
        material_tiles[material].first = first;
        first += atomicLoad(&material_tiles[material].tile_count);
    }
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_fill(
    @builtin(workgroup_id) tile: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
    @builtin(global_invocation_id) pixel: vec3<u32>,
) {
    let material = first_of_its_material(pixel.xy, index);
    if material != NO_MATERIAL {
        let slot = atomicAdd(&material_tiles[material].filled, 1u);
        tile_list[material_tiles[material].first + slot] = tile.x | (tile.y << 16u);
    }
}
