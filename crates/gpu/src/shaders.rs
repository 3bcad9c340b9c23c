//! `ShaderLibrary`: the one place WGSL modules are composed from the files in `shaders/`.
//!
//! Each [`Program`] lists the parts it is made of; programs that shade materials also take
//! a [`MaterialVariant`] that swaps in only the parts the scene needs (textures or flat
//! colour, normal maps or vertex normals, alpha test or none). Runtime code and `cargo
//! xtask validate-shaders` both go through [`ShaderLibrary::compose`] and
//! [`ShaderLibrary::all_compositions`], so what is validated is what runs.

use std::path::{Path, PathBuf};

use crate::context::GpuContext;
use crate::error::{GpuError, GpuResult};

macro_rules! embed {
    ($path:literal) => {
        (
            $path,
            include_str!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../shaders/",
                $path
            )),
        )
    };
}

/// The WGSL files, embedded at build time, by path relative to `shaders/`.
/// `tests::embedded_list_matches_the_shaders_folder` keeps this list honest.
pub const EMBEDDED_SHADERS: &[(&str, &str)] = &[
    embed!("common/view.wgsl"),
    embed!("common/scene.wgsl"),
    embed!("common/material.wgsl"),
    embed!("common/surface.wgsl"),
    embed!("common/variants/base_color_textured.wgsl"),
    embed!("common/variants/base_color_flat.wgsl"),
    embed!("common/variants/normal_mapped.wgsl"),
    embed!("common/variants/normal_vertex.wgsl"),
    embed!("common/variants/alpha_mask.wgsl"),
    embed!("common/variants/alpha_opaque.wgsl"),
    embed!("debug/base_color.wgsl"),
    embed!("gpu/mipmap.wgsl"),
    embed!("common/shading.wgsl"),
    embed!("common/fullscreen.wgsl"),
    embed!("lights/light_set.wgsl"),
    embed!("lights/animate.wgsl"),
    embed!("naive/naive.wgsl"),
    embed!("post/tonemap.wgsl"),
    embed!("post/exposure_state.wgsl"),
    embed!("post/exposure.wgsl"),
    embed!("debug/surface.wgsl"),
    embed!("cluster/cluster_index.wgsl"),
    embed!("cluster/assign.wgsl"),
    embed!("cluster/stats.wgsl"),
    embed!("forward_plus/forward_plus.wgsl"),
    embed!("cluster/cluster_lights.wgsl"),
    embed!("deferred/codecs.wgsl"),
    embed!("deferred/full_write.wgsl"),
    embed!("deferred/full_read.wgsl"),
    embed!("deferred/compact_write.wgsl"),
    embed!("deferred/compact_read.wgsl"),
    embed!("deferred/packed_write.wgsl"),
    embed!("deferred/packed_read.wgsl"),
    embed!("deferred/gbuffer.wgsl"),
    embed!("deferred/lighting.wgsl"),
    embed!("deferred/lighting_fragment.wgsl"),
    embed!("deferred/lighting_compute.wgsl"),
];

/// How the deferred G-buffer stores a surface (bytes per pixel in ARCHITECTURE.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum GBufferLayout {
    /// Every attribute in f32: lossless, matches naive.
    Full,
    /// Position from depth, octahedral normal in 2x16 bits, sRGB 8-bit albedo. Default.
    #[default]
    Compact,
    /// One Rgba32Uint target plus depth.
    Packed,
}

impl GBufferLayout {
    pub const ALL: [GBufferLayout; 3] = [
        GBufferLayout::Full,
        GBufferLayout::Compact,
        GBufferLayout::Packed,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            GBufferLayout::Full => "full",
            GBufferLayout::Compact => "compact",
            GBufferLayout::Packed => "packed",
        }
    }
}

/// How deferred lighting runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum LightingPath {
    /// A fullscreen fragment pass.
    Fragment,
    /// A compute pass over 8x8 tiles writing a storage texture. Default: measured much
    /// faster on GPUs with few graphics units.
    #[default]
    Compute,
}

