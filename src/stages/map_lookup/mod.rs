//! Map look-up: splits each position into a base entry and a weight, and reads the base
//! entry and (with interpolation) its three higher neighbours from the map banks of the
//! sample's read buffer; the host writes the other buffer through the same module.

pub mod model;

use super::map_bank::{banks, MapBank};
use super::testbench::TbData;
use super::unit::{port_of, Head, Memory, Traced, Unit, Vectors};
use crate::config::Config;
use crate::hdl::adder_tree::clock_q;
use crate::hdl::ports::{i, o, stage_head, Port};
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::vectors::field::Field;
use crate::vectors::inputs::{corner_traces, position_corners};
use askama::Template;

pub struct MapLookup;

/// Where map_lookup's registers sit: stage 1 forms the bank addresses, stage 2 reads the
/// banks (their block-RAM output registers), stage 3 registers the banks' outputs in the
/// fabric at depth >= 1, and the last stage reorders (or registers) the entries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    pub bank_reg: bool,
}

impl Plan {
    pub fn new(cfg: &Config) -> Plan {
        Plan {
            bank_reg: cfg.pipeline_depth >= 1,
        }
    }

    /// The number of the output stage, which is the latency.
    pub fn out_stage(self) -> u32 {
        3 + self.bank_reg as u32
    }
}

/// One map bank as map_lookup instantiates it.
struct BankInst {
    name: String,
    inst: String,
    /// The init-file parameter map_lookup passes to the bank's INIT_FILE.
    param: String,
    pu: usize,
    pv: usize,
}

#[derive(Template)]
#[template(path = "map_lookup/map_lookup.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    /// The map bank's module.
    bank: String,
    latency: u32,
    bank_reg: bool,
    /// Stage number of the reorder (output) stage, and the suffixes of its inputs and outputs.
    out: u32,
    rd: String,
    out_q: String,
    interpolation: bool,
    i: u32,
    p: u32,
    ih: u32,
    ba: u32,
    m: u32,
    base_max: u32,
    banks: Vec<BankInst>,
}

crate::tb_template!(Testbench, "map_lookup/map_lookup_tb.v");

impl Unit for MapLookup {
    fn name(&self) -> &'static str {
        "map_lookup"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let (pos, mb, w) = (cfg.pos_bits(), cfg.map_bits, cfg.weight_bits());
        let mut v = stage_head();
        v.push(i("axis_i", 2, ""));
        v.push(i("s_max_i", 1, ""));
        v.push(i("s_u_i", 1, ""));
        v.push(i("s_v_i", 1, ""));
        v.push(i("pu_i", pos, "position along u"));
        v.push(i("pv_i", pos, "position along v"));
        v.push(i("rd_buf_i", 1, "buffer this sample reads"));
        v.extend(crate::hdl::ports::host_write(cfg));
        v.push(o("valid_o", 1, ""));
        v.push(o("e00_o", mb, "entry (base_u, base_v)"));
        if cfg.interpolation {
            v.push(o("e10_o", mb, "entry (base_u + 1, base_v)"));
            v.push(o("e01_o", mb, "entry (base_u, base_v + 1)"));
            v.push(o("e11_o", mb, "entry (base_u + 1, base_v + 1)"));
            v.push(o("wu_o", w, "weight along u, 0..S"));
            v.push(o("wv_o", w, "weight along v, 0..S"));
        }
        v
    }

    fn latency(&self, cfg: &Config) -> Option<u32> {
        Some(Plan::new(cfg).out_stage())
    }

    fn children(&self, _cfg: &Config) -> Vec<&'static dyn Unit> {
        vec![&MapBank]
    }

    fn memories(&self, cfg: &Config) -> Vec<Memory> {
        (0..cfg.bank_count() as usize)
            .flat_map(|k| {
                MapBank.memories(cfg).into_iter().map(move |mut m| {
                    m.init_file = banks::bank_file(cfg, k);
                    m.param = banks::bank_param(cfg, k);
                    m.under(&banks::bank_instance(cfg, k))
                })
            })
            .collect()
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let names = banks::bank_names(cfg);
        let banks = (0..cfg.bank_count() as usize)
            .map(|k| BankInst {
                name: names[k].clone(),
                inst: banks::bank_instance(cfg, k),
                param: banks::bank_param(cfg, k),
                pu: k & 1,
                pv: k >> 1,
            })
            .collect();
        let plan = Plan::new(cfg);
        let out = plan.out_stage();
        Verilog {
            h,
            bank: MapBank.module(cfg),
            latency: out,
            bank_reg: plan.bank_reg,
            out,
            rd: clock_q(out - 1),
            out_q: clock_q(out),
            interpolation: cfg.interpolation,
            i: cfg.index_bits,
            p: cfg.interp_bits,
            ih: cfg.bank_index_bits(),
            ba: cfg.bank_addr_bits(),
            m: cfg.map_bits,
            base_max: cfg.base_max(),
            banks,
        }
        .render()
    }

    fn vectors(&self) -> Option<&dyn Vectors> {
        Some(self)
    }
}

