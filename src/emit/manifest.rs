//! `manifest.json`: what a generated directory holds, for tools and for people: the version,
//! the configuration, the modules in instantiation order with their ports and latencies, the
//! top's latency, the memories and every file written.

use crate::config::Config;
use crate::hdl::ports;
use crate::scene::Scene;
use crate::stages;
use crate::stages::rmap_axis::AxisInfo;
use crate::stages::rmap_lanes::LanesInfo;
use crate::stages::rmap_top::{self, SidebandDelays};
pub use crate::stages::unit::Memory;
use serde::{Deserialize, Serialize};

pub const FILE: &str = "manifest.json";

/// The test vectors a design directory holds (`generate --vectors N --seed S`): what
/// `roms --update` writes again for new maps, so the design stays consistent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VectorsInfo {
    /// Seeded random vectors per stage, after the corner cases.
    pub random: usize,
    pub seed: u64,
}

/// The FuseSoC core of a design, named by one rule: after the module users instantiate, the
/// design's top ([`stages::top`]: rmap_axis with `axis`, rmap_lanes with lanes, else rmap_top),
/// which is also the core's toplevel; its `sim` target runs that module's own testbench. The
/// core writer and the README writer (`emit::package`) and the manifest all read it from here.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Core {
    /// The core file, `<top>.core`.
    pub file: String,
    /// Its VLNV name, `rmapgen:ip:<top>_<hash>:<version>`: the hash ([`config_hash`]) tells
    /// two configurations apart even without a prefix, and one configuration always has the
    /// same name.
    pub name: String,
    /// The design's top, the toplevel of its `default`, `lint` and `synth` targets.
    pub toplevel: String,
    /// The top's testbench module (`<top>_tb`), the toplevel of its `sim` target.
    pub sim_toplevel: String,
}

impl Core {
    pub fn new(cfg: &Config) -> Core {
        let top = stages::top(cfg).module(cfg);
        Core {
            file: format!("{top}.core"),
            name: format!(
                "rmapgen:ip:{top}_{}:{}",
                config_hash(cfg),
                env!("CARGO_PKG_VERSION")
            ),
            sim_toplevel: format!("{top}_tb"),
            toplevel: top,
        }
    }
}

/// The configuration's hash: [`crate::config::config_hash`], defined with the configuration
/// (the register block's CFG_HASH holds it too).
pub use crate::config::config_hash;

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
    /// The FuseSoC core among them: its file, its name and its toplevels.
    pub core: Core,
    /// Where the maps of buffer 0 come from: the scene's name (`scenes/standard.toml`, a
    /// file's name) and the scene itself, its `map_fit` the one that filled the maps.
    pub scene_name: String,
    pub scene: Scene,
    /// The test vectors in `vectors/` (absent when the directory has none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vectors: Option<VectorsInfo>,
    /// The AXI4-Stream `tdata` layouts and `tuser` width (`axis` only; absent without it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis: Option<AxisInfo>,
    /// The lanes: their number, the per-lane ports' packing, the memory bits of one lane
    /// (`lanes` > 1 only; absent without it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lanes: Option<LanesInfo>,
    /// The bus slave: its bus, the register map, the views' files and the vector file whose
    /// samples its testbench streams (`bus` only; absent without it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bus: Option<crate::stages::rmap_bus::BusInfo>,
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

/// The block RAMs of `family` that memory `m` takes, as Yosys maps it (a copy per read port
/// where a block has fewer; the FPGA checks compare with Yosys, memory by memory).
pub fn block_rams_of(m: &Memory, family: crate::family::Family) -> u32 {
    family.get().block_ram.blocks(m.entries, m.width, m.reads)
}

/// The block RAMs of `family` that `cfg`'s memories take, written for it (`--target
/// <family>`: what `rmapgen fpga --family <family>` places).
pub fn block_rams(cfg: &Config, family: crate::family::Family) -> u32 {
    let cfg = cfg.for_target(crate::config::Target::Family(family));
    memories(&cfg)
        .iter()
        .map(|m| block_rams_of(m, family))
        .sum()
}

impl Manifest {
    /// The manifest of configuration `cfg` whose maps are `scene`'s, listing `files`, with
    /// `vectors` when the directory holds test vectors.
    pub fn new(
        cfg: &Config,
        scene: &Scene,
        vectors: Option<VectorsInfo>,
        files: Vec<String>,
    ) -> Manifest {
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
            core: Core::new(cfg),
            scene_name: scene.name.clone(),
            scene: scene.clone(),
            vectors,
            axis: AxisInfo::new(cfg),
            lanes: LanesInfo::new(cfg),
            bus: crate::stages::rmap_bus::BusInfo::new(cfg),
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
        let m = Manifest::new(&cfg, &Scene::standard(), None, vec![]);
        assert_eq!(m.memory_bits, 1280 + 1536 + 4 * 8192);
        assert_eq!(m.memory_bits, cfg.rom_total_bits() + cfg.bank_total_bits());
        assert_eq!(m.latency, 24);
        // iCE40: the atan ROM twice, one copy per read port.
        let ice40 = cfg.for_target(crate::config::Target::Family(crate::family::Family::Ice40));
        let m = Manifest::new(&ice40, &Scene::standard(), None, vec![]);
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
            let m = Manifest::new(&cfg, &Scene::standard(), None, vec![]);
            let one =
                Manifest::new(&Config::default(), &Scene::standard(), None, vec![]).memory_bits;
            // Two lanes share a reciprocal ROM (128 x 10): half of it a lane.
            assert_eq!(m.memory_bits, l as u64 * (one - 640));
            assert_eq!(m.lanes.as_ref().unwrap().memory_bits_per_lane, one - 640);
            assert_eq!(
                m.lanes.as_ref().unwrap().own_memory_bits_per_lane,
                one - 1280
            );
            // On the iCE40 every lane has its own.
            let ice40 = cfg.for_target(crate::config::Target::Family(crate::family::Family::Ice40));
            let one = Manifest::new(
                &Config::default()
                    .for_target(crate::config::Target::Family(crate::family::Family::Ice40)),
                &Scene::standard(),
                None,
                vec![],
            )
            .memory_bits;
            assert_eq!(
                Manifest::new(&ice40, &Scene::standard(), None, vec![]).memory_bits,
                l as u64 * one
            );
            assert_eq!(m.top, "rmap_lanes");
            assert_eq!(m.latency, 24);
        }
        assert!(
            Manifest::new(&Config::default(), &Scene::standard(), None, vec![])
                .lanes
                .is_none()
        );
    }
}
