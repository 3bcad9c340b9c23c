// Integer hashes shared by the light animation and the far field's random ranges; the
// same integer operations as `lights::animation::pcg_hash` on the CPU.

// PCG hash (Jarzynski and Olano 2020, "Hash Functions for GPU Rendering").
fn pcg_hash(input: u32) -> u32 {
    let state = input * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Uniform in [0, 1) from the top 24 bits (exact in f32).
fn hash_unit(key: u32) -> f32 {
    return f32(pcg_hash(key) >> 8u) * (1.0 / 16777216.0);
}
