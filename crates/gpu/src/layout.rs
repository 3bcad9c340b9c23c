//! The CPU/GPU contract, checked rather than trusted. Every `#[repr(C)]` struct the CPU
//! writes into a GPU buffer or reads back mirrors a WGSL struct; a test beside each one
//! ([`assert_wgsl_layout!`](crate::assert_wgsl_layout)) compares its size and each field's
//! offset with naga's layout of that WGSL struct in a composed program, so a member added,
//! removed, reordered or re-typed on one side only fails a test instead of corrupting a
//! frame. `cargo xtask test` has a guard that fails when a `Pod` struct has no such test.

use naga_oil::compose::Composer;

use crate::error::GpuResult;
use crate::shaders::{MaterialVariant, Program, ShaderLibrary, import_path};

/// naga's layout of a WGSL struct: its size and its members' (name, offset), in order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WgslStruct {
    pub size: usize,
    pub members: Vec<(String, usize)>,
}

/// The layout of struct `name`, declared in `shaders/<file>`, in `program` as composed
/// from the embedded shaders (default material variant). `None` when the composed module
/// does not contain it (a program only holds the imported structs it reaches).
pub fn wgsl_struct(program: &Program, file: &str, name: &str) -> GpuResult<Option<WgslStruct>> {
    let composed = ShaderLibrary::Embedded.compose(program, MaterialVariant::default())?;
    // naga_oil keeps the entry file's names and decorates those of imported modules.
    let wanted = if file == program.entry {
        name.to_string()
    } else {
        Composer::decorated_name(Some(&import_path(file)), name)
    };
    Ok(composed
        .module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some(wanted.as_str()))
        .and_then(|(_, ty)| match &ty.inner {
            naga::TypeInner::Struct { members, span } => Some(WgslStruct {
                size: *span as usize,
                members: members
                    .iter()
                    .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
                    .collect(),
            }),
            _ => None,
        }))
}

/// Panics unless the WGSL struct `name` of `shaders/<file>`, in `program`, has `size`
/// bytes and exactly `members` (name, offset), in order. Use [`assert_wgsl_layout!`](crate::assert_wgsl_layout)
/// (crate::assert_wgsl_layout), which takes the size and offsets from the Rust type.
#[track_caller]
pub fn assert_struct_layout(
    program: &Program,
    file: &str,
    name: &str,
    size: usize,
    members: &[(&str, usize)],
) {
    let found = wgsl_struct(program, file, name)
        .unwrap_or_else(|error| panic!("{error}"))
        .unwrap_or_else(|| {
            panic!(
                "struct {name} of shaders/{file} is not in program {} (does it reach it?)",
                program.name
            )
        });
    let expected = WgslStruct {
        size,
        members: members
            .iter()
            .map(|&(member, offset)| (member.to_string(), offset))
            .collect(),
    };
    assert_eq!(
        found, expected,
        "WGSL struct {name} (shaders/{file}, left) and its Rust mirror (right) disagree"
    );
}

/// Asserts that a Rust type and the WGSL struct it mirrors have the same size and the same
/// members at the same offsets, naming each WGSL member and the Rust field at its offset
/// (`+ 4` for the second element of a padding array):
///
/// ```ignore
/// assert_wgsl_layout!(program(), "naive/naive.wgsl", ShadingParams == ShadingUniform {
///     light_count: light_count, falloff: falloff, _pad0: _pad, _pad1: _pad + 4,
/// });
/// ```
#[macro_export]
macro_rules! assert_wgsl_layout {
    ($program:expr, $file:literal, $wgsl:ident == $rust:ty {
        $($member:ident : $field:ident $(+ $extra:literal)?),* $(,)?
    }) => {
        $crate::layout::assert_struct_layout(
            &$program,
            $file,
            stringify!($wgsl),
            ::core::mem::size_of::<$rust>(),
            &[$((
                stringify!($member),
                ::core::mem::offset_of!($rust, $field) $(+ $extra)?,
            )),*],
        )
    };
}
