//! The lanes top, rmap_lanes (`lanes` > 1): `lanes` copies of [`RmapTop`] side by side, so
//! the design takes L samples and returns L results a clock, in order. Each lane is a whole
//! rmap_top with its own ROMs and map banks (the first increment: nothing is shared yet); the
//! host write port and `swap_i` reach every lane, so every copy of a map is loaded by the
//! same writes and every lane swaps in the same clock, and the swap and write rules of a
//! single rmap_top hold unchanged.
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

use super::rmap_top::{top_latency, RmapTop};
use super::unit::{param_overrides, Head, Memory, Unit, Vectors};
use super::TOP;
use crate::config::Config;
use crate::rtl::ports::{Dir, Port, Width};
use askama::Template;
use serde::Serialize;

pub struct RmapLanes;

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
    /// Memory bits of one lane (every lane has its own copy of every memory).
    pub memory_bits_per_lane: u64,
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
            memory_bits_per_lane: RmapTop.memories(cfg).iter().map(|m| m.bits).sum(),
        })
    }
}

/// Lane `k`'s instance name, `u_lane<k>`.
pub fn instance(k: u32) -> String {
    format!("u_lane{k}")
}

/// rmap_top's ports as rmap_lanes has them: the per-lane ones L times as wide, `side_i` and
/// `side_o` (internal with the handshake) left out, the rest shared.
fn ports(cfg: &Config) -> Vec<Port> {
    TOP.ports(cfg)
        .into_iter()
        .filter(|p| p.name != "side_i" && p.name != "side_o")
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
    top.iter()
        .map(|p| {
            let e = match (p.name, cfg.handshake) {
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

    fn children(&self, _cfg: &Config) -> Vec<&'static dyn Unit> {
        vec![&RmapTop]
    }

    /// Every lane's memories, under `u_lane<k>`: one copy per lane.
    fn memories(&self, cfg: &Config) -> Vec<Memory> {
        (0..cfg.lanes)
            .flat_map(|k| {
                RmapTop
                    .memories(cfg)
                    .into_iter()
                    .map(move |m| m.under(&instance(k)))
            })
            .collect()
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
        }
        .render()
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
    fn every_lane_has_its_own_memories_loaded_from_the_same_files() {
        let cfg = lanes(2, false, false);
        let one = RmapTop.memories(&cfg);
        let m = RmapLanes.memories(&cfg);
        assert_eq!(m.len(), 2 * one.len());
        assert!(m[..one.len()]
            .iter()
            .all(|m| m.instance.starts_with("u_lane0.")));
        assert!(m[one.len()..]
            .iter()
            .all(|m| m.instance.starts_with("u_lane1.")));
        assert_eq!(
            crate::stages::unit::file_params(&m).len(),
            crate::stages::unit::file_params(&one).len()
        );
        let info = LanesInfo::new(&cfg).unwrap();
        assert_eq!(
            info.memory_bits_per_lane * 2,
            m.iter().map(|m| m.bits).sum::<u64>()
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
