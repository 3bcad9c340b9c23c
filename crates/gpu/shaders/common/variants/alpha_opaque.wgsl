// Variant: opaque materials; no discard, so early depth testing stays on.

fn apply_alpha_mask(alpha: f32) {}
