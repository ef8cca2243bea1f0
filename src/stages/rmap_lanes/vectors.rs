//! The lanes top's vectors are the top's own (`vectors/<rmap_top>.hex`, the model's results
//! with the map swap): every lane runs the same model, so the testbench deals them out to the
//! lanes in file order, lane 0 first in each beat, with random per-lane valid bits.

use super::RmapLanes;
use crate::config::Config;
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::stages::rmap_top::RmapTop;
use crate::stages::testbench::TbData;
use crate::stages::unit::{Traced, Vectors};
use crate::vectors::field::Field;
use anyhow::Result;
use askama::Template;

crate::tb_template!(Testbench, "rmap_lanes/rmap_lanes_tb.v");

impl Vectors for RmapLanes {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        RmapTop.fields(cfg)
    }

    fn corners(&self, model: &Model, maps: &MapSet) -> Vec<Vec<u64>> {
        RmapTop.corners(model, maps)
    }

    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        RmapTop.random(cfg, rng)
    }

    fn expected(&self, model: &Model, maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        RmapTop.expected(model, maps, inp)
    }

    fn traced(&self, cfg: &Config, s: &Traced) -> Vec<u64> {
        RmapTop.traced(cfg, s)
    }

    /// The top's stream, vector for vector (the same file).
    fn inputs(
        &self,
        model: &Model,
        maps: &MapSet,
        random: usize,
        seed: u64,
        emit: &mut dyn FnMut(&[u64]) -> Result<()>,
    ) -> Result<()> {
        RmapTop.inputs(model, maps, random, seed, emit)
    }

    fn port(&self, field: &Field) -> Option<String> {
        RmapTop.port(field)
    }

    fn reset_at(&self, cfg: &Config) -> u32 {
        RmapTop.reset_at(cfg)
    }

    fn lanes(&self, cfg: &Config) -> u32 {
        cfg.lanes
    }

    /// The top's vector file: the lanes read the same vectors.
    fn vector_file(&self, cfg: &Config) -> String {
        RmapTop.vector_file(cfg)
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
