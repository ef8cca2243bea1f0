//! The lanes top, rmap_lanes (`lanes` > 1): `lanes` copies of [`RmapTop`] side by side, so
//! the design takes L samples and returns L results a clock, in order. The host write port and
//! `swap_i` reach every lane, so every copy of a map is loaded by the same writes and every
//! lane swaps in the same clock, and the swap and write rules of a single rmap_top hold
//! unchanged.
//!
//! Memories ([`recip_read`] decides, here only, which lane reads which port of which memory):
//! - the reciprocal ROM (one read per lane per clock) is shared where the block RAM is true
//!   dual-port (every target but `ice40`, [`recip_rom::dual`]): ROM `u_recip_rom<j>` serves lane
//!   2j on port a and lane 2j+1 on port b, each port on its lane's own enable; an odd last
//!   lane has a ROM of its own (port b idle). On the iCE40 (SB_RAM40_4K: one read port) each
//!   lane keeps its own, inside its rmap_top;
//! - the compensation ROM is read twice per lane per clock (u and v): both ports of one array
//!   on a dual-port target, so a second lane would need a third and fourth port: one per lane;
//! - a map bank is read once per lane per clock and written by the host at any clock (into the
//!   back buffer, which lives in the same array as the front one the lanes read): port a the
//!   write, port b the lane's read, so a second lane's read would need a third port: one per
//!   lane, every copy written by the same host writes.
//!
//! The per-lane ports ([`lane_ports`], defined here once) are `valid_i` / `valid_o` (one bit
//! per lane) and every port a field of the top's vector file drives or is compared with,
//! each L times as wide: lane k in bits `[k*W +: W]`. The template slices them with it,
//! `manifest.json` carries it under `lanes` and the README prints it.
//!
//! Without the handshake the lanes are independent pipelines with their clock enables tied
//! high, so a sample of lane k accepted at edge t leaves at t + latency like a beat's other
//! samples. With the handshake the whole beat moves together: every lane's rmap_top takes
//! the beat's valid (`|valid_i`) and the shared `ready_i`, so their flow control (the
//! pipeline enable, the output queue and `ready_o`) runs in step, and the lane's own valid
//! bit travels beside its sample through the top's `side_i` / `side_o` (a delay line on the
//! pipeline's enable and the output queue), masking `valid_o`. A beat with every valid bit
//! low is not a beat: it is not accepted and gives no result.

mod vectors;

use super::recip_rom::{self, RecipRom};
use super::rmap_top::{top_latency, RmapTop};
use super::unit::{param_overrides, Head, Memory, Unit, Vectors};
use super::TOP;
use crate::config::Config;
use crate::hdl::ports::{Dir, Port, Width};
use askama::Template;
use serde::Serialize;

pub struct RmapLanes;

/// Which shared reciprocal ROM (`u_recip_rom<rom>`) lane `k` reads, and through which of its
/// [`recip_rom::PORTS`] (0: a, 1: b): the pairing, defined once.
pub fn recip_read(k: u32) -> (u32, usize) {
    (k / 2, (k % 2) as usize)
}

/// The shared reciprocal ROMs: one per pair of lanes, one more for an odd last lane.
pub fn recip_roms(cfg: &Config) -> u32 {
    if recip_rom::dual(cfg) {
        cfg.lanes.div_ceil(2)
    } else {
        0
    }
}

/// The instance name of shared reciprocal ROM `j`, `u_recip_rom<j>`.
pub fn recip_instance(j: u32) -> String {
    format!("u_recip_rom{j}")
}

/// The lane that reads port `port` of shared ROM `rom`, if any ([`recip_read`] inverted).
fn recip_reader(cfg: &Config, rom: u32, port: usize) -> Option<u32> {
    (0..cfg.lanes).find(|&k| recip_read(k) == (rom, port))
}

