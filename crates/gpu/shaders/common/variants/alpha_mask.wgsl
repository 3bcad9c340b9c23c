// Variant: alpha-masked materials (their own pipeline, so opaque ones keep early depth).

#import manylights::common::material_bindings::material

fn apply_alpha_mask(alpha: f32) {
    if alpha < material.alpha_cutoff_double_sided.x {
        discard;
    }
}
