//! `cargo xtask limits`: what each program's entry points need of a WebGPU adapter, read
//! from the composed modules with naga (so the table in docs/webgpu-limits.md comes from the
//! code): the storage buffers, uniform buffers and textures an entry point uses, the bind
//! groups it reaches, its workgroup storage and its invocations per workgroup, against
//! the limits every WebGPU adapter guarantees. A program is listed in its most demanding
//! material variant. The pipelines' layouts themselves are held to those limits by
//! `tests/webgpu_limits.rs`, which renders every option on a device with exactly them.

use manylights_gpu::{Program, ShaderLibrary};

/// What every WebGPU adapter guarantees (`wgpu::Limits::default()`).
const STORAGE_BUFFERS: usize = 8;
const BIND_GROUPS: u32 = 4;
const WORKGROUP_STORAGE_BYTES: u32 = 16_384;
const INVOCATIONS: u32 = 256;

#[derive(Debug, Default, Clone)]
struct EntryNeeds {
    storage_buffers: usize,
    uniform_buffers: usize,
    textures: usize,
    groups: u32,
    workgroup_bytes: u32,
    invocations: u32,
}

fn entry_needs(module: &naga::Module, info: &naga::valid::ModuleInfo, index: usize) -> EntryNeeds {
    let uses = info.get_entry_point(index);
    let point = &module.entry_points[index];
    let mut layouter = naga::proc::Layouter::default();
    let _ = layouter.update(module.to_ctx());
    let mut needs = EntryNeeds {
        invocations: point.workgroup_size.iter().product(),
        ..EntryNeeds::default()
    };
    for (handle, variable) in module.global_variables.iter() {
        if uses[handle].is_empty() {
            continue;
        }
        if let Some(binding) = &variable.binding {
            needs.groups = needs.groups.max(binding.group + 1);
        }
        match variable.space {
            naga::AddressSpace::Storage { .. } => needs.storage_buffers += 1,
            naga::AddressSpace::Uniform => needs.uniform_buffers += 1,
            naga::AddressSpace::Handle => {
                if matches!(
                    module.types[variable.ty].inner,
                    naga::TypeInner::Image { .. }
                ) {
                    needs.textures += 1;
                }
            }
            naga::AddressSpace::WorkGroup => needs.workgroup_bytes += layouter[variable.ty].size,
            _ => {}
        }
    }
    needs
}

fn worst_of(a: &EntryNeeds, b: &EntryNeeds) -> EntryNeeds {
    EntryNeeds {
        storage_buffers: a.storage_buffers.max(b.storage_buffers),
        uniform_buffers: a.uniform_buffers.max(b.uniform_buffers),
        textures: a.textures.max(b.textures),
        groups: a.groups.max(b.groups),
        workgroup_bytes: a.workgroup_bytes.max(b.workgroup_bytes),
        invocations: a.invocations.max(b.invocations),
    }
}

/// One row per program and entry point: its needs in its most demanding variant (material
/// variants, and the light loop's variants of one program, `name (falloff, ...)`, are one
/// row).
fn rows(programs: &[Program]) -> anyhow::Result<Vec<(String, String, EntryNeeds)>> {
    let library = ShaderLibrary::Embedded;
    let mut worst: Vec<(String, String, EntryNeeds)> = Vec::new();
    for program in programs {
        let family = program
            .name
            .split(" (")
            .next()
            .unwrap_or(&program.name)
            .to_string();
        for variant in program.variants() {
            let composed = library.compose(program, variant)?;
            let info = naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            )
            .validate(&composed.module)?;
            for (index, point) in composed.module.entry_points.iter().enumerate() {
                let needs = entry_needs(&composed.module, &info, index);
                let known = worst
                    .iter_mut()
                    .find(|(name, entry, _)| *name == family && *entry == point.name);
                match known {
                    Some((_, _, known)) => *known = worst_of(known, &needs),
                    None => worst.push((family.clone(), point.name.clone(), needs)),
                }
            }
        }
    }
    Ok(worst)
}

/// Where `cargo xtask limits` writes its table (a test holds the file to the code).
pub const LIMITS_DOC: &str = "docs/webgpu-limits.md";

/// The Markdown of [`LIMITS_DOC`]: what each entry point needs, and the programs over the
/// limits every adapter guarantees (empty when every one fits).
pub fn limits_doc(
    catalogues: &[(&'static manylights_gpu::ShaderModules, Vec<Program>)],
) -> anyhow::Result<(String, Vec<String>)> {
    let mut doc = format!(
        "# What each program needs of a WebGPU adapter\n\n\
         Written by `cargo xtask limits` from the composed modules (naga's analysis of each \
         entry point); a test fails when this file and the code disagree. Each row is the \
         most demanding material variant of its program; \"-\" marks a render stage. \
         docs/architecture/page.md says how the pipelines stay within these limits.\n\n\
         | program | entry point | storage buffers (WebGPU: {STORAGE_BUFFERS}) | uniforms | textures | bind groups (WebGPU: {BIND_GROUPS}) | workgroup storage (WebGPU: {WORKGROUP_STORAGE_BYTES} B) | invocations (WebGPU: {INVOCATIONS}) |\n\
         |---|---|---:|---:|---:|---:|---:|---:|\n"
    );
    let mut over = Vec::new();
    for (_, programs) in catalogues {
        for (program, entry, needs) in rows(programs)? {
            let mut flag = |value: u64, limit: u64| {
                if value > limit {
                    over.push(format!("{program} {entry}"));
                    format!("**{value}**")
                } else {
                    value.to_string()
                }
            };
            let storage = flag(needs.storage_buffers as u64, STORAGE_BUFFERS as u64);
            let groups = flag(u64::from(needs.groups), u64::from(BIND_GROUPS));
            let shared = flag(
                u64::from(needs.workgroup_bytes),
                u64::from(WORKGROUP_STORAGE_BYTES),
            );
            let invocations = match needs.invocations {
                0 => "-".to_string(),
                n => flag(u64::from(n), u64::from(INVOCATIONS)),
            };
            doc.push_str(&format!(
                "| {program} | {entry} | {storage} | {} | {} | {groups} | {shared} | {invocations} |\n",
                needs.uniform_buffers, needs.textures
            ));
        }
    }
    Ok((doc, over))
}

/// `cargo xtask limits`: prints the table and writes it to [`LIMITS_DOC`]; fails when a
/// program is over the limits.
pub fn limits(
    catalogues: &[(&'static manylights_gpu::ShaderModules, Vec<Program>)],
) -> anyhow::Result<()> {
    let (doc, over) = limits_doc(catalogues)?;
    print!("{doc}");
    let path = crate::web::workspace_root().join(LIMITS_DOC);
    std::fs::write(&path, &doc)?;
    println!("wrote {}", path.display());
    if !over.is_empty() {
        anyhow::bail!("over WebGPU's guaranteed limits: {}", over.join(", "));
    }
    Ok(())
}