/// One per-lane port of rmap_lanes: rmap_top's port of the same name, `bits` wide, `lanes`
/// times, lane k in bits `[k*bits +: bits]`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct LanePort {
    pub port: &'static str,
    pub dir: Dir,
    /// Bits of one lane (rmap_top's width).
    pub bits: u32,
}

impl LanePort {
    /// `[hi:lo]` of lane `k` (`[k]` for one bit a lane).
    pub fn range(&self, k: u32) -> String {
        let lo = k * self.bits;
        if self.bits == 1 {
            format!("[{lo}]")
        } else {
            format!("[{}:{lo}]", lo + self.bits - 1)
        }
    }
}

/// Whether rmap_top's port `name` is one per lane: valid_i, valid_o and the ports of the
/// top's vector fields.
fn per_lane(cfg: &Config, name: &str) -> bool {
    let top = TOP.vectors().expect("the top has vectors");
    name == "valid_i"
        || name == "valid_o"
        || top
            .fields(cfg)
            .iter()
            .any(|f| top.port(f).as_deref() == Some(name))
}

/// The per-lane ports in rmap_top's port order: the packing, defined once.
pub fn lane_ports(cfg: &Config) -> Vec<LanePort> {
    TOP.ports(cfg)
        .into_iter()
        .filter(|p| per_lane(cfg, p.name))
        .map(|p| LanePort {
            port: p.name,
            dir: p.dir,
            bits: match p.width {
                Width::Bits(b) => b,
                Width::Param(_) => unreachable!("the top's ports have fixed widths"),
            },
        })
        .collect()
}

/// What the manifest says about the lanes (`lanes` > 1 only).
#[derive(Clone, Debug, Serialize)]
pub struct LanesInfo {
    pub lanes: u32,
    /// How each per-lane port is packed.
    pub packing: &'static str,
    pub ports: Vec<LanePort>,
    /// The module every lane is an instance of, and the instances (`u_lane<k>`).
    pub lane_module: String,
    pub instances: Vec<String>,
    /// Memory bits per lane, a memory shared by two lanes counted once per pair (half to
    /// each lane): [`LanesInfo::own_memory_bits_per_lane`] plus half of each shared ROM.
    pub memory_bits_per_lane: u64,
    /// Memory bits every lane has to itself (its rmap_top's memories).
    pub own_memory_bits_per_lane: u64,
    /// The memories two lanes share, and who reads which port.
    pub shared: Vec<SharedMemory>,
}

/// A memory of rmap_lanes read by two lanes through its two ports.
#[derive(Clone, Debug, Serialize)]
pub struct SharedMemory {
    /// Its array below rmap_lanes.
    pub instance: String,
    pub bits: u64,
    /// `u_lane0 port a, u_lane1 port b`.
    pub readers: String,
}

/// How a per-lane port is packed, in words (the manifest, the README and the template say it).
pub const PACKING: &str = "lane k in bits [k*W+W-1 : k*W], W the lane's width";

impl LanesInfo {
    pub fn new(cfg: &Config) -> Option<LanesInfo> {
        (cfg.lanes > 1).then(|| LanesInfo {
            lanes: cfg.lanes,
            packing: PACKING,
            ports: lane_ports(cfg),
            lane_module: RmapTop.module(cfg),
            instances: (0..cfg.lanes).map(instance).collect(),
            memory_bits_per_lane: own(cfg) + shared_bits(cfg) / 2,
            own_memory_bits_per_lane: own(cfg),
            shared: shared_roms(cfg)
                .into_iter()
                .enumerate()
                .map(|(j, m)| SharedMemory {
                    instance: m.instance,
                    bits: m.bits,
                    readers: (0..2)
                        .filter_map(|p| {
                            recip_reader(cfg, j as u32, p)
                                .map(|k| format!("{} port {}", instance(k), ["a", "b"][p]))
                        })
                        .collect::<Vec<_>>()
                        .join(", "),
                })
                .collect(),
        })
    }
}

