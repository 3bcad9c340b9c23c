//! The shader library's compose cache (`ShaderLibrary::compose`, in `shaders.rs`).
//!
//! What composing costs is mostly naga_oil's: a new composer compiles its regular
//! expressions, and every imported module is preprocessed and parsed again for each program
//! (a renderer composes twenty programs or more, a test binary creates dozens of renderers:
//! composing was a fifth of the clustered tests' time on lavapipe, and validating
//! deferred's programs took 70 s). So one composer per library keeps the modules it has
//! built (naga_oil keys each by the shader defs it reads), and each composed program is
//! kept by its entry file and defs: the same inputs compose to the same module. A
//! [`ShaderLibrary::Directory`](crate::shaders::ShaderLibrary::Directory)'s files are
//! read once per process (a mutant or a validation run is a process of its own).

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{LazyLock, Mutex, MutexGuard};

use naga_oil::compose::{Composer, ShaderDefValue};

/// One library's composer and the programs composed from it.
pub(crate) struct ComposeCache {
    pub(crate) composer: Composer,
    pub(crate) modules: HashMap<ComposedKey, naga::Module>,
}

impl ComposeCache {
    fn empty() -> Self {
        Self {
            // Programs may use optional features (the primitive index); wgpu checks a
            // module against its device's features when it is created.
            composer: Composer::default().with_capabilities(naga::valid::Capabilities::all()),
            modules: HashMap::new(),
        }
    }
}

/// A composed program: its entry file and every shader def it was composed with, sorted.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub(crate) struct ComposedKey {
    entry: &'static str,
    defs: Vec<(String, String)>,
}

impl ComposedKey {
    pub(crate) fn new(entry: &'static str, defs: &HashMap<String, ShaderDefValue>) -> Self {
        let mut defs: Vec<(String, String)> = defs
            .iter()
            .map(|(name, value)| (name.clone(), format!("{value:?}")))
            .collect();
        defs.sort_unstable();
        Self { entry, defs }
    }
}

/// The compose caches, one per library (`None`: the embedded shaders). Each is leaked:
/// it lives as long as the process.
static COMPOSE_CACHES: LazyLock<Mutex<HashMap<Option<PathBuf>, &'static Mutex<ComposeCache>>>> =
    LazyLock::new(|| Mutex::new(HashMap::new()));

/// The composer and composed modules of `library` (`None`: the embedded shaders), shared
/// by every compose in the process. A compose that panicked may have left its composer
/// half-built: the next one starts from an empty cache.
pub(crate) fn for_library(library: Option<PathBuf>) -> MutexGuard<'static, ComposeCache> {
    // The map's lock is released before the library's is taken: a long compose of one
    // library does not hold up another's.
    let cache: &'static Mutex<ComposeCache> = COMPOSE_CACHES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .entry(library)
        .or_insert_with(|| Box::leak(Box::new(Mutex::new(ComposeCache::empty()))));
    cache.lock().unwrap_or_else(|poisoned| {
        cache.clear_poison();
        let mut guard = poisoned.into_inner();
        *guard = ComposeCache::empty();
        guard
    })
}
