//! The generated design, one folder per Verilog module. Each folder holds everything
//! rmapgen knows about that module: its bit-accurate model (`model.rs`), its register plan
//! (`plan.rs`, or a small `Plan` in `mod.rs`), its ports, template context, corner cases,
//! random inputs and expected outputs (`mod.rs`, the [`Unit`] and [`Vectors`] impls), its
//! Verilog template (`<name>.v`) and its testbench template (`<name>_tb.v`).
//!
//! | folder | module | instantiated by | has vectors and a testbench |
//! |---|---|---|---|
//! | `rmap_axis` | the AXI4-Stream top (`axis`) | — | yes (the top's vectors, in `tdata`) |
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
pub mod rmap_bus;
pub mod rmap_lanes;
pub mod rmap_regs;
pub mod rmap_top;
pub mod sort_shift;
pub mod testbench;
pub mod unit;
pub mod zero_detect;

use crate::config::Config;
pub use unit::{Head, Memory, Stream, Traced, Unit, Vectors};

/// The top of the shading pipeline, with the top-level vectors and testbench; the design's
/// top too, except with `axis` ([`top`]).
pub const TOP: &dyn Unit = &rmap_top::RmapTop;

/// The design's outermost module: [`rmap_bus::RmapBus`] (which instantiates the
/// [`sample_top`] and the register block) with a `bus`, else the [`sample_top`]. The
/// manifest's `top`, lint, synthesis and the FPGA flow start here.
pub fn top(cfg: &Config) -> &'static dyn Unit {
    if cfg.bus.is_none() {
        sample_top(cfg)
    } else {
        &rmap_bus::RmapBus
    }
}

/// What checks the design's top when it is not [`TOP`] (the AXI4-Stream wrapper, the bus
/// slave), which `rmapgen prove` does not drive (it proves the [`TOP`] inside; its scope line
/// says so with this): the top's testbench, which `rmapgen sim` runs.
pub fn checked_by(cfg: &Config) -> String {
    let outer = top(cfg);
    let tb = outer
        .vectors()
        .map_or_else(|| outer.file(cfg), |v| v.testbench_file(cfg));
    format!("its testbench {tb}, run by `rmapgen sim`")
}

/// The outermost module of the sample stream: [`rmap_axis::RmapAxis`] (which instantiates
/// [`TOP`]) with `axis`, [`rmap_lanes::RmapLanes`] (one [`TOP`] per lane) with `lanes` > 1,
/// else [`TOP`]. It has the host write port; the design's [`top`] unless a bus slave drives
/// that port.
pub fn sample_top(cfg: &Config) -> &'static dyn Unit {
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
/// the sample stream's top if it is another module (rmap_lanes, rmap_axis), then the design's
/// top if it is yet another with vectors.
pub fn checked(cfg: &Config) -> Vec<&'static dyn Vectors> {
    let tops = [TOP.name(), sample_top(cfg).name(), top(cfg).name()];
    let mut v: Vec<&'static dyn Vectors> = modules(cfg)
        .into_iter()
        .filter(|m| !tops.contains(&m.name()))
        .filter_map(|m| m.vectors())
        .collect();
    v.extend(TOP.vectors());
    for (k, t) in [sample_top(cfg), top(cfg)].into_iter().enumerate() {
        if !tops[..=k].contains(&t.name()) {
            v.extend(t.vectors());
        }
    }
    v
}

/// One value on a sample's path: the Verilog signal that carries it (a stage's port as
/// `u_<stage>.<port>`, its instance in the top; the top's own ports by name), its width and
/// the bits it carries (a gradient component in two's complement, as on the wire).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Signal {
    pub name: String,
    pub bits: u32,
    pub value: u64,
}

