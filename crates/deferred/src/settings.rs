//! What a deferred frame can vary, each choice with one name (`FromStr`/`Display`) that the
//! command line, the lab, the viewer's script and its UI all use.

use std::fmt;
use std::str::FromStr;

use manylights_cluster::{ClusterView, ClusteringSettings, FIRST_PIPELINE_VIEW_CODE};
use manylights_gpu::ShaderDef;
use manylights_lights::BoundedFalloff;

/// How the G-buffer stores a surface (bytes per pixel: [`crate::bytes_per_pixel`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum GBufferLayout {
    /// Every attribute in f32: lossless, matches naive.
    Full,
    /// Position from depth, octahedral normal in 2x16 bits, sRGB 8-bit albedo. Default.
    #[default]
    Compact,
    /// One Rgba32Uint target plus depth.
    Packed,
    /// A visibility buffer: the raster writes depth and each pixel's instance and triangle
    /// (Rg32Uint), and compute passes rebuild the surfaces into the `packed` layout, one
    /// material at a time (`crate::visibility`).
    Visibility,
}

impl GBufferLayout {
    pub const ALL: [GBufferLayout; 4] = [
        GBufferLayout::Full,
        GBufferLayout::Compact,
        GBufferLayout::Packed,
        GBufferLayout::Visibility,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            GBufferLayout::Full => "full",
            GBufferLayout::Compact => "compact",
            GBufferLayout::Packed => "packed",
            GBufferLayout::Visibility => "visibility",
        }
    }

    /// The layout lighting reads: the visibility buffer's resolve writes `packed`.
    pub fn stored(&self) -> GBufferLayout {
        match self {
            GBufferLayout::Visibility => GBufferLayout::Packed,
            layout => *layout,
        }
    }

    /// The shader def that makes `gbuffer.wgsl` and `lighting.wgsl` import the write and
    /// read halves of the layout stored (`<name>_write.wgsl`, `<name>_read.wgsl`).
    pub fn shader_def(&self) -> String {
        format!("GBUFFER_{}", self.stored().name().to_uppercase())
    }
}

manylights_gpu::named_choice!(GBufferLayout, "G-buffer layout");

/// How deferred lighting runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum LightingPath {
    /// A fullscreen fragment pass.
    Fragment,
    /// A compute pass over 8x8 tiles writing a storage texture, each pixel running its
    /// cluster's list: measured much faster than the fragment pass on GPUs with few
    /// graphics units.
    Compute,
    /// The compute pass with the tile's pixels sharing their clusters' lists: loaded into
    /// workgroup memory once a tile, culled to the box around the tile's surfaces
    /// (`shaders/cluster/tile_lights.wgsl`). The same image as `Compute`. Default: faster
    /// than `Compute` from a few thousand lights (H200, lighting pass: 0.66 against 0.71
    /// ms at 5,000 lights, 11.1 against 13.8 ms at 100,000, 0.58 against 1.77 ms at
    /// 1,000,000 with radius 0.25 m; 0.20 against 0.16 ms at 1,000;
    /// `scripts/gpu-machine-tiles.sh`).
    #[default]
    Tiles,
}

impl LightingPath {
    pub const ALL: [LightingPath; 3] = [
        LightingPath::Fragment,
        LightingPath::Compute,
        LightingPath::Tiles,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            LightingPath::Fragment => "fragment",
            LightingPath::Compute => "compute",
            LightingPath::Tiles => "tiles",
        }
    }

    /// Whether the pass is a compute pass (writes the HDR target as a storage texture).
    pub fn is_compute(&self) -> bool {
        matches!(self, LightingPath::Compute | LightingPath::Tiles)
    }
}

manylights_gpu::named_choice!(LightingPath, "lighting path");

/// A G-buffer channel shown as a debug view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GBufferChannel {
    /// Albedo.
    Albedo,
    /// The normal as 0.5 + 0.5 n.
    Normal,
    /// View depth: black at the eye to white at 32 m and beyond.
    Depth,
    /// World position, fractional metres.
    Position,
}

