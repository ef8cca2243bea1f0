//! `manifest.json`: what a generated directory holds, for tools and for people: the version,
//! the configuration, the modules in instantiation order with their ports and latencies, the
//! top's latency, the memories and every file written.

use super::{banks, latency, modules, ports, sideband_delays, Module, SidebandDelays};
use crate::config::Config;
use serde::Serialize;

pub const FILE: &str = "manifest.json";

#[derive(Clone, Debug, Serialize)]
pub struct Manifest {
    pub rmapgen_version: &'static str,
    pub config: Config,
    pub config_summary: String,
    pub top: &'static str,
    /// Clock cycles from accepting a sample to its result at the top's outputs.
    pub latency: u32,
    pub sideband_delays: SidebandDelays,
    pub modules: Vec<ModuleInfo>,
    pub memories: Vec<Memory>,
    /// Bits of all memories together.
    pub memory_bits: u64,
    /// Every file of the directory written by the design generator, in writing order.
    pub files: Vec<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ModuleInfo {
    pub name: &'static str,
    pub file: String,
    /// The module that instantiates it; null for the top.
    pub parent: Option<&'static str>,
    /// Input to registered output in clock cycles; null for pipe_delay (its DEPTH parameter).
    pub latency: Option<u32>,
    pub ports: Vec<ports::Port>,
}

/// One memory array of the design.
#[derive(Clone, Debug, Serialize)]
pub struct Memory {
    /// Hierarchical name below rmap_top.
    pub instance: String,
    pub module: &'static str,
    pub init_file: String,
    pub entries: u32,
    pub width: u32,
    pub bits: u64,
    pub writable: bool,
}

fn memory(
    instance: &str,
    module: Module,
    init_file: String,
    entries: u32,
    width: u32,
    writable: bool,
) -> Memory {
    Memory {
        instance: instance.to_string(),
        module: module.name(),
        init_file,
        entries,
        width,
        bits: entries as u64 * width as u64,
        writable,
    }
}

/// The memory arrays of a configuration.
pub fn memories(cfg: &Config) -> Vec<Memory> {
    let mut v = vec![memory(
        "u_normalise.u_recip_rom.rom",
        Module::RecipRom,
        "recip_rom.hex".into(),
        cfg.recip_entries(),
        cfg.recip_bits,
        false,
    )];
    if cfg.compensation {
        for rom in ["rom_u", "rom_v"] {
            v.push(memory(
                &format!("u_atan_rom.{rom}"),
                Module::AtanRom,
                "atan_rom.hex".into(),
                cfg.atan_entries(),
                cfg.pos_bits(),
                false,
            ));
        }
    }
    for (k, name) in banks::bank_names(cfg).iter().enumerate() {
        let inst = if name.is_empty() {
            "u_bank".to_string()
        } else {
            format!("u_bank_{name}")
        };
        v.push(memory(
            &format!("u_map_lookup.{inst}.mem"),
            Module::MapBank,
            banks::bank_file(cfg, k),
            cfg.bank_entries(),
            cfg.map_bits,
            true,
        ));
    }
    v
}

impl Manifest {
    pub fn new(cfg: &Config, files: Vec<String>) -> Manifest {
        let modules = modules(cfg)
            .into_iter()
            .map(|m| ModuleInfo {
                name: m.name(),
                file: m.file(),
                parent: m.parent().map(Module::name),
                latency: latency(cfg, m),
                ports: ports::ports(cfg, m),
            })
            .collect();
        let memories = memories(cfg);
        Manifest {
            rmapgen_version: env!("CARGO_PKG_VERSION"),
            config: cfg.clone(),
            config_summary: cfg.summary(),
            top: Module::RmapTop.name(),
            latency: super::top_latency(cfg),
            sideband_delays: sideband_delays(cfg),
            modules,
            memory_bits: memories.iter().map(|m| m.bits).sum(),
            memories,
            files,
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
        let cfg = Config::default();
        let m = Manifest::new(&cfg, vec![]);
        // recip 128 x 10, two atan copies 256 x 6, four banks of 1024 x 8.
        assert_eq!(m.memory_bits, 1280 + 2 * 1536 + 4 * 8192);
        assert_eq!(
            m.memory_bits,
            cfg.rom_total_bits() + 1536 + cfg.bank_total_bits()
        );
        assert_eq!(m.latency, 24);
    }
}
