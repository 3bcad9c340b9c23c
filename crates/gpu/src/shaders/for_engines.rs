//! Our WGSL in an engine's own shaders: a composed module written back as one prefixed
//! source ([`ComposedShader::to_wgsl`]) for engines that do not compose with naga_oil, and
//! our modules added to an engine's own naga_oil composer
//! ([`ShaderLibrary::add_to_composer`]) for those that do.

use std::collections::HashMap;

use naga_oil::compose::{Composer, ShaderDefValue};

use super::{ComposedShader, MaterialVariant, Program, ShaderLibrary, add_composable, import_path};
use crate::error::{GpuError, GpuResult};

/// What naga_oil puts between an imported item's name and its module's (encoded) path.
const NAGA_OIL_DECORATION: &str = "X_naga_oil_mod_X";

impl ComposedShader {
    /// The composed module written back as one self-contained WGSL source (no
    /// `#import`s, no shader defs): what a program that does not compose with naga_oil
    /// puts before its own WGSL. Every named item (types, constants, bindings, functions)
    /// gets `prefix` before its name as written in its file, so none collides with the
    /// caller's names: `lights_at` of `cluster/listed_lights.wgsl` becomes
    /// `manylights_lights_at`, its `Light` struct `manylights_Light`. Struct members and
    /// arguments keep their names. Two items of one name in different files are refused
    /// (the prefixed names would collide).
    ///
    /// Only what the entry file's own functions and bindings reach is written: naga_oil
    /// brings an imported module's other items along (the camera binding of
    /// `common/view.wgsl` with any function of a file that imports it), which would
    /// collide with the engine's own bindings. Constants stay, as naga keeps them.
    pub fn to_wgsl(&self, prefix: &str) -> GpuResult<String> {
        let mut module = self.module.clone();
        keep_only_what_the_entry_file_reaches(&mut module);
        let mut renamed: HashMap<String, String> = HashMap::new();
        let mut rename = |name: &mut Option<String>| -> GpuResult<()> {
            let Some(decorated) = name.as_mut() else {
                return Ok(());
            };
            let written = decorated
                .split_once(NAGA_OIL_DECORATION)
                .map_or(decorated.as_str(), |(item, _)| item);
            let prefixed = format!("{prefix}{written}");
            if let Some(other) = renamed.insert(prefixed.clone(), decorated.clone())
                && other != *decorated
            {
                return Err(GpuError::Shader {
                    module: self.name.clone(),
                    message: format!(
                        "two items are named {written} (in different files): {prefixed} would \
                         name both"
                    ),
                });
            }
            *decorated = prefixed;
            Ok(())
        };
        let named_types: Vec<(naga::Handle<naga::Type>, naga::Type)> = module
            .types
            .iter()
            .filter(|(_, ty)| ty.name.is_some())
            .map(|(handle, ty)| (handle, ty.clone()))
            .collect();
        for (handle, mut ty) in named_types {
            rename(&mut ty.name)?;
            // `replace` panics on a value already in the arena: refused before it.
            if module.types.get(&ty).is_some() {
                return Err(GpuError::Shader {
                    module: self.name.clone(),
                    message: format!("a type is already named {:?}", ty.name),
                });
            }
            module.types.replace(handle, ty);
        }
        for (_, constant) in module.constants.iter_mut() {
            rename(&mut constant.name)?;
        }
        for (_, global) in module.global_variables.iter_mut() {
            rename(&mut global.name)?;
        }
        for (_, function) in module.functions.iter_mut() {
            rename(&mut function.name)?;
        }
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .map_err(|error| GpuError::Shader {
            module: self.name.clone(),
            message: format!("the renamed module does not validate: {error}"),
        })?;
        naga::back::wgsl::write_string(&module, &info, naga::back::wgsl::WriterFlags::empty())
            .map_err(|error| GpuError::Shader {
                module: self.name.clone(),
                message: format!("writing WGSL: {error}"),
            })
    }
}

/// The name of the entry point that [`keep_only_what_the_entry_file_reaches`] adds and
/// takes away again.
const ROOTS_ENTRY_POINT: &str = "manylights_roots_of_the_entry_file";

/// Removes the functions and bindings that nothing of the entry file uses. The entry
/// file's items are those naga_oil left undecorated; naga's compaction keeps what entry
/// points reach, so a transient entry point calls each of the entry file's functions (with
/// zero values, or a local for a pointer) and names each of its bindings.
fn keep_only_what_the_entry_file_reaches(module: &mut naga::Module) {
    let is_entry_files = |name: &Option<String>| {
        name.as_deref()
            .is_some_and(|name| !name.contains(NAGA_OIL_DECORATION))
    };
    let mut roots = naga::Function {
        name: Some(ROOTS_ENTRY_POINT.to_string()),
        ..Default::default()
    };
    let span = naga::Span::UNDEFINED;
    for (handle, function) in module.functions.iter() {
        if !is_entry_files(&function.name) {
            continue;
        }
        let arguments = function
            .arguments
            .iter()
            .map(|argument| {
                let value = match module.types[argument.ty].inner {
                    naga::TypeInner::Pointer { base, .. } => {
                        let local = roots.local_variables.append(
                            naga::LocalVariable {
                                name: None,
                                ty: base,
                                init: None,
                            },
                            span,
                        );
                        naga::Expression::LocalVariable(local)
                    }
                    _ => naga::Expression::ZeroValue(argument.ty),
                };
                roots.expressions.append(value, span)
            })
            .collect();
        let result = function.result.as_ref().map(|_| {
            roots
                .expressions
                .append(naga::Expression::CallResult(handle), span)
        });
        roots.body.push(
            naga::Statement::Call {
                function: handle,
                arguments,
                result,
            },
            span,
        );
    }
    for (handle, global) in module.global_variables.iter() {
        if is_entry_files(&global.name) {
            let named = roots
                .expressions
                .append(naga::Expression::GlobalVariable(handle), span);
            roots
                .named_expressions
                .insert(named, format!("root_{}", handle.index()));
        }
    }
    module.entry_points.push(naga::EntryPoint {
        name: ROOTS_ENTRY_POINT.to_string(),
        stage: naga::ShaderStage::Compute,
        early_depth_test: None,
        workgroup_size: [1, 1, 1],
        workgroup_size_overrides: None,
        function: roots,
        mesh_info: None,
        task_payload: None,
        incoming_ray_payload: None,
    });
    naga::compact::compact(module, naga::compact::KeepUnused::No);
    module
        .entry_points
        .retain(|entry_point| entry_point.name != ROOTS_ENTRY_POINT);
}

impl ShaderLibrary {
    /// For an engine that composes its own WGSL with naga_oil (this crate's version,
    /// re-exported as [`naga_oil`]): adds `program`'s entry file as a
    /// composable module (import path `manylights::<its path>`, e.g.
    /// `manylights::cluster::listed_lights`) and every module it imports to the engine's
    /// `composer`, and returns the shader defs the engine passes to its
    /// `make_naga_module` (the Rust constants our WGSL reads and the program's own defs).
    /// The engine's shader then `#import`s from it as from any module of its own.
    pub fn add_to_composer(
        &self,
        composer: &mut Composer,
        program: &Program,
    ) -> GpuResult<HashMap<String, ShaderDefValue>> {
        let (entry, source) = self.add_imports_of_entry(composer, program, &program.name)?;
        if !composer.contains_module(&import_path(entry.path)) {
            add_composable(composer, &entry, &source)?;
        }
        let defs = program.naga_oil_defs(MaterialVariant::default());
        Ok(defs)
    }
}