impl Vectors for MapLookup {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        let (pos, m, w) = (cfg.pos_bits(), cfg.map_bits, cfg.weight_bits());
        let mut v = vec![
            Field::input("axis", 2),
            Field::input("s_max", 1),
            Field::input("s_u", 1),
            Field::input("s_v", 1),
            Field::input("pu", pos),
            Field::input("pv", pos),
            Field::input("buf", 1),
            Field::output("e00", m),
        ];
        if cfg.interpolation {
            v.extend([
                Field::output("e10", m),
                Field::output("e01", m),
                Field::output("e11", m),
                Field::output("wu", w),
                Field::output("wv", w),
            ]);
        }
        v
    }

    fn corners(&self, model: &Model, maps: &MapSet) -> Vec<Vec<u64>> {
        let cfg = &model.cfg;
        let p = position_corners(cfg);
        let pmax = cfg.pos_max() as u64;
        let n = p.len();
        let mut out = Vec::new();
        // Every position corner in each lane, axes, signs and buffers cycling.
        for (j, &pc) in p.iter().enumerate() {
            let other = p[(j * 7 + 3) % n] as u64;
            let k = j as u64;
            out.push(vec![
                k % 3,
                k & 1,
                (k >> 1) & 1,
                (k >> 2) & 1,
                pc as u64,
                other,
                (k >> 3) & 1,
            ]);
            out.push(vec![
                (k + 1) % 3,
                (k >> 2) & 1,
                k & 1,
                (k >> 1) & 1,
                other,
                pc as u64,
                !(k >> 3) & 1,
            ]);
        }
        // Every axis, sign combination and buffer at the two extreme corners.
        for buf in 0..2 {
            for axis in 0..3 {
                for signs in 0..8u64 {
                    for (pu, pv) in [(0, 0), (pmax, pmax), (0, pmax)] {
                        out.push(vec![
                            axis,
                            signs & 1,
                            (signs >> 1) & 1,
                            signs >> 2,
                            pu,
                            pv,
                            buf,
                        ]);
                    }
                }
            }
        }
        // The traced corners, alternating buffers.
        for (i, t) in corner_traces(model, &maps.scene).enumerate() {
            let buf = (i & 1) as u64;
            out.push(self.traced(cfg, &Traced { buf, ..t }));
        }
        out
    }

    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        let pmax = cfg.pos_max() as u64;
        vec![
            rng.below(3),
            rng.bits(1),
            rng.bits(1),
            rng.bits(1),
            rng.range(0, pmax),
            rng.range(0, pmax),
            rng.bits(1),
        ]
    }

    fn expected(&self, model: &Model, maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        let cfg = &model.cfg;
        let u = |k: usize| inp[k] as u32;
        let l = model::eval(cfg, maps.buffer(inp[6]), u(0), u(1), u(2), u(3), u(4), u(5));
        if cfg.interpolation {
            [l.e[0], l.e[1], l.e[2], l.e[3], l.w_u, l.w_v]
                .map(u64::from)
                .to_vec()
        } else {
            vec![l.e[0] as u64]
        }
    }

    fn traced(&self, _cfg: &Config, s: &Traced) -> Vec<u64> {
        let (o, t) = (s.trace.sort, &s.trace);
        let mut v = [o.axis, o.s_max, o.s_u, o.s_v, t.p_u, t.p_v]
            .map(u64::from)
            .to_vec();
        v.push(s.buf);
        v
    }

    /// The buffer field drives rd_buf_i.
    fn port(&self, field: &Field) -> Option<String> {
        Some(match field.name {
            "buf" => "rd_buf_i".to_string(),
            _ => port_of(field),
        })
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
