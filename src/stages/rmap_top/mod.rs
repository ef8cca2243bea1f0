//! The top, rmap_top: instantiates the stages a configuration needs in pipeline order, the
//! sideband delay lines beside them, the map buffer swap, the output register (where the zero
//! flag applies) and, with `handshake`, the valid/ready flow control. Its latency and its
//! sideband delays are computed here from the stages' own latencies.

mod latency;
mod vectors;

use super::color_mul::ColorMul;
use super::interpolate::Interpolate;
use super::map_lookup::MapLookup;
use super::normalise::Normalise;
use super::pipe_delay::PipeDelay;
use super::recip_rom;
use super::sort_shift::SortShift;
use super::unit::{param_overrides, Head, Memory, Unit, Vectors};
use super::zero_detect::ZeroDetect;
use crate::config::{Config, COLOR_BITS};
use crate::hdl::ports::{i, o, Port};
use askama::Template;
pub use latency::{
    pipeline, position, sideband_delays, top_latency, SidebandDelays, OUTPUT_LATENCY,
};
pub use vectors::{corners_for_map, random_for_map, stream_lines};

pub struct RmapTop;

/// The module names ([`Unit::module`]) the top instantiates; a stage the configuration
/// leaves out is named all the same and not instantiated.
struct Modules {
    zero_detect: String,
    sort_shift: String,
    normalise: String,
    position: String,
    map_lookup: String,
    interpolate: String,
    color_mul: String,
    pipe_delay: String,
}

impl Modules {
    fn new(cfg: &Config) -> Modules {
        Modules {
            zero_detect: ZeroDetect.module(cfg),
            sort_shift: SortShift.module(cfg),
            normalise: Normalise.module(cfg),
            position: position(cfg).module(cfg),
            map_lookup: MapLookup.module(cfg),
            interpolate: Interpolate.module(cfg),
            color_mul: ColorMul.module(cfg),
            pipe_delay: PipeDelay.module(cfg),
        }
    }
}

/// The ` #(...)` passing each child with memories its init-file parameters
/// ([`param_overrides`]), empty for the others.
struct Overrides {
    normalise: String,
    position: String,
    map_lookup: String,
}

impl Overrides {
    fn new(cfg: &Config) -> Overrides {
        Overrides {
            normalise: param_overrides(cfg, &Normalise),
            position: param_overrides(cfg, position(cfg)),
            map_lookup: param_overrides(cfg, &MapLookup),
        }
    }
}

#[derive(Template)]
#[template(path = "rmap_top/rmap_top.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    mods: Modules,
    pars: Overrides,
    handshake: bool,
    interpolation: bool,
    color: bool,
    /// The position stage's name (its instance is `u_<name>`).
    position: &'static str,
    r: u32,
    f: u32,
    pos: u32,
    m: u32,
    p: u32,
    c: u32,
    latency_list: String,
    total: u32,
    sign_delay: u32,
    buf_delay: u32,
    zero_delay: u32,
    rgb_delay: u32,
    i_delay: u32,
    /// Width of side_i / side_o (0: absent).
    sd: u32,
    /// What side_i carries: {tuser, tlast} with `axis`, else a lane's valid bit.
    axis: bool,
    side_delay: u32,
    /// normalise reads a reciprocal ROM shared in rmap_lanes through the recip_* ports.
    recip_out: bool,
    /// The compensation table is a double-buffered RAM on the host write port
    /// (`comp_table = ram`), read in the buffer delayed by `table_buf_delay`.
    table_ram: bool,
    table_buf_delay: u32,
}

