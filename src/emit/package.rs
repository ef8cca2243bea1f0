//! The generated directory as a piece of IP: a FuseSoC core (`<prefix>rmap_top.core`, CAPI2,
//! file sets with the `.v` and `.hex` files, targets, the testbench's plusargs as parameters)
//! and a `README.md` with the port table and the timing notes (latency, flow control, reset,
//! buffer swap and write rules), both from the same tables as the Verilog.
//!
//! The core is named by one rule, [`manifest::Core`]: after the design's top, the module
//! users instantiate, with a hash of the configuration.

use super::manifest;
use crate::config::Config;
use crate::design::Design;
use crate::geometry::{face_tangent, place};
use crate::hdl::{Dir, Width};
use crate::map_stream;
use crate::model::map_addr;
use crate::model::map_set::{map_file, AXES};
use crate::stages::map_bank::MapBank;
use crate::stages::rmap_top::{latency_list, top_latency};
use crate::stages::testbench::TbFile;
use crate::stages::unit::{file_params, FileParam};
use crate::stages::{self, rmap_axis, rmap_lanes, Unit, Vectors, TOP};
use anyhow::{Context, Result};
use askama::Template;

pub const README_FILE: &str = "README.md";

#[derive(Template)]
#[template(path = "pkg/rmap_top.core")]
struct Core {
    version: &'static str,
    summary: String,
    vlnv: String,
    core_file: String,
    /// The design's top ([`stages::top`]).
    top: String,
    /// The top testbench's module (`<rmap_top module>_tb`).
    tb_top: String,
    tb_file: String,
    vector_file: String,
    latency: u32,
    rtl_files: Vec<String>,
    mem_files: Vec<String>,
    tb_files: Vec<String>,
    /// The top's init-file parameters; the testbench has the same ones and passes them down.
    file_params: Vec<FileParam>,
    /// The testbench's own file parameters (the second map).
    tb_params: Vec<TbFile>,
}

/// A row of the README's "Fits on" table: a part and what this design takes of it.
struct FitsRow {
    family: &'static str,
    part: &'static str,
    device: &'static str,
    package: &'static str,
    boards: &'static str,
    /// The larger part whose die it is, when nextpnr offers all of it.
    die: &'static str,
    logic_cells: u32,
    block_rams: u32,
    needs: u32,
}

/// Every known part of every family ([`crate::family`]), with the block RAMs `cfg` takes there
/// written for the family's block RAM ([`manifest::block_rams`]).
fn fits_rows(cfg: &Config) -> Vec<FitsRow> {
    crate::family::Family::ALL
        .into_iter()
        .flat_map(|f| {
            let needs = manifest::block_rams(cfg, f);
            let d = f.get();
            d.parts.iter().map(move |p| FitsRow {
                family: d.title,
                part: p.title,
                device: p.device,
                package: p.package,
                boards: if p.boards.is_empty() { "—" } else { p.boards },
                die: p.die.unwrap_or_default(),
                logic_cells: p.logic_cells,
                block_rams: p.block_rams,
                needs,
            })
        })
        .collect()
}

