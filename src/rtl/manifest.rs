//! `manifest.json`: what a generated directory holds, for tools and for people: the version,
//! the configuration, the modules in instantiation order with their ports and latencies, the
//! top's latency, the memories and every file written.

use super::ports;
use crate::config::Config;
use crate::stages;
use crate::stages::rmap_axis::AxisInfo;
use crate::stages::rmap_lanes::LanesInfo;
use crate::stages::rmap_top::{self, SidebandDelays};
pub use crate::stages::unit::Memory;
use serde::Serialize;

pub const FILE: &str = "manifest.json";

#[derive(Clone, Debug, Serialize)]
pub struct Manifest {
    pub rmapgen_version: &'static str,
    pub config: Config,
    pub config_summary: String,
    /// The design's top module ([`stages::top`]: rmap_axis with `axis`, rmap_lanes with
    /// `lanes` > 1, else rmap_top), with
    /// the configuration's prefix, as every name here.
    pub top: String,
    /// Clock cycles from accepting a sample to its result at the top's outputs.
    pub latency: u32,
    pub sideband_delays: SidebandDelays,
    pub modules: Vec<ModuleInfo>,
    pub memories: Vec<Memory>,
    /// Bits of all memories together.
    pub memory_bits: u64,
    /// Every file of the directory written by the design generator, in writing order.
    pub files: Vec<String>,
    /// The AXI4-Stream `tdata` layouts and `tuser` width (`axis` only; absent without it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis: Option<AxisInfo>,
    /// The lanes: their number, the per-lane ports' packing, the memory bits of one lane
    /// (`lanes` > 1 only; absent without it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lanes: Option<LanesInfo>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ModuleInfo {
    /// The module name, [`crate::stages::Unit::module`].
    pub name: String,
    pub file: String,
    /// The module that instantiates it; null for the top.
    pub parent: Option<String>,
    /// Input to registered output in clock cycles; null for pipe_delay (its DEPTH parameter).
    pub latency: Option<u32>,
    pub ports: Vec<ports::Port>,
}

/// The memory arrays of a configuration, named below the design's top ([`stages::top`]).
pub fn memories(cfg: &Config) -> Vec<Memory> {
    stages::top(cfg).memories(cfg)
}

impl Manifest {
    pub fn new(cfg: &Config, files: Vec<String>) -> Manifest {
        let parents = stages::parents(cfg);
        let modules = stages::modules(cfg)
            .into_iter()
            .map(|m| ModuleInfo {
                name: m.module(cfg),
                file: m.file(cfg),
                parent: parents
                    .iter()
                    .find(|(n, _)| *n == m.name())
                    .and_then(|(_, p)| *p)
                    .map(|p| cfg.prefixed(p)),
                latency: m.latency(cfg),
                ports: m.ports(cfg),
            })
            .collect();
        let memories = memories(cfg);
        Manifest {
            rmapgen_version: env!("CARGO_PKG_VERSION"),
            config: cfg.clone(),
            config_summary: cfg.summary(),
            top: stages::top(cfg).module(cfg),
            latency: rmap_top::top_latency(cfg),
            sideband_delays: rmap_top::sideband_delays(cfg),
            modules,
            memory_bits: memories.iter().map(|m| m.bits).sum(),
            memories,
            files,
            axis: AxisInfo::new(cfg),
            lanes: LanesInfo::new(cfg),
        }
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("the manifest serialises")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_bits_add_up() {
        // Generic (the default): recip 128 x 10, one atan ROM 256 x 6, four banks 1024 x 8.
        let cfg = Config::default();
        let m = Manifest::new(&cfg, vec![]);
        assert_eq!(m.memory_bits, 1280 + 1536 + 4 * 8192);
        assert_eq!(m.memory_bits, cfg.rom_total_bits() + cfg.bank_total_bits());
        assert_eq!(m.latency, 24);
        // iCE40: the atan ROM twice, one copy per read port.
        let ice40 = cfg.for_target(crate::config::Target::Ice40);
        let m = Manifest::new(&ice40, vec![]);
        assert_eq!(m.memory_bits, 1280 + 2 * 1536 + 4 * 8192);
        assert_eq!(
            m.memory_bits,
            cfg.rom_total_bits() + 1536 + cfg.bank_total_bits()
        );
    }

    #[test]
    fn a_lane_costs_its_memories_and_half_a_shared_rom() {
        for l in [2, 4] {
            let cfg = Config {
                lanes: l,
                ..Config::default()
            };
            let m = Manifest::new(&cfg, vec![]);
            let one = Manifest::new(&Config::default(), vec![]).memory_bits;
            // Two lanes share a reciprocal ROM (128 x 10): half of it a lane.
            assert_eq!(m.memory_bits, l as u64 * (one - 640));
            assert_eq!(m.lanes.as_ref().unwrap().memory_bits_per_lane, one - 640);
            assert_eq!(
                m.lanes.as_ref().unwrap().own_memory_bits_per_lane,
                one - 1280
            );
            // On the iCE40 every lane has its own.
            let ice40 = cfg.for_target(crate::config::Target::Ice40);
            let one = Manifest::new(
                &Config::default().for_target(crate::config::Target::Ice40),
                vec![],
            )
            .memory_bits;
            assert_eq!(Manifest::new(&ice40, vec![]).memory_bits, l as u64 * one);
            assert_eq!(m.top, "rmap_lanes");
            assert_eq!(m.latency, 24);
        }
        assert!(Manifest::new(&Config::default(), vec![]).lanes.is_none());
    }
}