/// One sample's path through the design, as a student follows it in a waveform: every
/// checked module's ports in pipeline order (the top's last), inputs then outputs, the
/// inputs from the model's trace ([`Vectors::traced`]) and the outputs from the module's own
/// model ([`Vectors::expected`]). `buf` is the map buffer the sample reads.
pub fn path(
    model: &crate::model::Model,
    maps: &crate::model::MapSet,
    buf: u64,
    g: [i32; 3],
    rgb: [u32; 3],
) -> Vec<Signal> {
    let cfg = &model.cfg;
    let s = Traced::new(model, maps.buffer(buf), buf, g, rgb);
    let mut v = Vec::new();
    // The lanes top carries the same sample in one of its lanes, the AXI4-Stream top in
    // `tdata`: the top's ports say it.
    for m in checked(cfg)
        .into_iter()
        .filter(|m| m.lanes(cfg) == 1 && m.inner().is_none())
    {
        let inp = m.traced(cfg, &s);
        let out = m.expected(model, maps, &inp);
        let scope = if m.name() == TOP.name() {
            String::new()
        } else {
            format!("{}.", instance(m.name()))
        };
        for (f, &value) in m.fields(cfg).iter().zip(inp.iter().chain(&out)) {
            if let Some(port) = m.port(f) {
                v.push(Signal {
                    name: format!("{scope}{port}"),
                    bits: f.bits,
                    value,
                });
            }
        }
    }
    v
}