/// Memory bits of one lane's own memories.
fn own(cfg: &Config) -> u64 {
    RmapTop.memories(cfg).iter().map(|m| m.bits).sum()
}

/// Bits of one shared reciprocal ROM (0 when nothing is shared).
fn shared_bits(cfg: &Config) -> u64 {
    if recip_rom::dual(cfg) {
        RecipRom.memories(cfg).iter().map(|m| m.bits).sum()
    } else {
        0
    }
}

/// The shared reciprocal ROMs' arrays, `u_recip_rom<j>.rom`.
fn shared_roms(cfg: &Config) -> Vec<Memory> {
    (0..recip_roms(cfg))
        .flat_map(|j| {
            RecipRom
                .memories(cfg)
                .into_iter()
                .map(move |m| m.under(&recip_instance(j)))
        })
        .collect()
}

/// Lane `k`'s instance name, `u_lane<k>`.
pub fn instance(k: u32) -> String {
    format!("u_lane{k}")
}

/// rmap_top's ports as rmap_lanes has them: the per-lane ones L times as wide, `side_i` and
/// `side_o` (internal with the handshake) left out, the rest shared.
fn ports(cfg: &Config) -> Vec<Port> {
    let (en, addr, data) = recip_rom::READER;
    TOP.ports(cfg)
        .into_iter()
        .filter(|p| p.name != "side_i" && p.name != "side_o")
        .filter(|p| ![en, addr, data].contains(&p.name))
        .map(|mut p| {
            if per_lane(cfg, p.name) {
                let Width::Bits(b) = p.width else {
                    unreachable!("the top's ports have fixed widths")
                };
                p.width = Width::Bits(b * cfg.lanes);
                p.note = match p.name {
                    "valid_i" if cfg.handshake => {
                        "one bit per lane; the beat (every lane) is accepted with valid_i != 0 && ready_o"
                    }
                    "valid_i" => "one bit per lane: lane k's sample is accepted when valid_i[k]",
                    "valid_o" if cfg.handshake => {
                        "one bit per lane, the beat's valid_i; the beat holds until ready_i"
                    }
                    "valid_o" => "one bit per lane: lane k's result is on its outputs",
                    _ => "lane k in bits [k*W+W-1 : k*W]",
                };
            } else {
                p.note = match p.name {
                    "swap_i" => "every lane's map buffers swap together",
                    "wr_en_i" => "host write into the back buffer of every lane",
                    "ready_i" => "the beat's results leave at a rising edge with valid_o != 0 && ready_i",
                    "ready_o" => "the lanes accept a beat (a register; low in reset)",
                    _ => p.note,
                };
            }
            p
        })
        .collect()
}

/// `.port (expr)` of every port of lane `k`'s rmap_top, names aligned.
fn pins(cfg: &Config, k: u32) -> Vec<String> {
    let lanes = lane_ports(cfg);
    let top = TOP.ports(cfg);
    let w = top.iter().map(|p| p.name.len()).max().unwrap_or(0);
    let (en, addr, data) = recip_rom::READER;
    top.iter()
        .map(|p| {
            let e = match (p.name, cfg.handshake) {
                (n, _) if n == en => format!("recip_en[{k}]"),
                (n, _) if n == addr => format!("recip_addr{}", recip_bus(cfg, n).range(k)),
                (n, _) if n == data => format!("recip_data{}", recip_bus(cfg, n).range(k)),
                ("valid_i", true) => "beat_valid".to_string(),
                ("valid_o", true) => format!("lane_valid[{k}]"),
                ("ready_o", _) => format!("lane_ready[{k}]"),
                ("side_i", _) => format!("valid_i[{k}]"),
                ("side_o", _) => format!("lane_side[{k}]"),
                (n, _) => match lanes.iter().find(|l| l.port == n) {
                    Some(l) => format!("{n}{}", l.range(k)),
                    None => n.to_string(),
                },
            };
            format!(".{:w$} ({e})", p.name)
        })
        .collect()
}

