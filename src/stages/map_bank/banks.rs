//! How the three logical maps of both buffers are laid out in the map RAM banks
//! (docs/ARCHITECTURE.md, "Map banks and double buffering"), and the banks' init files.
//!
//! With interpolation there are four banks, one per parity pair (i_u[0], i_v[0]), so the four
//! neighbours of an interpolation are always in four different banks; a bank address is
//! {buf, axis[1:0], s_max, s_u, i_u >> 1, s_v, i_v >> 1}. Without interpolation one bank
//! holds {buf, axis[1:0], s_max, s_u, i_u, s_v, i_v}. Axis slot 3 is unused and holds 0.

use super::MapBank;
use crate::config::Config;
use crate::hexfile;
use crate::model::map_addr::MapAddr;
use crate::model::Maps;
use crate::stages::unit::file_param;
use crate::stages::Unit;

/// Where one logical map entry lives: which bank (index into [`bank_names`]) and where in it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BankSlot {
    pub bank: usize,
    pub addr: u32,
}

/// Concatenates (value, width) fields, first field most significant, like Verilog's {a, b}.
fn concat(fields: &[(u32, u32)]) -> u32 {
    fields.iter().fold(0, |acc, &(v, w)| {
        debug_assert!(v < 1 << w, "field {v} wider than {w} bits");
        (acc << w) | v
    })
}

/// Bank name suffixes, in the order the banks are indexed: `<i_u parity><i_v parity>`, or a
/// single unnamed bank without interpolation.
pub fn bank_names(cfg: &Config) -> Vec<String> {
    if cfg.interpolation {
        (0..4).map(|k| format!("{}{}", k & 1, k >> 1)).collect()
    } else {
        vec![String::new()]
    }
}

/// The `$readmemh` file of bank `k`: `<module>.hex` for the only bank, `<module>_<name>.hex`
/// for one of four.
pub fn bank_file(cfg: &Config, k: usize) -> String {
    let module = MapBank.module(cfg);
    let name = &bank_names(cfg)[k];
    if name.is_empty() {
        format!("{module}.hex")
    } else {
        format!("{module}_{name}.hex")
    }
}

/// The init-file parameter of bank `k` in map_lookup and above it: `MAP_BANK_FILE` for the
/// only bank, `MAP_BANK_<name>_FILE` for one of four.
pub fn bank_param(cfg: &Config, k: usize) -> String {
    let name = &bank_names(cfg)[k];
    if name.is_empty() {
        file_param(MapBank.name())
    } else {
        file_param(&format!("{}_{name}", MapBank.name()))
    }
}

/// The instance name of bank `k` in map_lookup.v.
pub fn bank_instance(cfg: &Config, k: usize) -> String {
    let name = &bank_names(cfg)[k];
    if name.is_empty() {
        "u_bank".to_string()
    } else {
        format!("u_bank_{name}")
    }
}

/// The bank and bank address of logical entry `addr` of the map of `axis` in buffer `buf`.
pub fn bank_slot(cfg: &Config, buf: u32, axis: u32, addr: u32) -> BankSlot {
    let a = MapAddr::decode(cfg, addr);
    if cfg.interpolation {
        let ih = cfg.bank_index_bits();
        let bank = ((a.i_u & 1) | ((a.i_v & 1) << 1)) as usize;
        let addr = concat(&[
            (buf, 1),
            (axis, 2),
            (a.s_max, 1),
            (a.s_u, 1),
            (a.i_u >> 1, ih),
            (a.s_v, 1),
            (a.i_v >> 1, ih),
        ]);
        BankSlot { bank, addr }
    } else {
        BankSlot {
            bank: 0,
            addr: concat(&[(buf, 1), (axis, 2), (addr, cfg.map_addr_bits())]),
        }
    }
}

/// The contents of every bank with buffer b holding `buffers[b]`.
pub fn bank_contents(cfg: &Config, buffers: [&Maps; 2]) -> Vec<Vec<u32>> {
    let mut banks = vec![vec![0u32; cfg.bank_entries() as usize]; cfg.bank_count() as usize];
    for (buf, maps) in buffers.iter().enumerate() {
        for axis in 0..3 {
            for (addr, &e) in maps.axis(axis).iter().enumerate() {
                let s = bank_slot(cfg, buf as u32, axis, addr as u32);
                banks[s.bank][s.addr as usize] = e;
            }
        }
    }
    banks
}

/// The init files of the banks, (file name, text), both buffers holding `maps`.
pub fn bank_files(cfg: &Config, maps: &Maps) -> Vec<(String, String)> {
    let layout = if cfg.interpolation {
        "address {buf, axis, s_max, s_u, i_u >> 1, s_v, i_v >> 1}"
    } else {
        "address {buf, axis, s_max, s_u, i_u, s_v, i_v}"
    };
    bank_contents(cfg, [maps, maps])
        .iter()
        .enumerate()
        .map(|(k, data)| {
            let name = &bank_names(cfg)[k];
            let which = if name.is_empty() {
                "map bank".to_string()
            } else {
                format!(
                    "map bank {name} (i_u parity {}, i_v parity {})",
                    &name[..1],
                    &name[1..]
                )
            };
            let what = format!("{which}, {layout}, both buffers the scene's map, axis 3 unused");
            (
                bank_file(cfg, k),
                hexfile::format(cfg, &what, cfg.map_bits, data),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::map_addr;

    fn configs() -> Vec<Config> {
        let d = Config::default();
        vec![
            d.clone(),
            Config {
                interpolation: false,
                interp_bits: 0,
                ..d.clone()
            },
            Config {
                index_bits: 2,
                interp_bits: 1,
                ..d.clone()
            },
            Config {
                index_bits: 6,
                interp_bits: 5,
                ..d
            },
        ]
    }

    #[test]
    fn every_entry_has_its_own_slot() {
        for cfg in configs() {
            let mut seen =
                vec![vec![false; cfg.bank_entries() as usize]; cfg.bank_count() as usize];
            for buf in 0..2 {
                for axis in 0..3 {
                    for addr in 0..cfg.map_entries() {
                        let s = bank_slot(&cfg, buf, axis, addr);
                        assert!(s.addr < cfg.bank_entries(), "{}", cfg.summary());
                        assert!(!seen[s.bank][s.addr as usize], "{} collides", cfg.summary());
                        seen[s.bank][s.addr as usize] = true;
                    }
                }
            }
            // Exactly the axis-3 slots stay free.
            let used: usize = seen.iter().flatten().filter(|&&b| b).count();
            assert_eq!(used, 6 * cfg.map_entries() as usize);
        }
    }

    #[test]
    fn four_neighbours_in_four_banks() {
        let cfg = Config::default();
        for bu in 0..=cfg.base_max() {
            for bv in 0..=cfg.base_max() {
                let mut banks: Vec<usize> = [(0, 0), (1, 0), (0, 1), (1, 1)]
                    .iter()
                    .map(|&(du, dv)| {
                        bank_slot(&cfg, 0, 1, map_addr::addr(&cfg, 1, 0, bu + du, 1, bv + dv)).bank
                    })
                    .collect();
                banks.sort();
                assert_eq!(banks, vec![0, 1, 2, 3]);
            }
        }
    }

    #[test]
    fn decode_inverts_addr() {
        let cfg = Config::default();
        for addr in 0..cfg.map_entries() {
            let a = MapAddr::decode(&cfg, addr);
            assert_eq!(
                map_addr::addr(&cfg, a.s_max, a.s_u, a.i_u, a.s_v, a.i_v),
                addr
            );
        }
    }
}