impl GBufferChannel {
    pub const ALL: [GBufferChannel; 4] = [
        GBufferChannel::Albedo,
        GBufferChannel::Normal,
        GBufferChannel::Depth,
        GBufferChannel::Position,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            GBufferChannel::Albedo => "albedo",
            GBufferChannel::Normal => "normal",
            GBufferChannel::Depth => "depth",
            GBufferChannel::Position => "position",
        }
    }

    /// Its code in the clustered shading uniform, above the cluster views' codes.
    pub fn shader_code(&self) -> u32 {
        let index = Self::ALL.iter().position(|c| c == self).unwrap_or(0) as u32;
        FIRST_PIPELINE_VIEW_CODE + index
    }

    /// The shader defs that give `lighting.wgsl` the channels' codes (the crate's WGSL
    /// constants).
    pub fn shader_defs() -> Vec<(String, ShaderDef)> {
        Self::ALL
            .iter()
            .map(|channel| {
                (
                    format!("GBUFFER_VIEW_{}", channel.name().to_uppercase()),
                    ShaderDef::UInt(channel.shader_code()),
                )
            })
            .collect()
    }
}

manylights_gpu::named_choice!(GBufferChannel, "G-buffer channel");

/// What the deferred pipeline can draw instead of the shaded image.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum DeferredView {
    Cluster(ClusterView),
    GBuffer(GBufferChannel),
}

impl DeferredView {
    /// Every view, by name (the heatmap at its default maximum).
    pub fn all() -> Vec<DeferredView> {
        ClusterView::ALL
            .into_iter()
            .map(DeferredView::Cluster)
            .chain(GBufferChannel::ALL.into_iter().map(DeferredView::GBuffer))
            .collect()
    }
}

impl fmt::Display for DeferredView {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DeferredView::Cluster(view) => view.fmt(f),
            DeferredView::GBuffer(channel) => channel.fmt(f),
        }
    }
}

impl FromStr for DeferredView {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        text.parse::<ClusterView>()
            .map(DeferredView::Cluster)
            .or_else(|_| text.parse::<GBufferChannel>().map(DeferredView::GBuffer))
            .map_err(|_| {
                format!(
                    "unknown deferred view `{text}`: expected heatmap, slices, evaluations, albedo, normal, depth or position"
                )
            })
    }
}

/// What a deferred frame can vary.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[derive(serde::Serialize, serde::Deserialize)]
// Fields missing from a serialized pipeline are the defaults: a frame's settings can
// switch pipelines by naming another `kind`.
#[serde(default)]
pub struct DeferredSettings {
    /// A falloff with a radius: lights are culled by it.
    pub falloff: BoundedFalloff,
    pub layout: GBufferLayout,
    pub lighting: LightingPath,
    /// A cluster view or a G-buffer channel instead of the shaded image.
    pub debug_view: Option<DeferredView>,
    /// The light lists' grid, assignment and far field.
    pub clustering: ClusteringSettings,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for layout in GBufferLayout::ALL {
            assert_eq!(layout.to_string().parse::<GBufferLayout>(), Ok(layout));
        }
        for path in LightingPath::ALL {
            assert_eq!(path.to_string().parse::<LightingPath>(), Ok(path));
        }
        for view in DeferredView::all() {
            assert_eq!(view.to_string().parse::<DeferredView>(), Ok(view));
        }
        assert!("diagonal".parse::<GBufferLayout>().is_err());
    }

    #[test]
    fn channel_codes_stay_clear_of_cluster_views() {
        for channel in GBufferChannel::ALL {
            for view in ClusterView::ALL {
                assert_ne!(channel.shader_code(), view.shader_code());
            }
            assert!(channel.shader_code() >= FIRST_PIPELINE_VIEW_CODE);
        }
    }
}
