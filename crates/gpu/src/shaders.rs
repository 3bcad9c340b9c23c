//! `ShaderLibrary`: composes WGSL modules from the files in `shaders/` by their explicit
//! `#import`s (naga_oil), for programs that each crate declares itself.
//!
//! The composer knows no pipeline. A crate that owns shaders embeds its folder of
//! `shaders/` as [`ShaderModules`] (with [`shader_files!`](crate::shader_files)), naming the module sets of
//! the crates below it that its files import; it declares its [`Program`]s (an entry file,
//! the shader defs of a variant) and lists every variant in a `programs()` function, which
//! `cargo xtask validate-shaders` validates. A file's import path is its path under
//! `shaders/`: `cluster/cluster_index.wgsl` is `manylights::cluster::cluster_index`.
//!
//! Programs that shade scene materials are composed for a [`MaterialVariant`]: its shader
//! defs (`BASE_COLOR_TEXTURE`, `NORMAL_MAP`, `ALPHA_MASK`) select the variant files that
//! `common/material.wgsl` and `common/scene.wgsl` import, so a scene without textures or
//! normal maps gets shaders without them.

use std::collections::{HashMap, HashSet};
use std::path::PathBuf;

use naga_oil::compose::{
    ComposableModuleDescriptor, Composer, NagaModuleDescriptor, ShaderDefValue, ShaderLanguage,
    ShaderType,
};

use crate::compose_cache::{self, ComposeCache, ComposedKey};

mod for_engines;
use crate::context::GpuContext;
use crate::error::{GpuError, GpuResult};

/// One WGSL file of a crate's `shaders/` folder, embedded by that crate.
#[derive(Debug, Clone, Copy)]
pub struct ShaderFile {
    /// Relative to the owning crate's `shaders/` folder, e.g. `cluster/assign.wgsl`.
    pub path: &'static str,
    pub source: &'static str,
}

/// The WGSL files one crate owns, the module sets of the crates below it that they import
/// from, and the Rust constants they read.
#[derive(Debug)]
pub struct ShaderModules {
    /// The owning crate's short name (`gpu`, `cluster`, ...).
    pub owner: &'static str,
    pub files: &'static [ShaderFile],
    pub uses: &'static [&'static ShaderModules],
    /// The constants this set's WGSL reads as shader defs (`#NAME` in the source), each
    /// from its one Rust definition: every program composed from this set, or from a set
    /// that uses it, gets them, so WGSL never holds a copy of a Rust number.
    pub constants: fn() -> Vec<(String, ShaderDef)>,
}

/// For a [`ShaderModules`] whose WGSL reads no Rust constant.
pub fn no_constants() -> Vec<(String, ShaderDef)> {
    Vec::new()
}

