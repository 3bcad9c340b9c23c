//! [`Specialized`]: pipelines built the first time a frame asks for their key and kept for
//! every later frame with that key (Bevy's `SpecializedRenderPipelines`, without the
//! descriptor step).
//!
//! The key names everything a pipeline is specialized for: a pass's light loop, its
//! blending, the targets' samples a pixel, and so on. A frame that changes one dial
//! therefore builds only the pipelines whose key that dial is part of, and a frame that
//! comes back to an earlier dial finds its pipelines still built. Nothing is ever dropped
//! while the owner lives: the keys a user can reach are a small, fixed set (the largest,
//! Forward+'s, is light loops x pre-pass x sample counts), and dropping would turn a dial
//! moved back and forth into a shader compilation each time (the soak test moved
//! reverse-Z back and forth and rebuilt every pipeline each time, when the renderer still
//! dropped them).

use std::collections::HashMap;
use std::hash::Hash;

use crate::error::GpuResult;

/// Values (pipelines, or the sets of pipelines one key needs) built on first use, one per
/// key.
#[derive(Debug)]
pub struct Specialized<K, V> {
    built: HashMap<K, V>,
}

impl<K, V> Default for Specialized<K, V> {
    fn default() -> Self {
        Self {
            built: HashMap::new(),
        }
    }
}

impl<K: Copy + Eq + Hash, V> Specialized<K, V> {
    /// The value for `key`, built by `build` if no frame has asked for it before. A build
    /// that fails leaves nothing behind: the next frame with this key tries again.
    pub fn get_or_build(
        &mut self,
        key: K,
        build: impl FnOnce(K) -> GpuResult<V>,
    ) -> GpuResult<&mut V> {
        use std::collections::hash_map::Entry;
        match self.built.entry(key) {
            Entry::Occupied(entry) => Ok(entry.into_mut()),
            Entry::Vacant(entry) => Ok(entry.insert(build(key)?)),
        }
    }

    /// The value for `key`, if a frame has built it.
    pub fn get(&self, key: &K) -> Option<&V> {
        self.built.get(key)
    }

    /// How many keys have been built (what tests count to see that a dial built only
    /// what its key names).
    pub fn len(&self) -> usize {
        self.built.len()
    }

    pub fn is_empty(&self) -> bool {
        self.built.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::GpuError;

    #[test]
    fn each_key_is_built_once_and_a_failed_build_leaves_nothing() {
        let mut cache: Specialized<u32, String> = Specialized::default();
        let mut builds = 0;
        for key in [1, 2, 1, 2, 1] {
            let value = cache
                .get_or_build(key, |k| {
                    builds += 1;
                    Ok(format!("pipeline {k}"))
                })
                .expect("builds");
            assert_eq!(*value, format!("pipeline {key}"));
        }
        assert_eq!((builds, cache.len()), (2, 2));

        let failed = cache.get_or_build(3, |_| Err(GpuError::Unsupported("no".into())));
        assert!(failed.is_err());
        assert_eq!(cache.len(), 2, "a failed build is not kept");
        assert!(cache.get(&3).is_none());
        cache
            .get_or_build(3, |_| Ok("built on the retry".into()))
            .expect("a retry builds");
        assert_eq!(cache.len(), 3);
    }
}
