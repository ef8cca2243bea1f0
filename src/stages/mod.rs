//! The generated design, one folder per Verilog module. Each folder holds everything
//! rmapgen knows about that module: its bit-accurate model (`model.rs`), its register plan
//! (`plan.rs`, or a small `Plan` in `mod.rs`), its ports, template context, corner cases,
//! random inputs and expected outputs (`mod.rs`, the [`Unit`] and [`Vectors`] impls), its
//! Verilog template (`<name>.v`) and its testbench template (`<name>_tb.v`).
//!
//! | folder | module | instantiated by | has vectors and a testbench |
//! |---|---|---|---|
//! | `rmap_axis` | the AXI4-Stream top (`axis`) | — | — (the cocotb test, tb/cocotb/) |
//! | `rmap_lanes` | the lanes top (`lanes` > 1): one rmap_top per lane | — | yes (the top's vectors) |
//! | `rmap_top` | the top (the shading pipeline; inside rmap_axis with `axis`, once per lane in rmap_lanes) | rmap_axis, rmap_lanes | yes |
//! | `zero_detect` | zero detect | rmap_top | yes |
//! | `sort_shift` | sort & shift | rmap_top | yes |
//! | `normalise` | normalise | rmap_top | yes |
//! | `recip_rom` | reciprocal ROM | normalise | through normalise |
//! | `atan_rom` | position with compensation | rmap_top | yes |
//! | `linear_index` | position without compensation | rmap_top | yes |
//! | `map_lookup` | map look-up | rmap_top | yes |
//! | `map_bank` | map RAM bank | map_lookup | through map_lookup |
//! | `interpolate` | bilinear interpolation | rmap_top | yes |
//! | `color_mul` | colour multiply | rmap_top | yes |
//! | `pipe_delay` | sideband delay line | rmap_top | — |
//!
//! The rest of the generator walks [`modules`] and [`checked`]; only the top, which wires
//! the stages together, names them. A folder's name is its stage's [`Unit::name`]; the
//! generated module is [`Unit::module`], the name with the configuration's prefix.

pub mod atan_rom;
pub mod color_mul;
pub mod interpolate;
pub mod linear_index;
pub mod map_bank;
pub mod map_lookup;
pub mod normalise;
pub mod pipe_delay;
pub mod position;
pub mod recip_rom;
pub mod rmap_axis;
pub mod rmap_lanes;
pub mod rmap_top;
pub mod sort_shift;
pub mod testbench;
pub mod unit;
pub mod zero_detect;

use crate::config::Config;
pub use unit::{Head, Memory, Unit, Vectors};

/// The top of the shading pipeline, with the top-level vectors and testbench; the design's
/// top too, except with `axis` ([`top`]).
pub const TOP: &dyn Unit = &rmap_top::RmapTop;

/// The design's outermost module: [`rmap_axis::RmapAxis`] (which instantiates [`TOP`]) with
/// `axis`, [`rmap_lanes::RmapLanes`] (one [`TOP`] per lane) with `lanes` > 1, else [`TOP`].
/// The manifest's `top`, lint, synthesis and the FPGA flow start here.
pub fn top(cfg: &Config) -> &'static dyn Unit {
    if cfg.axis {
        &rmap_axis::RmapAxis
    } else if cfg.lanes > 1 {
        &rmap_lanes::RmapLanes
    } else {
        TOP
    }
}

/// The modules of a configuration in instantiation order: the top, then what it instantiates
/// in the order its file does, each child right after its parent and each module once.
/// Stages the configuration leaves out are absent.
pub fn modules(cfg: &Config) -> Vec<&'static dyn Unit> {
    fn walk(cfg: &Config, m: &'static dyn Unit, out: &mut Vec<&'static dyn Unit>) {
        if out.iter().any(|o| o.name() == m.name()) {
            return;
        }
        out.push(m);
        for c in m.children(cfg) {
            walk(cfg, c, out);
        }
    }
    let mut out = Vec::new();
    walk(cfg, top(cfg), &mut out);
    out
}

/// The module that instantiates each module of [`modules`], by name (None for the top).
pub fn parents(cfg: &Config) -> Vec<(&'static str, Option<&'static str>)> {
    let mut v = vec![(top(cfg).name(), None)];
    for m in modules(cfg) {
        for c in m.children(cfg) {
            if !v.iter().any(|(n, _)| *n == c.name()) {
                v.push((c.name(), Some(m.name())));
            }
        }
    }
    v
}

/// The modules with their own vectors and testbench, in pipeline order, then the top, then
/// the design's top if it is another module with vectors (rmap_lanes).
pub fn checked(cfg: &Config) -> Vec<&'static dyn Vectors> {
    let outer = top(cfg);
    let mut v: Vec<&'static dyn Vectors> = modules(cfg)
        .into_iter()
        .filter(|m| m.name() != TOP.name() && m.name() != outer.name())
        .filter_map(|m| m.vectors())
        .collect();
    v.extend(TOP.vectors());
    if outer.name() != TOP.name() {
        v.extend(outer.vectors());
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names<'a>(it: impl IntoIterator<Item = &'a str>) -> String {
        it.into_iter().collect::<Vec<_>>().join(" ")
    }

    #[test]
    fn modules_follow_the_config() {
        assert_eq!(
            names(modules(&Config::default()).iter().map(|m| m.name())),
            "rmap_top zero_detect sort_shift normalise recip_rom atan_rom map_lookup map_bank interpolate pipe_delay"
        );
        let off = Config {
            compensation: false,
            interpolation: false,
            interp_bits: 0,
            color: true,
            ..Config::default()
        };
        assert_eq!(
            names(modules(&off).iter().map(|m| m.name())),
            "rmap_top zero_detect sort_shift normalise recip_rom linear_index map_lookup map_bank color_mul pipe_delay"
        );
        assert_eq!(
            names(checked(&off).iter().map(|m| m.name())),
            "zero_detect sort_shift normalise linear_index map_lookup color_mul rmap_top"
        );
    }

    #[test]
    fn every_module_but_the_top_has_one_parent() {
        let cfg = Config {
            color: true,
            ..Config::default()
        };
        let p = parents(&cfg);
        assert_eq!(p.len(), modules(&cfg).len());
        let of = |n: &str| p.iter().find(|(m, _)| *m == n).unwrap().1;
        assert_eq!(of("rmap_top"), None);
        assert_eq!(of("recip_rom"), Some("normalise"));
        assert_eq!(of("map_bank"), Some("map_lookup"));
        assert_eq!(of("color_mul"), Some("rmap_top"));
    }
}