impl ShaderModules {
    /// This set and every set it uses, each once.
    fn all_sets(&'static self) -> Vec<&'static ShaderModules> {
        let mut sets = Vec::new();
        let mut seen_sets: HashSet<*const ShaderModules> = HashSet::new();
        let mut stack = vec![self];
        while let Some(set) = stack.pop() {
            if !seen_sets.insert(set as *const _) {
                continue;
            }
            sets.push(set);
            stack.extend(set.uses.iter().copied());
        }
        sets
    }

    /// This set's files and those of every set it uses, each once.
    pub fn all_files(&'static self) -> Vec<ShaderFile> {
        self.all_sets()
            .into_iter()
            .flat_map(|set| set.files.iter().copied())
            .collect()
    }

    /// The constants of this set and of every set it uses.
    pub fn all_constants(&'static self) -> Vec<(String, ShaderDef)> {
        self.all_sets()
            .into_iter()
            .flat_map(|set| (set.constants)())
            .collect()
    }
}

/// Embeds WGSL files of the calling crate's own `shaders/` folder at build time:
/// `shader_files!["cluster/assign.wgsl", ...]` is a `&'static [ShaderFile]`.
#[macro_export]
macro_rules! shader_files {
    ($($path:literal),* $(,)?) => {
        &[$($crate::shaders::ShaderFile {
            path: $path,
            source: include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders/", $path)),
        }),*]
    };
}

/// The shared WGSL (`shaders/common`) and this crate's own programs (`shaders/gpu`; the
/// automatic exposure's, which reads constants of its own, is `post`'s set).
pub static SHADERS: ShaderModules = ShaderModules {
    owner: "gpu",
    files: shader_files![
        "common/view.wgsl",
        "common/history.wgsl",
        "common/scene.wgsl",
        "common/surface.wgsl",
        "common/material_bindings.wgsl",
        "common/material.wgsl",
        "common/fullscreen.wgsl",
        "common/variants/base_color_textured.wgsl",
        "common/variants/base_color_flat.wgsl",
        "common/variants/normal_mapped.wgsl",
        "common/variants/normal_vertex.wgsl",
        "common/variants/alpha_mask.wgsl",
        "common/variants/alpha_opaque.wgsl",
        "common/variants/emissive.wgsl",
        "common/variants/emissive_none.wgsl",
        "common/variants/metallic_roughness_textured.wgsl",
        "common/variants/metallic_roughness_flat.wgsl",
        "gpu/base_color.wgsl",
        "gpu/surface.wgsl",
        "gpu/mipmap.wgsl",
        "gpu/tonemap.wgsl",
        "gpu/taa.wgsl",
        "gpu/bloom.wgsl",
        "gpu/exposure_state.wgsl",
        "gpu/weighted_blended.wgsl",
        "gpu/weighted_composite.wgsl",
    ],
    uses: &[],
    constants: || {
        vec![(
            "SCREEN_TILE".into(),
            crate::ShaderDef::UInt(crate::SCREEN_TILE),
        )]
    },
};

/// `program`'s entry file among `files` (its module sets'); errors name it as `name`.
fn entry_file<'f>(
    program: &Program,
    files: &'f [ShaderFile],
    name: &str,
) -> GpuResult<&'f ShaderFile> {
    files
        .iter()
        .find(|f| f.path == program.entry)
        .ok_or_else(|| GpuError::Shader {
            module: name.to_string(),
            message: format!(
                "entry file shaders/{} is not in the {} module set",
                program.entry, program.modules.owner
            ),
        })
}

/// Adds `file` (its `source`) to `composer` as a composable module under its import path.
fn add_composable(composer: &mut Composer, file: &ShaderFile, source: &str) -> GpuResult<()> {
    let file_path = format!("shaders/{}", file.path);
    let added = composer.add_composable_module(ComposableModuleDescriptor {
        source,
        file_path: &file_path,
        language: ShaderLanguage::Wgsl,
        as_name: Some(import_path(file.path)),
        additional_imports: &[],
        shader_defs: HashMap::new(),
    });
    match added {
        Ok(_) => Ok(()),
        Err(error) => Err(GpuError::Shader {
            module: file_path,
            message: error.emit_to_string(composer),
        }),
    }
}

/// The import path of a file under `shaders/`: `manylights::` and its path, `/` as `::`.
pub fn import_path(file: &str) -> String {
    format!(
        "manylights::{}",
        file.trim_end_matches(".wgsl").replace('/', "::")
    )
}

/// The shader features a material-shading program is specialised for. Built from the
/// scene's feature summary, so absent features cost nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct MaterialVariant {
    pub base_color_texture: bool,
    pub normal_map: bool,
    pub alpha_mask: bool,
    /// A material of the scene emits light.
    pub emissive: bool,
    /// A material of the scene has a metallic-roughness texture (read by PBR programs only).
    pub metallic_roughness_texture: bool,
}

impl MaterialVariant {
    /// All 32 combinations, for validation.
    pub fn all() -> impl Iterator<Item = MaterialVariant> {
        (0..32u8).map(|bits| MaterialVariant {
            base_color_texture: bits & 1 != 0,
            normal_map: bits & 2 != 0,
            alpha_mask: bits & 4 != 0,
            emissive: bits & 8 != 0,
            metallic_roughness_texture: bits & 16 != 0,
        })
    }

    /// The shader defs that select this variant's files (only the features present).
    fn shader_defs(&self) -> impl Iterator<Item = &'static str> {
        [
            (self.base_color_texture, "BASE_COLOR_TEXTURE"),
            (self.normal_map, "NORMAL_MAP"),
            (self.alpha_mask, "ALPHA_MASK"),
            (self.emissive, "EMISSIVE"),
            (
                self.metallic_roughness_texture,
                "METALLIC_ROUGHNESS_TEXTURE",
            ),
        ]
        .into_iter()
        .filter_map(|(on, name)| on.then_some(name))
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
            if self.alpha_mask { "masked" } else { "opaque" },
        ) + if self.emissive { "+emissive" } else { "" }
            + if self.metallic_roughness_texture {
                "+metallicroughness"
            } else {
                ""
            }
    }
}