/// `sort_shift 4, normalise 6, ...`: each stage of [`pipeline`] with its latency.
pub fn latency_list(cfg: &Config) -> String {
    pipeline(cfg)
        .iter()
        .map(|s| {
            format!(
                "{} {}",
                s.name(),
                s.latency(cfg).expect("a stage has a latency")
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

impl Unit for RmapTop {
    fn name(&self) -> &'static str {
        "rmap_top"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let (g, mb) = (cfg.grad_bits, cfg.map_bits);
        let mut v = vec![
            i("clk_i", 1, ""),
            i("rst_ni", 1, "asynchronous, active low"),
            i(
                "valid_i",
                1,
                if cfg.handshake {
                    "a sample is accepted at a rising edge with valid_i && ready_o"
                } else {
                    "a sample is accepted every cycle valid_i is high"
                },
            ),
            i("gx_i", g, "G-bit two's complement"),
            i("gy_i", g, ""),
            i("gz_i", g, ""),
        ];
        if cfg.color {
            v.push(i("r_i", COLOR_BITS, "sample colour channel"));
            v.push(i("g_i", COLOR_BITS, "sample colour channel"));
            v.push(i("b_i", COLOR_BITS, "sample colour channel"));
        }
        v.push(i("swap_i", 1, "exchange front and back map buffers"));
        v.push(i("wr_en_i", 1, "host write into the back buffer"));
        v.push(i("wr_axis_i", 2, ""));
        v.push(i(
            "wr_addr_i",
            cfg.map_addr_bits(),
            "{s_max, s_u, i_u, s_v, i_v}",
        ));
        v.push(i("wr_data_i", mb, ""));
        if cfg.side_bits() > 0 {
            v.push(i(
                "side_i",
                cfg.side_bits(),
                if cfg.axis {
                    "{tuser, tlast} of the sample (axis): leaves unchanged on side_o with its result"
                } else {
                    "the lane's valid bit (lanes): leaves unchanged on side_o with its result"
                },
            ));
        }
        if cfg.handshake {
            v.push(i(
                "ready_i",
                1,
                "the result leaves at a rising edge with valid_o && ready_i",
            ));
            v.push(o(
                "ready_o",
                1,
                "the pipeline accepts a sample (a register; low in reset)",
            ));
        }
        v.push(o(
            "valid_o",
            1,
            if cfg.handshake {
                "a result is on the outputs; holds, with them, until ready_i"
            } else {
                "a result is on the outputs (high one clock per sample)"
            },
        ));
        v.push(o("zero_o", 1, "the sample's gradient was zero"));
        v.push(o("i_o", mb, "intensity (0 when zero_o)"));
        if cfg.color {
            v.push(o("r_o", COLOR_BITS, "colour channel times the intensity"));
            v.push(o("g_o", COLOR_BITS, "colour channel times the intensity"));
            v.push(o("b_o", COLOR_BITS, "colour channel times the intensity"));
        }
        if cfg.side_bits() > 0 {
            v.push(o("side_o", cfg.side_bits(), "side_i of the sample"));
        }
        v.extend(recip_rom::reader_ports(cfg));
        v
    }

    fn latency(&self, cfg: &Config) -> Option<u32> {
        Some(top_latency(cfg))
    }

    /// In the order rmap_top.v instantiates them; stages the configuration leaves out are
    /// absent, not bypassed.
    /// The zero detect beside the pipeline, the stages of [`pipeline`] in order, and the
    /// sideband delay lines.
    fn children(&self, cfg: &Config) -> Vec<&'static dyn Unit> {
        let mut v: Vec<&'static dyn Unit> = vec![&ZeroDetect];
        v.extend(pipeline(cfg));
        v.push(&PipeDelay);
        v
    }

    /// Every child's memories, under its instance `u_<module>`.
    fn memories(&self, cfg: &Config) -> Vec<Memory> {
        self.children(cfg)
            .into_iter()
            .flat_map(|c| {
                let inst = format!("u_{}", c.name());
                c.memories(cfg).into_iter().map(move |m| m.under(&inst))
            })
            .collect()
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let d = sideband_delays(cfg);
        Verilog {
            h,
            mods: Modules::new(cfg),
            pars: Overrides::new(cfg),
            handshake: cfg.handshake,
            interpolation: cfg.interpolation,
            color: cfg.color,
            position: position(cfg).name(),
            r: cfg.red_bits,
            f: cfg.frac_bits,
            pos: cfg.pos_bits(),
            m: cfg.map_bits,
            p: cfg.interp_bits,
            c: COLOR_BITS,
            latency_list: latency_list(cfg),
            total: top_latency(cfg),
            sign_delay: d.sign,
            buf_delay: d.buf,
            zero_delay: d.zero,
            rgb_delay: d.rgb.unwrap_or(0),
            i_delay: d.intensity.unwrap_or(0),
            sd: cfg.side_bits(),
            axis: cfg.axis,
            side_delay: d.side.unwrap_or(0),
            recip_out: recip_rom::dual(cfg),
            table_ram: d.table_buf.is_some(),
            table_buf_delay: d.table_buf.unwrap_or(0),
        }
        .render()
    }

    /// A sample is accepted with `valid_i` (and `ready_o` with the handshake); a result
    /// leaves with `valid_o` (and `ready_i`).
    fn stream(&self, cfg: &Config) -> Option<super::unit::Stream> {
        let (accept, deliver) = if cfg.handshake {
            ("valid_i && ready_o", "valid_o && ready_i")
        } else {
            ("valid_i", "valid_o")
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
    use crate::stages::unit::Head;

    /// The top's Verilog follows the one pipeline list: for every row of the parameter grid,
    /// each child of [`RmapTop::children`] (the zero detect and [`pipeline`]) is instantiated
    /// exactly once, as `u_<stage>`, the pipeline's stages in the list's order, and no stage the
    /// list leaves out (interpolation or colour off, the other position stage) is there. The
    /// model's trace is the same chain by its data flow: each stage reads the one before, and
    /// the top's vectors and `prove` compare the two sample by sample.
    #[test]
    fn the_top_instantiates_the_pipeline_list_in_its_order_and_nothing_else() {
        let every = [
            "zero_detect",
            "sort_shift",
            "normalise",
            "atan_rom",
            "linear_index",
            "map_lookup",
            "interpolate",
            "color_mul",
        ];
        for row in crate::grid::rows() {
            let cfg = &row.config;
            let text = RmapTop.render(cfg, Head::new(cfg, &RmapTop)).unwrap();
            let at = |name: &str| {
                let inst = format!(" u_{name} (");
                let found: Vec<usize> = text.match_indices(&inst).map(|(i, _)| i).collect();
                found
            };
            let list: Vec<&str> = pipeline(cfg).iter().map(|u| u.name()).collect();
            let mut last = 0;
            for name in &list {
                let found = at(name);
                assert_eq!(found.len(), 1, "{}: u_{name} {found:?}", row.name);
                assert!(
                    found[0] > last,
                    "{}: u_{name} before its predecessor",
                    row.name
                );
                last = found[0];
            }
            let children: Vec<&str> = RmapTop.children(cfg).iter().map(|u| u.name()).collect();
            for name in every {
                let want = usize::from(children.contains(&name));
                assert_eq!(at(name).len(), want, "{}: u_{name}", row.name);
            }
        }
    }
}