impl LightingPath {
    pub const ALL: [LightingPath; 2] = [LightingPath::Fragment, LightingPath::Compute];

    pub fn name(&self) -> &'static str {
        match self {
            LightingPath::Fragment => "fragment",
            LightingPath::Compute => "compute",
        }
    }
}

/// The shader features a material-shading program is specialised for. Built from the
/// scene's feature summary, so absent features cost nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct MaterialVariant {
    pub base_color_texture: bool,
    pub normal_map: bool,
    pub alpha_mask: bool,
}

impl MaterialVariant {
    /// All 8 combinations, for validation.
    pub fn all() -> impl Iterator<Item = MaterialVariant> {
        (0..8u8).map(|bits| MaterialVariant {
            base_color_texture: bits & 1 != 0,
            normal_map: bits & 2 != 0,
            alpha_mask: bits & 4 != 0,
        })
    }

    fn parts(&self) -> [&'static str; 3] {
        [
            if self.base_color_texture {
                "common/variants/base_color_textured.wgsl"
            } else {
                "common/variants/base_color_flat.wgsl"
            },
            if self.normal_map {
                "common/variants/normal_mapped.wgsl"
            } else {
                "common/variants/normal_vertex.wgsl"
            },
            if self.alpha_mask {
                "common/variants/alpha_mask.wgsl"
            } else {
                "common/variants/alpha_opaque.wgsl"
            },
        ]
    }

    fn label(&self) -> String {
        format!(
            "{}+{}+{}",
            if self.base_color_texture {
                "textured"
            } else {
                "flat"
            },
            if self.normal_map {
                "normalmap"
            } else {
                "vertexnormal"
            },
            if self.alpha_mask { "masked" } else { "opaque" }
        )
    }
}

/// Every entry-point module the renderer uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Program {
    /// Unlit base colour of the scene (debug view, round-trip test).
    BaseColor,
    /// Mip chain generation for uploaded textures.
    Mipmap,
    /// Light animation compute pass.
    AnimateLights,
    /// Naive forward shading: every fragment loops over every light.
    Naive,
    /// Exposure and tonemapping from the HDR target to the output.
    Tonemap,
    /// Automatic exposure: luminance histogram and its median, on the GPU.
    AutoExposure,
    /// Full-precision surface attributes (position, normal, albedo, specular) for the
    /// accuracy reference.
    SurfaceDump,
    /// Cluster light assignment: count, prefix sum, fill, sort.
    AssignLights,
    /// Light-list statistics (lengths, false positives) on the GPU.
    ClusterStats,
    /// Forward+ shading, its depth pre-pass and the cluster debug views.
    ForwardPlus,
    /// The deferred G-buffer pass in a layout.
    GBuffer(GBufferLayout),
    /// Deferred lighting reading a layout, on a path.
    DeferredLighting(GBufferLayout, LightingPath),
}

impl Program {
    /// Every program, in every G-buffer layout and lighting path.
    pub fn all() -> Vec<Program> {
        let mut programs = vec![
            Program::BaseColor,
            Program::Mipmap,
            Program::AnimateLights,
            Program::Naive,
            Program::Tonemap,
            Program::AutoExposure,
            Program::SurfaceDump,
            Program::AssignLights,
            Program::ClusterStats,
            Program::ForwardPlus,
        ];
        for layout in GBufferLayout::ALL {
            programs.push(Program::GBuffer(layout));
            for path in LightingPath::ALL {
                programs.push(Program::DeferredLighting(layout, path));
            }
        }
        programs
    }

    /// Whether this program shades scene materials (and so takes a [`MaterialVariant`]).
    pub fn shades_materials(&self) -> bool {
        matches!(
            self,
            Program::BaseColor | Program::Naive | Program::SurfaceDump
        )
    }