/// The shader def of PBR programs (`scene::Shading::Pbr`).
const SHADING_PBR: &str = "SHADING_PBR";

/// The shader defs that make a program shade with `shading`: `SHADING_PBR` for PBR, none
/// for Blinn-Phong. Every program that builds a surface from a material or evaluates the
/// BRDF is composed with them.
pub fn shading_defs(shading: manylights_scene::Shading) -> Vec<(String, ShaderDef)> {
    match shading {
        manylights_scene::Shading::Pbr => vec![(SHADING_PBR.to_string(), ShaderDef::Bool(true))],
        manylights_scene::Shading::BlinnPhong => Vec::new(),
    }
}

/// The value of a shader def: `#ifdef NAME` sees every def; `#NAME` in the source is
/// replaced by its value (how Rust enums hand their codes to WGSL without a copy).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShaderDef {
    Bool(bool),
    UInt(u32),
}

/// One shader program: an entry file under `shaders/` (holding the entry points), the
/// module set its imports come from, and the shader defs of this variant. Declared by the
/// crate that owns the entry file.
#[derive(Debug, Clone)]
pub struct Program {
    /// e.g. `tonemap`; material programs add the variant when composed.
    pub name: String,
    pub modules: &'static ShaderModules,
    /// Relative to `shaders/`.
    pub entry: &'static str,
    pub defs: Vec<(String, ShaderDef)>,
    /// Composed once per [`MaterialVariant`] a scene needs (and validated in every one).
    pub shades_materials: bool,
}

impl Program {
    /// A program whose entry file does not shade scene materials.
    pub fn new(
        name: impl Into<String>,
        modules: &'static ShaderModules,
        entry: &'static str,
    ) -> Self {
        Self {
            name: name.into(),
            modules,
            entry,
            defs: Vec::new(),
            shades_materials: false,
        }
    }

    /// A program that rasterises the scene and shades its materials.
    pub fn shading_materials(
        name: impl Into<String>,
        modules: &'static ShaderModules,
        entry: &'static str,
    ) -> Self {
        Self {
            shades_materials: true,
            ..Self::new(name, modules, entry)
        }
    }

    /// Adds a shader def.
    pub fn with_def(mut self, name: impl Into<String>, value: ShaderDef) -> Self {
        self.defs.push((name.into(), value));
        self
    }

    /// Shades materials with `shading`'s BRDF (`SHADING_PBR` in surface-building and
    /// lighting code).
    pub fn with_shading(self, shading: manylights_scene::Shading) -> Self {
        self.with_defs(shading_defs(shading))
    }

    /// Adds shader defs.
    pub fn with_defs(mut self, defs: impl IntoIterator<Item = (String, ShaderDef)>) -> Self {
        self.defs.extend(defs);
        self
    }

    /// Its name in logs and errors, e.g. `base_color[textured+vertexnormal+masked]`.
    pub fn composed_name(&self, variant: MaterialVariant) -> String {
        if self.shades_materials {
            format!("{}[{}]", self.name, variant.label())
        } else {
            self.name.clone()
        }
    }

    /// The material variants this program is validated in (one unless it shades
    /// materials): every one a scene can ask for, except that the metallic-roughness
    /// texture, an independent block, is composed with none or all of the other features.
    pub fn variants(&self) -> Vec<MaterialVariant> {
        if self.shades_materials {
            // The metallic-roughness texture is read by PBR programs only (in the others its
            // variants are the same program), in a block of its own that no other feature
            // touches: beside every combination of the other four, it is composed with
            // none of them and with all of them (18 variants, not 32).
            let pbr = self.defs.iter().any(|(name, _)| name == SHADING_PBR);
            let all_or_none = |v: &MaterialVariant| {
                let others = [v.base_color_texture, v.normal_map, v.alpha_mask, v.emissive];
                others.iter().all(|&on| on) || others.iter().all(|&on| !on)
            };
            MaterialVariant::all()
                .filter(|variant| {
                    !variant.metallic_roughness_texture || (pbr && all_or_none(variant))
                })
                .collect()
        } else {
            vec![MaterialVariant::default()]
        }
    }

