//! What measuring a candidate shares across a search ([`Ctx`]): the test image, the cache of
//! maps ([`MapCache`]) and the pixels that rejected recent candidates ([`Killers`]). Separate
//! because both the search and the lowest-error search (`fit::best`) measure through it.

use super::measure::{self, Errors, Limits, TestImage};
use super::outcome::Candidate;
use super::space;
use super::target::Target;
use crate::config::Config;
use crate::model::map_fit::{self, MapFit};
use crate::model::Maps;
use crate::scene::Scene;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// The maps of each candidate. The sampled map depends only on the index bits, the
/// compensation and the map width (entry directions and quantisation), so it is built once
/// per such key; fitted maps depend on the whole pipeline and are built per candidate.
pub(super) struct MapCache {
    pub(super) fit: MapFit,
    pub(super) shade: crate::scene::PreparedScene,
    pub(super) sampled: Mutex<HashMap<(u32, bool, u32), Arc<Maps>>>,
}

impl MapCache {
    pub(super) fn new(scene: &Scene, fit: MapFit) -> MapCache {
        MapCache {
            fit,
            shade: scene.prepared(),
            sampled: Mutex::new(HashMap::new()),
        }
    }

    pub(super) fn get(&self, cfg: &Config) -> Arc<Maps> {
        let build = |c: &Config| Arc::new(map_fit::contents(c, self.fit, |n| self.shade.shade(n)));
        if self.fit != MapFit::Sample {
            return build(cfg);
        }
        let key = (cfg.index_bits, cfg.compensation, cfg.map_bits);
        if let Some(m) = self.sampled.lock().expect("map cache").get(&key) {
            return m.clone();
        }
        let m = build(cfg);
        self.sampled
            .lock()
            .expect("map cache")
            .entry(key)
            .or_insert(m)
            .clone()
    }
}

/// Pixels that rejected candidates, most recent first: tried first by the next ones.
pub(super) struct Killers(pub(super) Mutex<Vec<usize>>);

impl Killers {
    const KEEP: usize = 24;
    fn snapshot(&self) -> Vec<usize> {
        self.0.lock().expect("killers").clone()
    }
    fn add(&self, k: usize) {
        let mut v = self.0.lock().expect("killers");
        if let Some(p) = v.iter().position(|&x| x == k) {
            v.remove(p);
        }
        v.insert(0, k);
        v.truncate(Self::KEEP);
    }
}

/// Progress of a search: candidates measured, of how many, and a note.
pub type Progress<'a> = &'a (dyn Fn(usize, usize, &str) + Sync);

/// The information bound of each front end (red, frac and recip widths: what
/// [`Model::state`](crate::model::Model::state) depends on, the interface fields being the
/// search's own).
#[derive(Default)]
pub(super) struct Bounds(Mutex<HashMap<(u32, u32, u32), Errors>>);

impl Bounds {
    fn get(&self, cfg: &Config, img: &TestImage) -> Errors {
        let key = (cfg.red_bits, cfg.frac_bits, cfg.recip_bits);
        if let Some(b) = self.0.lock().expect("bounds").get(&key) {
            return *b;
        }
        let b = measure::information_bound(cfg, img);
        self.0.lock().expect("bounds").insert(key, b);
        b
    }
}

pub(super) struct Ctx<'a> {
    pub(super) img: &'a TestImage,
    pub(super) maps: MapCache,
    pub(super) killers: Killers,
    pub(super) bounds: Bounds,
}

impl Ctx<'_> {
    pub(super) fn measure(&self, cfg: &Config, limits: Limits) -> Errors {
        // A front end that cannot meet the limits whatever the contents is rejected before
        // its maps are fitted.
        if limits != Limits::default() {
            let b = self.bounds.get(cfg, self.img);
            if measure::bound_exceeds(&b, &limits, self.img.pixels()) {
                return b;
            }
        }
        let maps = self.maps.get(cfg);
        let (e, worst) = measure::measure(cfg, &maps, self.img, limits, &self.killers.snapshot());
        if !e.complete {
            if let Some(k) = worst {
                self.killers.add(k);
            }
        }
        e
    }

    pub(super) fn candidate(&self, cfg: &Config, errors: Errors, target: &Target) -> Candidate {
        Candidate {
            config: cfg.clone(),
            summary: cfg.summary(),
            bits: space::bits(cfg),
            cells: None,
            fits: None,
            shortage: None,
            meets_target: target.met_by(&errors),
            errors,
        }
    }

    /// A full measurement.
    pub(super) fn full(&self, cfg: &Config, target: &Target) -> Candidate {
        let e = self.measure(cfg, Limits::default());
        self.candidate(cfg, e, target)
    }
}

/// Candidates measured per parallel batch of the lowest-error search (when nothing passes),
/// which measures the whole space.
pub(super) const BATCH: usize = 64;

/// Candidates measured per parallel batch of the search for the cheapest passing one: two
/// per thread, so that the search stops soon after the first pass. Past it, a batch measures
/// dearer candidates that nothing needs, and with a slow map fit (`minimax` at 6 index bits
/// takes minutes) a batch of 64 cost the fixed-front-end search 20 minutes where it needed
/// one.
pub(super) fn search_batch() -> usize {
    (2 * rayon::current_num_threads()).clamp(2, BATCH)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampled_maps_depend_only_on_the_cache_key() {
        let scene = Scene::alternate();
        let cache = MapCache::new(&scene, MapFit::Sample);
        for c in space::candidates(&Config::default(), &space::Fixed::default())
            .iter()
            .step_by(977)
        {
            assert_eq!(*cache.get(c), scene.maps(c), "{}", c.summary());
        }
    }
}