    fn name(&self) -> String {
        match self {
            Program::BaseColor => "base_color".into(),
            Program::Mipmap => "mipmap".into(),
            Program::AnimateLights => "animate_lights".into(),
            Program::Naive => "naive".into(),
            Program::Tonemap => "tonemap".into(),
            Program::AutoExposure => "auto_exposure".into(),
            Program::SurfaceDump => "surface_dump".into(),
            Program::AssignLights => "assign_lights".into(),
            Program::ClusterStats => "cluster_stats".into(),
            Program::ForwardPlus => "forward_plus".into(),
            Program::GBuffer(layout) => format!("gbuffer_{}", layout.name()),
            Program::DeferredLighting(layout, path) => {
                format!("deferred_lighting_{}_{}", layout.name(), path.name())
            }
        }
    }

    /// The parts, in order. Material programs: view, scene, material, the variant parts,
    /// then their own.
    fn parts(&self, variant: MaterialVariant) -> Vec<&'static str> {
        let material_prelude = |own: &[&'static str]| {
            let mut parts = vec!["common/view.wgsl"];
            parts.extend(variant.parts().iter().filter(|p| p.contains("normal_")));
            parts.push("common/scene.wgsl");
            parts.push("common/surface.wgsl");
            parts.push("common/material.wgsl");
            parts.extend(variant.parts().iter().filter(|p| !p.contains("normal_")));
            parts.extend_from_slice(own);
            parts
        };
        match self {
            Program::BaseColor => material_prelude(&["debug/base_color.wgsl"]),
            Program::Naive => material_prelude(&[
                "lights/light_set.wgsl",
                "common/shading.wgsl",
                "naive/naive.wgsl",
            ]),
            Program::SurfaceDump => material_prelude(&["debug/surface.wgsl"]),
            Program::ForwardPlus => material_prelude(&[
                "lights/light_set.wgsl",
                "common/shading.wgsl",
                "cluster/cluster_index.wgsl",
                "cluster/cluster_lights.wgsl",
                "forward_plus/forward_plus.wgsl",
            ]),
            Program::GBuffer(layout) => material_prelude(&[
                "deferred/codecs.wgsl",
                match layout {
                    GBufferLayout::Full => "deferred/full_write.wgsl",
                    GBufferLayout::Compact => "deferred/compact_write.wgsl",
                    GBufferLayout::Packed => "deferred/packed_write.wgsl",
                },
                "deferred/gbuffer.wgsl",
            ]),
            Program::DeferredLighting(layout, path) => {
                let mut parts = vec![
                    "common/view.wgsl",
                    "common/surface.wgsl",
                    "lights/light_set.wgsl",
                    "common/shading.wgsl",
                    "cluster/cluster_index.wgsl",
                    "cluster/cluster_lights.wgsl",
                    "deferred/codecs.wgsl",
                    match layout {
                        GBufferLayout::Full => "deferred/full_read.wgsl",
                        GBufferLayout::Compact => "deferred/compact_read.wgsl",
                        GBufferLayout::Packed => "deferred/packed_read.wgsl",
                    },
                    "deferred/lighting.wgsl",
                ];
                match path {
                    LightingPath::Fragment => {
                        parts.extend(["common/fullscreen.wgsl", "deferred/lighting_fragment.wgsl"])
                    }
                    LightingPath::Compute => parts.push("deferred/lighting_compute.wgsl"),
                }
                parts
            }
            Program::AssignLights => vec![
                "common/view.wgsl",
                "lights/light_set.wgsl",
                "cluster/cluster_index.wgsl",
                "cluster/assign.wgsl",
            ],
            Program::ClusterStats => vec![
                "common/view.wgsl",
                "cluster/cluster_index.wgsl",
                "cluster/stats.wgsl",
            ],
            Program::Mipmap => vec!["common/fullscreen.wgsl", "gpu/mipmap.wgsl"],
            Program::AnimateLights => vec!["lights/light_set.wgsl", "lights/animate.wgsl"],
            Program::Tonemap => vec![
                "common/fullscreen.wgsl",
                "post/exposure_state.wgsl",
                "post/tonemap.wgsl",
            ],
            Program::AutoExposure => vec!["post/exposure_state.wgsl", "post/exposure.wgsl"],
        }
    }
}