/// A stage's instance name in the module that instantiates it (the templates' `u_<stage>`).
pub fn instance(stage: &str) -> String {
    format!("u_{stage}")
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

    /// Configurations whose paths differ: the paper's; colour with neither interpolation nor
    /// compensation; a compensation table in RAM (the position stage reads a buffer); lanes.
    fn path_configs() -> Vec<Config> {
        let d = Config::default();
        vec![
            d.clone(),
            Config {
                color: true,
                compensation: false,
                interpolation: false,
                interp_bits: 0,
                ..d.clone()
            },
            Config {
                comp_table: crate::config::CompTable::Ram,
                ..d.clone()
            },
            Config {
                handshake: true,
                axis: true,
                axis_user: 2,
                color: true,
                ..d.clone()
            },
            Config { lanes: 2, ..d },
        ]
    }

    #[test]
    fn a_samples_path_names_real_ports_of_real_instances() {
        for cfg in path_configs() {
            let model = crate::model::Model::new(&cfg);
            let maps = crate::model::MapSet::standard(&cfg);
            let top = TOP.render(&cfg, Head::new(&cfg, TOP)).unwrap();
            let path = path(&model, &maps, 1, [-300, 1000, 77], [200, 100, 50]);
            let mut scopes = Vec::new();
            for sig in &path {
                let (module, port) = match sig.name.split_once('.') {
                    Some((inst, port)) => {
                        let m = modules(&cfg)
                            .into_iter()
                            .find(|m| instance(m.name()) == inst)
                            .unwrap_or_else(|| {
                                panic!("{}: no module is instance {inst}", sig.name)
                            });
                        assert!(
                            top.contains(&format!(" {inst} (")),
                            "{inst} is not in the top"
                        );
                        scopes.push(m.name());
                        (m, port)
                    }
                    None => (TOP, sig.name.as_str()),
                };
                let p = module.ports(&cfg).into_iter().find(|p| p.name == port);
                let p = p.unwrap_or_else(|| {
                    panic!("{}: {} has no port {port}", sig.name, module.name())
                });
                if let crate::hdl::ports::Width::Bits(b) = p.width {
                    assert_eq!(b, sig.bits, "{}", sig.name);
                }
                assert!(
                    sig.value < 1 << sig.bits,
                    "{} = {} in {} bits",
                    sig.name,
                    sig.value,
                    sig.bits
                );
            }
            scopes.dedup();
            let want: Vec<_> = checked(&cfg)
                .iter()
                .map(|m| m.name())
                .filter(|&n| n != TOP.name() && n != super::top(&cfg).name())
                .collect();
            assert_eq!(scopes, want, "every checked stage, in pipeline order");
            assert!(
                path.last().unwrap().name.ends_with("_o"),
                "the top's outputs last"
            );
        }
    }

    #[test]
    fn a_samples_path_carries_each_value_from_stage_to_stage() {
        let wires = [
            ("u_sort_shift.axis_o", "u_map_lookup.axis_i"),
            ("u_sort_shift.s_max_o", "u_map_lookup.s_max_i"),
            ("u_sort_shift.s_u_o", "u_map_lookup.s_u_i"),
            ("u_sort_shift.s_v_o", "u_map_lookup.s_v_i"),
            ("u_sort_shift.m_o", "u_normalise.m_i"),
            ("u_sort_shift.a_o", "u_normalise.a_i"),
            ("u_sort_shift.b_o", "u_normalise.b_i"),
            ("u_normalise.u_o", "u_POS.u_i"),
            ("u_normalise.v_o", "u_POS.v_i"),
            ("u_POS.pu_o", "u_map_lookup.pu_i"),
            ("u_POS.pv_o", "u_map_lookup.pv_i"),
            ("u_map_lookup.e00_o", "u_interpolate.e00_i"),
            ("u_map_lookup.e10_o", "u_interpolate.e10_i"),
            ("u_map_lookup.e01_o", "u_interpolate.e01_i"),
            ("u_map_lookup.e11_o", "u_interpolate.e11_i"),
            ("u_map_lookup.wu_o", "u_interpolate.wu_i"),
            ("u_map_lookup.wv_o", "u_interpolate.wv_i"),
            ("u_interpolate.i_o", "i_o"),
            ("u_map_lookup.e00_o", "i_o"),
            ("u_zero_detect.zero_o", "zero_o"),
            ("u_color_mul.r_o", "r_o"),
            ("u_color_mul.b_o", "b_o"),
            ("rd_buf", "u_map_lookup.rd_buf_i"),
        ];
        let mut rng = crate::rng::SplitMix64::new(7);
        for cfg in path_configs() {
            let model = crate::model::Model::new(&cfg);
            let maps = crate::model::MapSet::standard(&cfg);
            let pos = if cfg.compensation {
                "u_atan_rom"
            } else {
                "u_linear_index"
            };
            let mut joined = 0;
            for k in 0..200 {
                let g = crate::vectors::inputs::random_top_gradient(&cfg, &mut rng);
                if g == [0; 3] {
                    continue;
                }
                let (buf, rgb) = (k & 1, [k as u32 % 256, 255 - k as u32 % 256, 9]);
                let path = path(&model, &maps, buf, g, rgb);
                let at = |n: &str| {
                    let n = n.replace("u_POS", pos);
                    if n == "rd_buf" {
                        return Some(buf);
                    }
                    path.iter().find(|s| s.name == n).map(|s| s.value)
                };
                for (from, to) in wires {
                    // Without interpolation the nearest entry is the result.
                    if cfg.interpolation && from == "u_map_lookup.e00_o" && to == "i_o" {
                        continue;
                    }
                    if let (Some(a), Some(b)) = (at(from), at(to)) {
                        assert_eq!(a, b, "{from} -> {to} at {g:?}");
                        joined += 1;
                    }
                }
                let out = model.shade(maps.buffer(buf), g, rgb);
                assert_eq!(at("i_o"), Some(out.intensity as u64), "{g:?}");
                assert_eq!(at("zero_o"), Some(0));
                let enc = |c: i32| crate::vectors::inputs::enc_grad(&cfg, c);
                assert_eq!(at("u_sort_shift.gx_i"), Some(enc(g[0])));
                assert_eq!(at("gz_i"), Some(enc(g[2])));
                if cfg.color {
                    assert_eq!(at("r_o"), Some(out.rgb[0] as u64));
                    assert_eq!(at("u_color_mul.g_i"), Some(rgb[1] as u64));
                }
            }
            assert!(joined > 1000, "{joined} wires joined");
        }
    }
}
