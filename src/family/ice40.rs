//! Lattice iCE40: Debian's Yosys (`synth_ice40`) and nextpnr-ice40.

use super::{BlockRam, Descriptor, Names, Part, PartFlags, Tool, YOSYS};

/// The iCE40 HX and UltraPlus parts rmapgen places on, as nextpnr-ice40 reports their
/// capacity (`--pack-only`).
const PARTS: &[Part] = &[
    Part {
        device: "hx1k",
        package: "tq144",
        title: "iCE40-HX1K",
        boards: "iCEstick",
        die: None,
        logic_cells: 1280,
        block_rams: 16,
        dsps: 0,
    },
    Part {
        device: "hx4k",
        package: "tq144",
        title: "iCE40-HX4K",
        boards: "",
        die: Some("iCE40-HX8K"),
        logic_cells: 3520,
        block_rams: 20,
        dsps: 0,
    },
    Part {
        device: "up5k",
        package: "sg48",
        title: "iCE40-UP5K",
        boards: "iCEBreaker, UPduino",
        die: None,
        logic_cells: 5280,
        block_rams: 30,
        dsps: 8,
    },
    Part {
        device: "hx8k",
        package: "ct256",
        title: "iCE40-HX8K",
        boards: "iCE40-HX8K breakout",
        die: None,
        logic_cells: 7680,
        block_rams: 32,
        dsps: 0,
    },
];

pub static ICE40: Descriptor = Descriptor {
    name: "ice40",
    title: "iCE40",
    target_help: "Lattice iCE40 with Yosys: `ram_style = \"block\"` on every memory (block RAM even for a ROM Yosys would build from LUTs), `no_rw_check` on the map banks (no logic to define a same-address read and write, which the top never issues), and one copy of the compensation ROM per read port (an SB_RAM40_4K has one read port)",
    parts: PARTS,
    default_device: "hx8k",
    // SB_RAM40_4K: 4 kbit, one read and one write port.
    block_ram: BlockRam {
        cell: "SB_RAM40_4K",
        cells: &["SB_RAM40_4K"],
        read_ports: 1,
        shapes: &[(16, 256), (8, 512), (4, 1024), (2, 2048)],
        dual_width: 16,
    },
    yosys: YOSYS,
    synth_pass: "synth_ice40",
    verilog_netlist: true,
    nextpnr: Tool {
        var: "NEXTPNR",
        program: "nextpnr-ice40",
        venv: false,
    },
    names: Names {
        logic: "ICESTORM_LC",
        block_ram: "ICESTORM_RAM",
        dsp: "ICESTORM_DSP",
        luts: &["SB_LUT4"],
        carries: &["SB_CARRY"],
        flip_flops: &["SB_DFF"],
        dsps: &["SB_MAC16"],
    },
    dsps: false,
    bitstream: ("--asc", "asc"),
    out_of_context: false,
    part_flags: PartFlags::Lattice,
};