/// A composed module: its source and where each part's lines came from.
#[derive(Debug, Clone)]
pub struct ComposedShader {
    /// e.g. `naive[textured+vertexnormal+masked]`.
    pub name: String,
    pub source: String,
    /// (path relative to `shaders/`, first line in `source` (1-based), line count).
    parts: Vec<(String, usize, usize)>,
}

impl ComposedShader {
    /// Maps a 1-based line of the composed source back to `shaders/<file>:<line>`.
    pub fn locate(&self, line: usize) -> String {
        for (path, first, count) in &self.parts {
            if line >= *first && line < first + count {
                return format!("shaders/{path}:{}", line - first + 1);
            }
        }
        format!("{}:{line}", self.name)
    }

    /// `shaders/<file>:<line>` of the first defined span of an error.
    fn first_location(&self, spans: impl Iterator<Item = naga::Span>) -> String {
        spans
            .filter(|span| span.is_defined())
            .map(|span| self.locate(span.location(&self.source).line_number as usize))
            .next()
            .unwrap_or_else(|| self.name.clone())
    }
}

/// Where WGSL comes from: the copies embedded in the binary (the normal case) or a
/// directory on disk (used by `cargo xtask validate-shaders --shaders-dir`).
#[derive(Debug, Clone)]
pub enum ShaderLibrary {
    Embedded,
    Directory(PathBuf),
}

/// The variable that makes [`ShaderLibrary::from_env`] read WGSL from a folder at run time
/// (same layout as `shaders/`): how `cargo xtask mutants` tests mutated shaders without
/// rebuilding anything.
pub const SHADER_DIR_VARIABLE: &str = "MANYLIGHTS_SHADER_DIR";

impl ShaderLibrary {
    /// The embedded shaders, or the folder named by `MANYLIGHTS_SHADER_DIR` when it is set
    /// (logged, so a run on other shaders never goes unnoticed).
    pub fn from_env() -> Self {
        match std::env::var_os(SHADER_DIR_VARIABLE) {
            Some(dir) if !dir.is_empty() => {
                log::warn!(
                    "reading shaders from {} ({SHADER_DIR_VARIABLE})",
                    std::path::Path::new(&dir).display()
                );
                ShaderLibrary::Directory(PathBuf::from(dir))
            }
            _ => ShaderLibrary::Embedded,
        }
    }

    fn read(&self, path: &str) -> GpuResult<String> {
        match self {
            ShaderLibrary::Embedded => EMBEDDED_SHADERS
                .iter()
                .find(|(p, _)| *p == path)
                .map(|(_, source)| source.to_string())
                .ok_or_else(|| GpuError::Shader {
                    module: path.into(),
                    message: "not in EMBEDDED_SHADERS".into(),
                }),
            ShaderLibrary::Directory(dir) => {
                std::fs::read_to_string(dir.join(path)).map_err(|e| GpuError::Shader {
                    module: dir.join(path).display().to_string(),
                    message: e.to_string(),
                })
            }
        }
    }

    /// Concatenates a program's parts (each preceded by a marker comment).
    pub fn compose(&self, program: Program, variant: MaterialVariant) -> GpuResult<ComposedShader> {
        let name = if program.shades_materials() {
            format!("{}[{}]", program.name(), variant.label())
        } else {
            program.name()
        };
        let mut source = String::new();
        let mut parts = Vec::new();
        for path in program.parts(variant) {
            let text = self.read(path)?;
            source.push_str(&format!("// ---- shaders/{path}\n"));
            let first = source.lines().count() + 1;
            let count = text.lines().count();
            source.push_str(&text);
            if !text.ends_with('\n') {
                source.push('\n');
            }
            parts.push((path.to_string(), first, count));
        }
        Ok(ComposedShader {
            name,
            source,
            parts,
        })
    }

    /// Every (program, variant) the renderer can create: what validation must cover.
    pub fn all_compositions() -> Vec<(Program, MaterialVariant)> {
        Program::all()
            .into_iter()
            .flat_map(|program| {
                let variants: Vec<MaterialVariant> = if program.shades_materials() {
                    MaterialVariant::all().collect()
                } else {
                    vec![MaterialVariant::default()]
                };
                variants.into_iter().map(move |variant| (program, variant))
            })
            .collect()
    }