#[derive(Template)]
#[template(path = "pkg/README.md")]
struct Readme {
    version: &'static str,
    summary: String,
    prefix: String,
    top: String,
    core: manifest::Core,
    tb_file: String,
    map2: String,
    bank_glob: String,
    config_rows: Vec<(String, String)>,
    ports: Vec<(String, String, String, String)>,
    handshake: bool,
    latency: u32,
    depth: u32,
    latency_list: String,
    memories: Vec<(String, String, String, String)>,
    /// [`crate::config::Target::name`].
    target: &'static str,
    /// The family the design is written for: its title, its `--target` help and its default
    /// part's title (None: generic).
    family: Option<(&'static str, &'static str, &'static str)>,
    /// Every family's name, as `--target` and `--family` spell them.
    family_names: String,
    fits: Vec<FitsRow>,
    /// The parts of [`Self::fits`] that are a larger part's die: `iCE40-HX4K: iCE40-HX8K; ...`.
    dies: String,
    /// The edge after which `valid_o` is high for a sample accepted at edge 0.
    valid_edge: u32,
    compensation: bool,
    /// The compensation table is a RAM the host loads (`comp_table = ram`): its entries,
    /// position width and largest position.
    table_ram: bool,
    table_entries: u32,
    pos_bits: u32,
    pos_max: u32,
    frac_bits: u32,
    interp_bits: u32,
    interpolation: bool,
    /// The colour multiply (`color`): the formula of r_o, g_o, b_o.
    color: bool,
    grad_bits: u32,
    /// -2^(grad_bits - 1), the most negative gradient component.
    grad_min: i64,
    addr_bits: u32,
    /// (name, bits, width, meaning) of each address field.
    addr_fields: Vec<(String, String, u32, String)>,
    /// (wr_axis_i, max axis, u axis, v axis).
    uv_rows: Vec<(u32, String, String, String)>,
    entries: u32,
    /// (index, tangent with compensation, without).
    tangents: Vec<(u32, f64, f64)>,
    map_glob: String,
    map_x: String,
    scene_name: String,
    scene_toml: String,
    map_fit: &'static str,
    map_max: u32,
    map_bits: u32,
    writes: u32,
    last_addr: u32,
    addr_digits: u32,
    data_digits: u32,
    record_bytes: usize,
    c_array: String,
    c_count: String,
    /// The `## AXI4-Stream` section (`axis` only).
    axis: Option<AxisReadme>,
    /// The `## Lanes` section (`lanes` > 1 only).
    lanes: Option<LanesReadme>,
    /// The sections of the design's modules ([`crate::stages::Unit::readme`]), in module order.
    sections: Vec<String>,
}

/// What the README's `## Lanes` section prints: rmap_lanes' ports, the packing of the
/// per-lane ports and the memory cost of a lane, from [`rmap_lanes`].
struct LanesReadme {
    top: String,
    l: u32,
    last: u32,
    ports: Vec<(String, &'static str, u32, String)>,
    /// (port, direction, bits per lane, lane 0's bits, lane L-1's bits).
    packing: Vec<(&'static str, &'static str, u32, String, String)>,
    packing_rule: &'static str,
    memories_per_lane: usize,
    /// A shared memory counted once per pair (half to each lane).
    bits_per_lane: u64,
    own_bits_per_lane: u64,
    bits_total: u64,
    /// (shared array, bits, which lane reads which port).
    shared: Vec<(String, u64, String)>,
    /// The target's name, and whether its block RAM has one read port (nothing shared).
    target: &'static str,
    tb_file: String,
}

impl LanesReadme {
    fn new(cfg: &Config) -> Option<LanesReadme> {
        let info = rmap_lanes::LanesInfo::new(cfg)?;
        let dir = |d: Dir| match d {
            Dir::Input => "in",
            Dir::Output => "out",
        };
        let last = cfg.lanes - 1;
        Some(LanesReadme {
            top: rmap_lanes::RmapLanes.module(cfg),
            l: cfg.lanes,
            last,
            ports: rmap_lanes::RmapLanes
                .ports(cfg)
                .into_iter()
                .map(|p| {
                    let w = match p.width {
                        Width::Bits(b) => b,
                        Width::Param(_) => unreachable!("the lanes top's ports have fixed widths"),
                    };
                    (p.name.to_string(), dir(p.dir), w, describe(p.name, p.note))
                })
                .collect(),
            packing: info
                .ports
                .iter()
                .map(|p| (p.port, dir(p.dir), p.bits, p.range(0), p.range(last)))
                .collect(),
            packing_rule: info.packing,
            memories_per_lane: TOP.memories(cfg).len(),
            bits_per_lane: info.memory_bits_per_lane,
            own_bits_per_lane: info.own_memory_bits_per_lane,
            bits_total: manifest::memories(cfg).iter().map(|m| m.bits).sum(),
            shared: info
                .shared
                .iter()
                .map(|m| (m.instance.clone(), m.bits, m.readers.clone()))
                .collect(),
            target: cfg.target.name(),
            tb_file: rmap_lanes::RmapLanes.testbench_file(cfg),
        })
    }
}

/// What the README's `## AXI4-Stream` section prints: the wrapper's ports and the `tdata`
/// layouts, from [`rmap_axis`].
struct AxisReadme {
    top: String,
    /// The wrapper's testbench, `tb/<rmap_axis>_tb.v`.
    tb_file: String,
    tuser: u32,
    vectors: String,
    ports: Vec<(String, &'static str, u32, String)>,
    /// (bus, its width, field, field bits, `[hi:lo]`, the padding's `[hi:lo]` or `—`).
    slots: Vec<(&'static str, u32, &'static str, u32, String, String)>,
}

impl AxisReadme {
    fn new(cfg: &Config) -> Option<AxisReadme> {
        let info = rmap_axis::AxisInfo::new(cfg)?;
        let mut slots = Vec::new();
        for (bus, p) in [
            ("s_axis_tdata", &info.s_tdata),
            ("m_axis_tdata", &info.m_tdata),
        ] {
            for s in &p.slots {
                let pad = match s.pad() {
                    Some((h, l)) if h == l => format!("[{h}]"),
                    Some((h, l)) => format!("[{h}:{l}]"),
                    None => "—".into(),
                };
                slots.push((bus, p.bits, s.field, s.bits, s.range(), pad));
            }
        }
        Some(AxisReadme {
            top: rmap_axis::RmapAxis.module(cfg),
            tb_file: rmap_axis::RmapAxis.testbench_file(cfg),
            tuser: info.tuser_bits,
            vectors: info.vectors,
            ports: rmap_axis::port_rows(cfg)
                .into_iter()
                .map(|(n, d, w, note)| {
                    let text = describe(&n, note);
                    (n, d, w, text)
                })
                .collect(),
            slots,
        })
    }
}

/// The core file of `cfg` ([`manifest::Core`]): the design's modules and the init files they
/// read, and the design top's testbench with its vectors and the second map it loads.
pub fn core(cfg: &Config) -> Result<String> {
    let named = manifest::Core::new(cfg);
    let top = stages::top(cfg)
        .vectors()
        .expect("every design top has its testbench");
    // The design top's: with lanes it also sets the shared ROMs' file.
    let file_params = file_params(&manifest::memories(cfg));
    let mem_files = file_params.iter().map(|p| p.default.clone()).collect();
    let (tb_files, _) = super::tb::testbench_files(cfg, &named.sim_toplevel)?;
    let tb_params: Vec<TbFile> = tb_files
        .into_iter()
        .filter(|f| !file_params.iter().any(|p| p.name == f.param))
        .collect();
    let text = Core {
        version: env!("CARGO_PKG_VERSION"),
        summary: cfg.summary(),
        vlnv: named.name,
        core_file: named.file,
        top: named.toplevel,
        tb_top: named.sim_toplevel,
        tb_file: top.testbench_file(cfg),
        vector_file: top.vector_file(cfg),
        latency: top_latency(cfg),
        rtl_files: stages::modules(cfg).iter().map(|m| m.file(cfg)).collect(),
        // Not the logical maps map_<axis>.hex: they are for people and tools.
        mem_files,
        tb_files: tb_params.iter().map(|f| f.default.clone()).collect(),
        file_params,
        tb_params,
    }
    .render()
    .context("cannot render templates/pkg/rmap_top.core")?;
    Ok(text + "\n")
}

/// `README.md` for a design: its configuration, and the scene its maps come from.
pub fn readme(design: &Design) -> Result<String> {
    let cfg = design.cfg();
    let config_rows = toml::to_string(cfg)
        .context("cannot serialise the configuration")?
        .lines()
        .filter_map(|l| l.split_once(" = "))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let ports = TOP
        .ports(cfg)
        .into_iter()
        .map(|p| {
            (
                p.name.to_string(),
                match p.dir {
                    Dir::Input => "in".to_string(),
                    Dir::Output => "out".to_string(),
                },
                match p.width {
                    Width::Bits(b) => b.to_string(),
                    Width::Param(w) => w.to_string(),
                },
                describe(p.name, p.note),
            )
        })
        .collect();
    let latency_list = latency_list(cfg);
    let memories = manifest::memories(cfg)
        .into_iter()
        .map(|m| {
            (
                m.instance,
                format!("{} x {}", m.entries, m.width),
                m.param,
                m.init_file,
            )
        })
        .collect();
    // Every part's row, computed once (the table and its footnote read it).
    let fits = fits_rows(cfg);
    let text = Readme {
        version: env!("CARGO_PKG_VERSION"),
        summary: cfg.summary(),
        prefix: cfg.prefix.clone(),
        top: TOP.module(cfg),
        core: manifest::Core::new(cfg),
        tb_file: TOP
            .vectors()
            .expect("the top has vectors")
            .testbench_file(cfg),
        map2: map_file(cfg, 1, "<axis>"),
        bank_glob: format!("{}*.hex", MapBank.module(cfg)),
        config_rows,
        ports,
        handshake: cfg.handshake,
        latency: top_latency(cfg),
        depth: cfg.pipeline_depth,
        latency_list,
        memories,
        target: cfg.target.name(),
        family: cfg.target.family().map(|f| {
            let d = f.get();
            (d.title, d.target_help, d.default_part().title)
        }),
        family_names: crate::family::either(
            &crate::family::Family::ALL
                .iter()
                .map(|f| format!("`{}`", f.name()))
                .collect::<Vec<_>>(),
        ),
        dies: fits
            .iter()
            .filter(|p| !p.die.is_empty())
            .map(|p| format!("{}: {}", p.part, p.die))
            .collect::<Vec<_>>()
            .join("; "),
        fits,
        valid_edge: top_latency(cfg) - 1,
        compensation: cfg.compensation,
        table_ram: !cfg.comp_table.is_rom(),
        table_entries: cfg.atan_entries(),
        pos_bits: cfg.pos_bits(),
        pos_max: cfg.pos_max(),
        frac_bits: cfg.frac_bits,
        interp_bits: cfg.interp_bits,
        interpolation: cfg.interpolation,
        color: cfg.color,
        grad_bits: cfg.grad_bits,
        grad_min: -(1i64 << (cfg.grad_bits - 1)),
        addr_bits: cfg.map_addr_bits(),
        addr_fields: map_addr::fields(cfg)
            .iter()
            .map(|f| {
                let bits = if f.width == 1 {
                    format!("[{}]", f.lsb)
                } else {
                    format!("[{}:{}]", f.lsb + f.width - 1, f.lsb)
                };
                let meaning = match f.name {
                    "s_max" => "sign of the max-axis component".to_string(),
                    "s_u" => "sign of the u component".to_string(),
                    "s_v" => "sign of the v component".to_string(),
                    n => format!(
                        "index along {}: 0 (component 0) to {} (magnitude equal to the max's)",
                        &n[2..],
                        cfg.entries() - 1
                    ),
                };
                (f.name.to_string(), bits, f.width, meaning)
            })
            .collect(),
        uv_rows: (0..3u32)
            .map(|a| {
                let [x, y, z] = place(a, 0, 1, 2);
                let pos = |k: u32| AXES[[x, y, z].iter().position(|&c| c == k).expect("placed")];
                (
                    a,
                    pos(0).to_string(),
                    pos(1).to_string(),
                    pos(2).to_string(),
                )
            })
            .collect(),
        entries: cfg.entries(),
        tangents: (0..cfg.entries())
            .map(|i| {
                let r = i as f64 / (cfg.entries() - 1) as f64;
                (i, face_tangent(true, r), face_tangent(false, r))
            })
            .collect(),
        map_glob: map_file(cfg, 0, "<axis>"),
        map_x: map_file(cfg, 0, AXES[0]),
        scene_name: if design.scene.name.is_empty() {
            "(given as text)".to_string()
        } else {
            design.scene.name.clone()
        },
        scene_toml: toml::to_string(&design.scene)
            .context("cannot serialise the scene")?
            .trim_end()
            .to_string(),
        map_fit: design.scene.map_fit.name(),
        map_max: cfg.map_max(),
        map_bits: cfg.map_bits,
        writes: crate::map_stream::write_count(cfg),
        last_addr: cfg.map_entries() - 1,
        addr_digits: cfg.map_addr_bits().div_ceil(4),
        data_digits: cfg.map_bits.div_ceil(4),
        record_bytes: map_stream::RECORD_BYTES,
        c_array: map_stream::c_array(cfg),
        c_count: map_stream::c_count(cfg),
        axis: AxisReadme::new(cfg),
        lanes: LanesReadme::new(cfg),
        sections: stages::modules(cfg)
            .iter()
            .filter_map(|m| m.readme(cfg))
            .collect(),
    }
    .render()
    .context("cannot render templates/pkg/README.md")?;
    Ok(text + "\n")
}

/// A port's description for the table: its note, or what the name says.
fn describe(name: &str, note: &str) -> String {
    let base = match name {
        "clk_i" => "clock",
        "rst_ni" => "reset",
        "gx_i" => "gradient x component, G-bit two's complement",
        "gy_i" => "gradient y component, G-bit two's complement",
        "gz_i" => "gradient z component, G-bit two's complement",
        "wr_axis_i" => "host write: axis map (0 x, 1 y, 2 z)",
        "wr_data_i" => "host write: entry",
        "wr_addr_i" => "host write: logical map address",
        _ => "",
    };
    match (base.is_empty(), note.is_empty()) {
        (true, _) => note.to_string(),
        // A note the name's description already says is not said twice.
        (false, true) => base.to_string(),
        (false, false) if base.contains(note) => base.to_string(),
        (false, false) => format!("{base}: {note}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One rule names the core, after the design's top (the module users instantiate), and
    /// the core file, its toplevels, its sim target and the README all follow it.
    #[test]
    fn the_core_is_named_after_the_module_users_instantiate() {
        let axis = Config {
            handshake: true,
            axis: true,
            ..Config::default()
        };
        for (cfg, top) in [
            (Config::default(), "rmap_top"),
            (axis.clone(), "rmap_axis"),
            (
                Config {
                    lanes: 2,
                    ..Config::default()
                },
                "rmap_lanes",
            ),
            (
                Config {
                    prefix: "p_".into(),
                    ..axis
                },
                "p_rmap_axis",
            ),
        ] {
            let c = manifest::Core::new(&cfg);
            assert_eq!(c.toplevel, top);
            assert_eq!(c.file, format!("{top}.core"));
            assert_eq!(c.sim_toplevel, format!("{top}_tb"));
            assert_eq!(
                c.name,
                format!(
                    "rmapgen:ip:{top}_{}:{}",
                    manifest::config_hash(&cfg),
                    env!("CARGO_PKG_VERSION")
                )
            );
            let text = core(&cfg).unwrap();
            for want in [
                format!("# {top}.core: generated"),
                format!("\nname: {}\n", c.name),
                format!("    toplevel: {top}\n"),
                format!("    toplevel: {top}_tb\n"),
                format!("      - tb/{top}_tb.v\n"),
            ] {
                assert!(text.contains(&want), "{want}\n{text}");
            }
            let readme = readme(&Design::standard(&cfg).unwrap()).unwrap();
            assert_eq!(readme.matches(&c.name).count(), 2, "{top}");
            assert!(readme.contains(&format!("`{}`: the FuseSoC (CAPI2) core", c.file)));
            assert_eq!(readme.matches("<module>_<hash>").count(), 1);
        }
    }

    /// A port's description never says its name's description and a note that repeats it
    /// ("colour channel times the intensity: colour times intensity"): every port of the top of
    /// every grid row, the colour ones included.
    #[test]
    fn no_port_description_says_a_thing_twice() {
        for row in crate::grid::rows() {
            let cfg = &row.config;
            for p in TOP.ports(cfg) {
                let d = describe(p.name, p.note);
                if let Some((base, note)) = d.split_once(": ") {
                    let words = |s: &str| {
                        s.split(|c: char| !c.is_alphanumeric())
                            .filter(|w| w.len() > 2)
                            .map(str::to_lowercase)
                            .collect::<Vec<_>>()
                    };
                    let base = words(base);
                    let said = words(note).iter().filter(|w| base.contains(w)).count();
                    assert!(said * 2 < words(note).len().max(1), "{}: {d}", p.name);
                }
            }
        }
    }
}
