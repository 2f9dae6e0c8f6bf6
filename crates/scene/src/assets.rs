//! The assets one load has read and built — meshes with their BVHs, textures, terrains with
//! their pyramids — kept by what shapes them, so that a file resolved twice in one load (an
//! included file is validated alone, on an account of its own, then resolved again as part of
//! the scene) reads and builds each of them once. Each account an asset is used on is charged
//! for it once: what the first build charged is charged again on another account.

use fray_core::MemoryBudget;
use std::collections::HashMap;
use std::hash::Hash;
use std::sync::Arc;

/// One asset and what building it charged.
struct Loaded<T> {
    asset: Arc<T>,
    bytes: u64,
    /// The accounts it is charged on.
    charged_on: Vec<MemoryBudget>,
}

/// Assets of one kind, by key.
pub(crate) struct AssetStore<K, T> {
    loaded: HashMap<K, Loaded<T>>,
    /// How many were built (not found): for the tests.
    pub(crate) builds: usize,
}

impl<K, T> Default for AssetStore<K, T> {
    fn default() -> Self {
        Self {
            loaded: HashMap::new(),
            builds: 0,
        }
    }
}

impl<K: Eq + Hash, T> AssetStore<K, T> {
    /// The asset of `key`: built by `build` (which charges `budget` as it goes) the first time;
    /// afterwards the same one, charged to `budget` — as `what` — if its account has not paid
    /// for it yet. `charge` turns a budget refusal into the caller's error.
    pub(crate) fn get_or_build<E>(
        &mut self,
        key: K,
        budget: &MemoryBudget,
        what: impl FnOnce() -> String,
        build: impl FnOnce() -> Result<T, E>,
        charge: impl FnOnce(fray_core::BudgetError) -> E,
    ) -> Result<Arc<T>, E> {
        if let Some(loaded) = self.loaded.get_mut(&key) {
            if !loaded.charged_on.iter().any(|b| b.same_account(budget)) {
                budget.charge(what(), loaded.bytes).map_err(charge)?;
                loaded.charged_on.push(budget.clone());
            }
            return Ok(loaded.asset.clone());
        }
        let before = budget.charged();
        let asset = Arc::new(build()?);
        self.builds += 1;
        let bytes = budget.charged().saturating_sub(before);
        self.loaded.insert(
            key,
            Loaded {
                asset: asset.clone(),
                bytes,
                charged_on: vec![budget.clone()],
            },
        );
        Ok(asset)
    }
}

/// Every asset store of a load.
#[derive(Default)]
pub(crate) struct LoadedAssets {
    pub(crate) meshes: AssetStore<std::path::PathBuf, fray_mesh::PacketBvh>,
    pub(crate) textures: AssetStore<(std::path::PathBuf, bool), fray_mesh::Texture>,
    /// By file and the description that shaped the terrain (its `Debug` text).
    pub(crate) terrains: AssetStore<(std::path::PathBuf, String), fray_terrain::Terrain>,
}