    /// Parses and validates with naga (all validation flags, the capabilities the
    /// renderer uses). Errors name `shaders/<file>:<line>`.
    pub fn validate(shader: &ComposedShader) -> GpuResult<naga::Module> {
        let module = naga::front::wgsl::parse_str(&shader.source).map_err(|error| {
            let location = shader.first_location(error.labels().map(|(span, _)| span));
            GpuError::Shader {
                module: shader.name.clone(),
                message: format!(
                    "{location}: {}",
                    error.emit_to_string_with_path(&shader.source, &shader.name)
                ),
            }
        })?;
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        );
        validator.validate(&module).map_err(|error| {
            let location = shader.first_location(error.spans().map(|(span, _)| *span));
            GpuError::Shader {
                module: shader.name.clone(),
                message: format!(
                    "{location}: {}",
                    error.emit_to_string_with_path(&shader.source, &shader.name)
                ),
            }
        })?;
        Ok(module)
    }

    /// Composes, validates (for file:line errors) and creates the wgpu module.
    pub fn create_module(
        &self,
        context: &GpuContext,
        program: Program,
        variant: MaterialVariant,
    ) -> GpuResult<wgpu::ShaderModule> {
        let shader = self.compose(program, variant)?;
        Self::validate(&shader)?;
        context.scoped(&format!("creating shader module {}", shader.name), || {
            context
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(&shader.name),
                    source: wgpu::ShaderSource::Wgsl(shader.source.as_str().into()),
                })
        })
    }

    /// The `shaders/` folder of this source tree.
    pub fn source_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shaders")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wgsl_files(dir: &Path, prefix: &str, out: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).expect("shaders dir") {
            let entry = entry.expect("entry");
            let name = entry.file_name().to_string_lossy().into_owned();
            let path = entry.path();
            if path.is_dir() {
                wgsl_files(&path, &format!("{prefix}{name}/"), out);
            } else if name.ends_with(".wgsl") {
                out.push(format!("{prefix}{name}"));
            }
        }
    }

    #[test]
    fn embedded_list_matches_the_shaders_folder() {
        let mut on_disk = Vec::new();
        wgsl_files(&ShaderLibrary::source_dir(), "", &mut on_disk);
        on_disk.sort();
        let mut embedded: Vec<String> = EMBEDDED_SHADERS
            .iter()
            .map(|(p, _)| p.to_string())
            .collect();
        embedded.sort();
        assert_eq!(embedded, on_disk);
    }

    #[test]
    fn every_composition_validates() {
        for (program, variant) in ShaderLibrary::all_compositions() {
            let shader = ShaderLibrary::Embedded
                .compose(program, variant)
                .expect("compose");
            if let Err(error) = ShaderLibrary::validate(&shader) {
                panic!("{error}");
            }
        }
    }

    #[test]
    fn a_broken_shader_is_rejected_with_its_file_and_line() {
        let dir = tempfile::tempdir().expect("tempdir");
        for (path, source) in EMBEDDED_SHADERS {
            let file = dir.path().join(path);
            std::fs::create_dir_all(file.parent().expect("parent")).expect("mkdir");
            std::fs::write(file, source).expect("write");
        }
        // A type error on line 3 of the base colour shader.
        let broken = "// broken on purpose\n\nfn broken() -> u32 { return 1.5; }\n";
        std::fs::write(dir.path().join("debug/base_color.wgsl"), broken).expect("write");
        let library = ShaderLibrary::Directory(dir.path().to_path_buf());
        let shader = library
            .compose(Program::BaseColor, MaterialVariant::default())
            .expect("compose");
        let error = ShaderLibrary::validate(&shader)
            .expect_err("must fail")
            .to_string();
        assert!(error.contains("shaders/debug/base_color.wgsl:3"), "{error}");
    }
}