/// The lanes' reader port `name` ([`recip_rom::READER`]) of rmap_top, packed like a per-lane
/// port into the internal bus `recip_<...>`.
fn recip_bus(cfg: &Config, name: &'static str) -> LanePort {
    let p = TOP
        .ports(cfg)
        .into_iter()
        .find(|p| p.name == name)
        .expect("rmap_top reads a shared ROM");
    let Width::Bits(bits) = p.width else {
        unreachable!("the top's ports have fixed widths")
    };
    LanePort {
        port: p.name,
        dir: p.dir,
        bits,
    }
}

/// `.port (expr)` of every port of shared reciprocal ROM `j`: port a to lane 2j, port b to
/// lane 2j+1 ([`recip_read`]), or idle (enable low, data unused) when there is no such lane.
fn rom_pins(cfg: &Config, j: u32) -> Vec<String> {
    let (ra, rw) = (
        recip_bus(cfg, recip_rom::READER.1),
        recip_bus(cfg, recip_rom::READER.2),
    );
    let w = RecipRom
        .ports(cfg)
        .iter()
        .map(|p| p.name.len())
        .max()
        .unwrap_or(0);
    let mut v = vec![format!(".{:w$} (clk_i)", "clk_i")];
    for (p, (en, addr, data)) in recip_rom::PORTS.into_iter().enumerate() {
        let (e, a, d) = match recip_reader(cfg, j, p) {
            Some(k) => (
                format!("recip_en[{k}]"),
                format!("recip_addr{}", ra.range(k)),
                format!("recip_data{}", rw.range(k)),
            ),
            None => (
                "1'b0".to_string(),
                format!("{{{}{{1'b0}}}}", ra.bits),
                "unused_recip_data".to_string(),
            ),
        };
        v.push(format!(".{en:w$} ({e})"));
        v.push(format!(".{addr:w$} ({a})"));
        v.push(format!(".{data:w$} ({d})"));
    }
    v
}

struct Lane {
    inst: String,
    pins: Vec<String>,
}

#[derive(Template)]
#[template(path = "rmap_lanes/rmap_lanes.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    top: String,
    top_params: String,
    l: u32,
    handshake: bool,
    latency: u32,
    /// `valid_i [1:0], gx_i [11:0], ...`: the per-lane ports and one lane's range.
    packing: String,
    lanes: Vec<Lane>,
    /// The shared reciprocal ROMs (empty: each lane has its own).
    roms: Vec<Lane>,
    rom: String,
    rom_params: String,
    /// Address and data widths of the ROM's ports.
    ra: u32,
    rw: u32,
    /// The last ROM has an idle port b (an odd lane count).
    odd: bool,
}

