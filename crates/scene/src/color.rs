//! The sRGB transfer function, once for the whole workspace (MTL colours are display
//! colours, exported ones are encoded, tests compare against 8-bit sRGB output). The GPU
//! twin is `shaders/deferred/codecs.wgsl`, tested on the GPU against these.

/// Encodes a linear channel in [0, 1] (clamped) as sRGB.
pub fn linear_to_srgb(linear: f32) -> f32 {
    let c = linear.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Decodes an sRGB channel in [0, 1] to linear.
pub fn srgb_to_linear(encoded: f32) -> f32 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// A linear channel as an 8-bit sRGB value, rounded to nearest.
pub fn linear_to_srgb8(linear: f32) -> u8 {
    (linear_to_srgb(linear) * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_known_values() {
        assert_eq!(linear_to_srgb8(0.0), 0);
        assert_eq!(linear_to_srgb8(1.0), 255);
        assert_eq!(linear_to_srgb8(0.5), 188);
        assert_eq!(linear_to_srgb(0.002), 0.002 * 12.92);
        for i in 0..=255u8 {
            let encoded = f32::from(i) / 255.0;
            assert_eq!(linear_to_srgb8(srgb_to_linear(encoded)), i);
        }
    }
}
