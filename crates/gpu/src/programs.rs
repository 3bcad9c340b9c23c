//! This crate's programs in one list (the xtask validates every program of every crate,
//! and the tests below compose them). Each program is defined beside the pass that runs
//! it; this file only gathers them, so the shader registry (`shaders.rs`) knows no pass.

use crate::shaders::Program;

/// The programs of this crate: the unlit base colour, the full-precision surface capture,
/// mip generation, automatic exposure and the tonemap, temporal anti-aliasing, bloom and
/// the weighted blended composite.
pub fn programs() -> Vec<Program> {
    vec![
        crate::base_color::program(),
        crate::surface::program(manylights_scene::Shading::Pbr),
        crate::surface::program(manylights_scene::Shading::BlinnPhong),
        crate::mipmap::program(),
        crate::post::auto_exposure_program(),
        crate::post::tonemap_program(),
        crate::taa::program(),
        crate::bloom::program(),
        crate::blended::composite_program(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shaders::{
        MaterialVariant, Program, SHADERS, ShaderFile, ShaderLibrary, ShaderModules, no_constants,
    };

    #[test]
    fn every_program_of_this_crate_validates() {
        for result in ShaderLibrary::Embedded.validate_all(&programs()) {
            if let Err(error) = result {
                panic!("{error}");
            }
        }
    }

    #[test]
    fn material_variants_select_their_files() {
        // Only the textured variant binds a base colour texture.
        let base_color = crate::base_color::program();
        let has_texture = |variant| {
            let shader = ShaderLibrary::Embedded
                .compose(&base_color, variant)
                .expect("compose");
            shader.module.global_variables.iter().any(|(_, g)| {
                g.binding.is_some()
                    // Items of imported modules carry naga_oil's module suffix.
                    && g.name.as_deref().is_some_and(|n| n.starts_with("base_color_texture"))
            })
        };
        assert!(!has_texture(MaterialVariant::default()));
        assert!(has_texture(MaterialVariant {
            base_color_texture: true,
            ..Default::default()
        }));
    }

    fn copy_of_gpu_shaders() -> tempfile::TempDir {
        let dir = tempfile::tempdir().expect("tempdir");
        for file in SHADERS.files {
            let path = dir.path().join(file.path);
            std::fs::create_dir_all(path.parent().expect("parent")).expect("mkdir");
            std::fs::write(path, file.source).expect("write");
        }
        dir
    }

    #[test]
    fn a_broken_shader_is_rejected_with_its_file_and_line() {
        let dir = copy_of_gpu_shaders();
        // A type error on line 3 of an imported module.
        let broken = "// broken on purpose\n\nfn broken() -> u32 { return 1.5; }\nfn relative_to_origin(p: vec3<f32>) -> vec3<f32> { return p; }\n";
        std::fs::write(dir.path().join("common/view.wgsl"), broken).expect("write");
        let library = ShaderLibrary::Directory(dir.path().to_path_buf());
        let error = library
            .compose(&crate::base_color::program(), MaterialVariant::default())
            .expect_err("must fail")
            .to_string();
        // The file, and the offending line with its number in the margin.
        assert!(error.contains("shaders/common/view.wgsl"), "{error}");
        assert!(error.contains("3 │ fn broken() -> u32"), "{error}");
    }

    #[test]
    fn an_import_nobody_declares_is_an_error_naming_it() {
        let dir = copy_of_gpu_shaders();
        let entry = dir.path().join("gpu/mipmap.wgsl");
        let source = std::fs::read_to_string(&entry).expect("read");
        let renamed = source.replace(
            "manylights::common::fullscreen::",
            "manylights::nowhere::missing::",
        );
        assert_ne!(renamed, source);
        std::fs::write(&entry, renamed).expect("write");
        let library = ShaderLibrary::Directory(dir.path().to_path_buf());
        let error = library
            .compose(&crate::mipmap::program(), MaterialVariant::default())
            .expect_err("must fail")
            .to_string();
        assert!(error.contains("manylights::nowhere::missing"), "{error}");
        assert!(error.contains("shaders/gpu/mipmap.wgsl"), "{error}");
    }

    /// The shared composer already holds every module the full set imports; a program
    /// whose own module sets lack one of them must still fail, naming the import.
    #[test]
    fn a_module_another_program_added_is_no_import_of_a_set_without_it() {
        let library = ShaderLibrary::Embedded;
        let full = crate::mipmap::program();
        library
            .compose(&full, MaterialVariant::default())
            .expect("the mipmap program composes with its own module sets");
        let entry_only: &'static [ShaderFile] = Box::leak(Box::new([*SHADERS
            .files
            .iter()
            .find(|file| file.path == full.entry)
            .expect("the entry file")]));
        let without_imports: &'static ShaderModules = Box::leak(Box::new(ShaderModules {
            owner: "test",
            files: entry_only,
            uses: &[],
            constants: no_constants,
        }));
        let error = library
            .compose(
                &Program::new("mipmap without its imports", without_imports, full.entry),
                MaterialVariant::default(),
            )
            .expect_err("an import outside the program's module sets")
            .to_string();
        assert!(
            error.contains("which no module set it uses declares"),
            "{error}"
        );
    }

    /// The same program and defs compose to the same module from the cache; other defs to
    /// another module.
    #[test]
    fn a_program_composed_again_is_the_same_and_other_defs_compose_anew() {
        let library = ShaderLibrary::Embedded;
        let compose = |program: &Program| {
            let composed = library
                .compose(program, MaterialVariant::default())
                .expect("composes");
            format!("{:?}", composed.module)
        };
        let pbr = crate::surface::program(manylights_scene::Shading::Pbr);
        let blinn_phong = crate::surface::program(manylights_scene::Shading::BlinnPhong);
        let first = compose(&pbr);
        assert_eq!(compose(&pbr), first);
        assert_ne!(compose(&blinn_phong), first);
    }
}