impl Unit for RmapLanes {
    fn name(&self) -> &'static str {
        "rmap_lanes"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        ports(cfg)
    }

    fn latency(&self, cfg: &Config) -> Option<u32> {
        Some(top_latency(cfg))
    }

    fn children(&self, cfg: &Config) -> Vec<&'static dyn Unit> {
        if recip_rom::dual(cfg) {
            vec![&RmapTop, &RecipRom]
        } else {
            vec![&RmapTop]
        }
    }

    /// Every lane's own memories, under `u_lane<k>`, then the shared reciprocal ROMs.
    fn memories(&self, cfg: &Config) -> Vec<Memory> {
        let mut v: Vec<Memory> = (0..cfg.lanes)
            .flat_map(|k| {
                RmapTop
                    .memories(cfg)
                    .into_iter()
                    .map(move |m| m.under(&instance(k)))
            })
            .collect();
        v.extend(shared_roms(cfg));
        v
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let packing = lane_ports(cfg)
            .iter()
            .map(|p| format!("{} {}", p.port, p.range(0)))
            .collect::<Vec<_>>()
            .join(", ");
        Verilog {
            h,
            top: RmapTop.module(cfg),
            top_params: param_overrides(cfg, &RmapTop),
            l: cfg.lanes,
            handshake: cfg.handshake,
            latency: top_latency(cfg),
            packing,
            lanes: (0..cfg.lanes)
                .map(|k| Lane {
                    inst: instance(k),
                    pins: pins(cfg, k),
                })
                .collect(),
            roms: (0..recip_roms(cfg))
                .map(|j| Lane {
                    inst: recip_instance(j),
                    pins: rom_pins(cfg, j),
                })
                .collect(),
            rom: RecipRom.module(cfg),
            rom_params: param_overrides(cfg, &RecipRom),
            ra: cfg.recip_addr_bits(),
            rw: cfg.recip_bits,
            odd: recip_rom::dual(cfg) && cfg.lanes % 2 == 1,
        }
        .render()
    }

    /// A beat: a clock with any lane's valid bit (and `ready_o` with the handshake), in and
    /// out; without the handshake the lanes run in step, so every beat in leaves as one beat.
    fn stream(&self, cfg: &Config) -> Option<super::unit::Stream> {
        let (accept, deliver) = if cfg.handshake {
            ("|valid_i && ready_o", "|valid_o && ready_i")
        } else {
            ("|valid_i", "|valid_o")
        };
        Some(super::unit::Stream {
            accept: accept.into(),
            deliver: deliver.into(),
            last: None,
        })
    }

    fn vectors(&self) -> Option<&dyn Vectors> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lanes(l: u32, handshake: bool, color: bool) -> Config {
        Config {
            lanes: l,
            handshake,
            color,
            ..Config::default()
        }
    }

    #[test]
    fn per_lane_ports_are_l_times_wide_and_the_host_port_is_shared() {
        let cfg = lanes(4, true, true);
        let got: Vec<(&str, u32)> = ports(&cfg)
            .iter()
            .map(|p| {
                let Width::Bits(b) = p.width else { panic!() };
                (p.name, b)
            })
            .collect();
        assert_eq!(
            got,
            [
                ("clk_i", 1),
                ("rst_ni", 1),
                ("valid_i", 4),
                ("gx_i", 48),
                ("gy_i", 48),
                ("gz_i", 48),
                ("r_i", 32),
                ("g_i", 32),
                ("b_i", 32),
                ("swap_i", 1),
                ("wr_en_i", 1),
                ("wr_axis_i", 2),
                ("wr_addr_i", 9),
                ("wr_data_i", 8),
                ("ready_i", 1),
                ("ready_o", 1),
                ("valid_o", 4),
                ("zero_o", 4),
                ("i_o", 32),
                ("r_o", 32),
                ("g_o", 32),
                ("b_o", 32)
            ]
        );
        let gx = lane_ports(&cfg)
            .into_iter()
            .find(|p| p.port == "gx_i")
            .unwrap();
        assert_eq!(
            (0..4).map(|k| gx.range(k)).collect::<Vec<_>>(),
            ["[11:0]", "[23:12]", "[35:24]", "[47:36]"]
        );
        let v = lane_ports(&cfg)
            .into_iter()
            .find(|p| p.port == "valid_o")
            .unwrap();
        assert_eq!(v.range(3), "[3]");
    }

    #[test]
    fn two_lanes_share_a_reciprocal_rom_where_the_block_ram_is_dual_port() {
        use crate::config::Target;
        use crate::family::Family;
        // Lane 2j on port a, lane 2j+1 on port b of ROM j.
        assert_eq!(
            (0..5).map(recip_read).collect::<Vec<_>>(),
            [(0, 0), (0, 1), (1, 0), (1, 1), (2, 0)]
        );
        for (l, roms) in [(2, 1), (3, 2), (8, 4)] {
            for t in [Target::Generic, Target::Family(Family::Ecp5)] {
                let cfg = lanes(l, false, false).for_target(t);
                assert!(recip_rom::dual(&cfg));
                assert_eq!(recip_roms(&cfg), roms);
                let m = RmapLanes.memories(&cfg);
                let recip: Vec<&str> = m
                    .iter()
                    .filter(|m| m.module == RecipRom.module(&cfg))
                    .map(|m| m.instance.as_str())
                    .collect();
                let want: Vec<String> = (0..roms).map(|j| format!("u_recip_rom{j}.rom")).collect();
                assert_eq!(recip, want, "{l} lanes, {t:?}");
                // The last ROM of an odd count has port b idle.
                let last = rom_pins(&cfg, roms - 1);
                assert_eq!(
                    last.iter().any(|p| p.contains("unused_recip_data")),
                    l % 2 == 1,
                    "{last:?}"
                );
            }
            // The iCE40's SB_RAM40_4K has one read port: each lane keeps its own ROM.
            let cfg = lanes(l, false, false).for_target(Target::Family(Family::Ice40));
            assert!(!recip_rom::dual(&cfg));
            assert_eq!(recip_roms(&cfg), 0);
            assert!(RmapTop
                .memories(&cfg)
                .iter()
                .any(|m| m.instance == "u_normalise.u_recip_rom.rom"));
            assert!(LanesInfo::new(&cfg).unwrap().shared.is_empty());
        }
        let info = LanesInfo::new(&lanes(4, false, false)).unwrap();
        assert_eq!(info.shared.len(), 2);
        assert_eq!(info.shared[1].readers, "u_lane2 port a, u_lane3 port b");
        // One lane, nothing to share.
        assert!(!recip_rom::dual(&Config::default()));
    }

    #[test]
    fn every_lane_has_its_own_memories_loaded_from_the_same_files() {
        let cfg = lanes(2, false, false);
        let one = RmapTop.memories(&cfg);
        let m = RmapLanes.memories(&cfg);
        // Each lane's own, and the reciprocal ROM the two share.
        assert_eq!(m.len(), 2 * one.len() + 1);
        assert!(m[..one.len()]
            .iter()
            .all(|m| m.instance.starts_with("u_lane0.")));
        assert!(m[one.len()..2 * one.len()]
            .iter()
            .all(|m| m.instance.starts_with("u_lane1.")));
        assert!(m[2 * one.len()..]
            .iter()
            .all(|m| m.instance.starts_with("u_recip_rom0.")));
        assert_eq!(
            crate::stages::unit::file_params(&m).len(),
            crate::stages::unit::file_params(&one).len() + 1
        );
        let info = LanesInfo::new(&cfg).unwrap();
        assert_eq!(
            info.memory_bits_per_lane * 2,
            m.iter().map(|m| m.bits).sum::<u64>()
        );
        assert_eq!(
            info.memory_bits_per_lane,
            info.own_memory_bits_per_lane + cfg.recip_entries() as u64 * cfg.recip_bits as u64 / 2
        );
        assert!(LanesInfo::new(&Config::default()).is_none());
    }

    #[test]
    fn the_design_top_is_rmap_lanes_with_lanes() {
        assert_eq!(
            super::super::top(&lanes(2, false, false)).name(),
            "rmap_lanes"
        );
        assert_eq!(super::super::top(&Config::default()).name(), "rmap_top");
        // The handshake lanes take the beat's valid and carry their own beside the sample.
        let p = pins(&lanes(2, true, false), 1);
        assert!(p.iter().any(|p| p.ends_with("(beat_valid)")), "{p:?}");
        assert!(p.iter().any(|p| p.ends_with("(valid_i[1])")), "{p:?}");
        assert!(p.iter().any(|p| p.ends_with("(gx_i[23:12])")), "{p:?}");
        let p = pins(&lanes(2, false, false), 1);
        assert!(p.iter().any(|p| p.ends_with("(valid_i[1])")), "{p:?}");
        assert!(!p.iter().any(|p| p.contains("side")), "{p:?}");
    }
}