    /// The module sets' constants, then this variant's defs.
    fn naga_oil_defs(&self, variant: MaterialVariant) -> HashMap<String, ShaderDefValue> {
        let constants = self.modules.all_constants().into_iter();
        let mut defs: HashMap<String, ShaderDefValue> = constants
            .chain(self.defs.iter().cloned())
            .map(|(name, value)| {
                let value = match value {
                    ShaderDef::Bool(b) => ShaderDefValue::Bool(b),
                    ShaderDef::UInt(u) => ShaderDefValue::UInt(u),
                };
                (name, value)
            })
            .collect();
        if self.shades_materials {
            for name in variant.shader_defs() {
                defs.insert(name.to_string(), ShaderDefValue::Bool(true));
            }
        }
        defs
    }
}

/// A composed and validated module.
#[derive(Debug, Clone)]
pub struct ComposedShader {
    /// e.g. `base_color[textured+vertexnormal+masked]`.
    pub name: String,
    pub module: naga::Module,
}

impl ComposedShader {
    /// For each of `entries`, the bindings of `group` its entry point uses (naga's
    /// analysis of the composed module), in binding order.
    pub fn bindings_used<const N: usize>(
        &self,
        entries: [&str; N],
        group: u32,
    ) -> GpuResult<[Vec<u32>; N]> {
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&self.module)
        .map_err(|error| GpuError::Shader {
            module: self.name.clone(),
            message: error.emit_to_string(""),
        })?;
        let mut used = Vec::with_capacity(N);
        for entry in entries {
            let index = self
                .module
                .entry_points
                .iter()
                .position(|point| point.name == entry)
                .ok_or_else(|| GpuError::Shader {
                    module: self.name.clone(),
                    message: format!("no entry point '{entry}'"),
                })?;
            let uses = info.get_entry_point(index);
            let mut bindings: Vec<u32> = self
                .module
                .global_variables
                .iter()
                .filter(|(handle, _)| !uses[*handle].is_empty())
                .filter_map(|(_, variable)| variable.binding.as_ref())
                .filter(|binding| binding.group == group)
                .map(|binding| binding.binding)
                .collect();
            bindings.sort_unstable();
            used.push(bindings);
        }
        Ok(used
            .try_into()
            .unwrap_or_else(|_| unreachable!("one list per entry")))
    }
}

/// Where WGSL comes from: the copies embedded in the binary (the normal case) or a
/// directory on disk holding every crate's `shaders/` folder merged into one tree
/// (`cluster/assign.wgsl`, `common/view.wgsl`, ...: `cargo xtask validate-shaders
/// --shaders-dir`, shader mutants).
#[derive(Debug, Clone)]
pub enum ShaderLibrary {
    Embedded,
    Directory(PathBuf),
}

