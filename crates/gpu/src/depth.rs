//! Which way depth runs. Standard: 0 at near, 1 at far, nearer is less. Reverse-Z: 1 at
//! near, 0 at far, nearer is greater; with a float depth buffer the error then stays
//! relative to the distance (about d x 6e-8) instead of growing with d^2 / near, which is
//! what tiny near planes and huge near/far ratios need.

/// The depth convention of a set of pipelines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum DepthConvention {
    #[default]
    Standard,
    Reverse,
}

impl DepthConvention {
    /// The test that keeps the nearer fragment.
    pub fn nearer(&self) -> wgpu::CompareFunction {
        match self {
            DepthConvention::Standard => wgpu::CompareFunction::Less,
            DepthConvention::Reverse => wgpu::CompareFunction::Greater,
        }
    }

    /// The test that keeps the nearer or equal fragment (shading after a depth pre-pass).
    pub fn nearer_or_equal(&self) -> wgpu::CompareFunction {
        match self {
            DepthConvention::Standard => wgpu::CompareFunction::LessEqual,
            DepthConvention::Reverse => wgpu::CompareFunction::GreaterEqual,
        }
    }

    /// The depth of empty pixels (the farthest value).
    pub fn clear_value(&self) -> f32 {
        match self {
            DepthConvention::Standard => 1.0,
            DepthConvention::Reverse => 0.0,
        }
    }
}