/// The variable that makes [`ShaderLibrary::from_env`] read WGSL from a folder at run time
/// (the crates' `shaders/` folders merged): how `cargo xtask mutants` tests mutated shaders without
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

    fn read(&self, file: &ShaderFile) -> GpuResult<String> {
        match self {
            ShaderLibrary::Embedded => Ok(file.source.to_string()),
            ShaderLibrary::Directory(dir) => {
                let path = dir.join(file.path);
                std::fs::read_to_string(&path).map_err(|e| GpuError::Shader {
                    module: path.display().to_string(),
                    message: e.to_string(),
                })
            }
        }
    }

    /// Reads `program`'s entry file (named `name` in errors) and adds every module it
    /// imports, and theirs, to `composer`: how composing a program starts, in our composer
    /// or in an engine's.
    fn add_imports_of_entry(
        &self,
        composer: &mut Composer,
        program: &Program,
        name: &str,
    ) -> GpuResult<(ShaderFile, String)> {
        let files = program.modules.all_files();
        let entry = *entry_file(program, &files, name)?;
        let source = self.read(&entry)?;
        let mut path_of_imports = vec![import_path(entry.path)];
        let mut checked = HashSet::new();
        self.add_with_imports(
            composer,
            &files,
            &entry,
            &source,
            &mut path_of_imports,
            &mut checked,
        )?;
        Ok((entry, source))
    }

    /// Checks that every import of `file` (recursively) comes from `files`, the module sets
    /// its program may use, and adds to the composer those not added yet (depth first, so
    /// each module follows what it imports). The whole graph is walked on every compose,
    /// whatever the shared composer already holds: a program must not pass because another
    /// program, with more module sets, added a module first.
    fn add_with_imports(
        &self,
        composer: &mut Composer,
        files: &[ShaderFile],
        file: &ShaderFile,
        source: &str,
        path_of_imports: &mut Vec<String>,
        checked: &mut HashSet<String>,
    ) -> GpuResult<()> {
        let (_, imports, _) = naga_oil::compose::get_preprocessor_data(source);
        for import in imports {
            let shader_error = |message: String| GpuError::Shader {
                module: format!("shaders/{}", file.path),
                message,
            };
            if path_of_imports.contains(&import.import) {
                return Err(shader_error(format!(
                    "circular import: {} -> {}",
                    path_of_imports.join(" -> "),
                    import.import
                )));
            }
            let imported = files
                .iter()
                .find(|f| import_path(f.path) == import.import)
                .ok_or_else(|| {
                    shader_error(format!(
                        "imports {}, which no module set it uses declares",
                        import.import
                    ))
                })?;
            if !checked.insert(import.import.clone()) {
                continue;
            }
            let imported_source = self.read(imported)?;
            path_of_imports.push(import.import.clone());
            self.add_with_imports(
                composer,
                files,
                imported,
                &imported_source,
                path_of_imports,
                checked,
            )?;
            path_of_imports.pop();
            if composer.contains_module(&import.import) {
                continue;
            }
            add_composable(composer, imported, &imported_source)?;
        }
        Ok(())
    }

    /// Composes a program in a material variant (ignored unless it shades materials) and
    /// validates it with naga (all validation flags). Errors name `shaders/<file>:<line>`.
    pub fn compose(
        &self,
        program: &Program,
        variant: MaterialVariant,
    ) -> GpuResult<ComposedShader> {
        let name = program.composed_name(variant);
        let defs = program.naga_oil_defs(variant);
        let mut cache = self.cache();
        let ComposeCache { composer, modules } = &mut *cache;
        let (entry, source) = self.add_imports_of_entry(composer, program, &name)?;
        let key = ComposedKey::new(entry.path, &defs);
        if let Some(module) = modules.get(&key) {
            return Ok(ComposedShader {
                name,
                module: module.clone(),
            });
        }
        let file_path = format!("shaders/{}", entry.path);
        let module = composer
            .make_naga_module(NagaModuleDescriptor {
                source: &source,
                file_path: &file_path,
                shader_type: ShaderType::Wgsl,
                shader_defs: defs,
                additional_imports: &[],
            })
            .map_err(|error| GpuError::Shader {
                module: name.clone(),
                message: error.emit_to_string(composer),
            })?;
        modules.insert(key, module.clone());
        Ok(ComposedShader { name, module })
    }

    /// This library's composer and composed modules (`compose_cache`).
    fn cache(&self) -> std::sync::MutexGuard<'static, ComposeCache> {
        compose_cache::for_library(match self {
            ShaderLibrary::Embedded => None,
            ShaderLibrary::Directory(dir) => Some(dir.clone()),
        })
    }

    /// Composes, validates and creates the wgpu module.
    pub fn create_module(
        &self,
        context: &GpuContext,
        program: &Program,
        variant: MaterialVariant,
    ) -> GpuResult<wgpu::ShaderModule> {
        self.create_composed_module(context, self.compose(program, variant)?)
    }

    /// Creates the wgpu module of a shader already composed (by a caller that also read
    /// something from it, e.g. [`ComposedShader::bindings_used`]).
    pub fn create_composed_module(
        &self,
        context: &GpuContext,
        shader: ComposedShader,
    ) -> GpuResult<wgpu::ShaderModule> {
        context.scoped(&format!("creating shader module {}", shader.name), || {
            context
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(&shader.name),
                    source: wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(shader.module)),
                })
        })
    }

    /// Composes every program in every material variant it has; the names of those that
    /// composed and the errors of those that did not.
    pub fn validate_all(&self, programs: &[Program]) -> Vec<GpuResult<String>> {
        programs
            .iter()
            .flat_map(|program| {
                program
                    .variants()
                    .into_iter()
                    .map(move |variant| self.compose(program, variant).map(|s| s.name))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn import_paths_follow_file_paths() {
        assert_eq!(
            import_path("common/variants/normal_mapped.wgsl"),
            "manylights::common::variants::normal_mapped"
        );
    }
}
