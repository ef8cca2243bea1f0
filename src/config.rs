//! The one configuration type. Every width in the model, the ROM contents, the templates,
//! the vectors and the testbenches is read from a validated [`Config`]; derived widths are
//! methods here so that no width is computed in two places.

use crate::family::Family;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Parameters of one reflectance-map shader. Construct with [`Config::default`] (the paper's
/// design) or load from TOML, then call [`Config::validate`] (loaders do it for you).
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Config {
    /// Width of each two's-complement gradient component at the input.
    pub grad_bits: u32,
    /// Width of the magnitudes after sort & shift (leading zeros out, then truncated).
    pub red_bits: u32,
    /// Width of one reciprocal-ROM entry.
    pub recip_bits: u32,
    /// Width of the normalised fractions u, v; the compensation ROM has 2^frac_bits entries.
    pub frac_bits: u32,
    /// Map index bits per component (per sign half): 2^index_bits entries span 0..45 degrees.
    pub index_bits: u32,
    /// Interpolation fraction bits per component (0 when interpolation is off).
    pub interp_bits: u32,
    /// Width of one reflectance-map entry and of the output intensity.
    pub map_bits: u32,
    /// Distortion compensation (atan ROM) on, or a linear index mapping when off.
    pub compensation: bool,
    /// Bilinear interpolation of four neighbours on, or nearest entry when off.
    pub interpolation: bool,
    /// Multiply an 8-bit RGB sample colour by the intensity.
    pub color: bool,
    /// Where the RTL's pipeline registers sit, trading latency for clock rate (the model's
    /// results do not depend on it): 0 compact (fewest registers, lowest latency), 1 adds a
    /// register after every memory read and after every second adder level of the
    /// multipliers, 2 (the default) registers every adder level. Range [`PIPELINE_DEPTHS`];
    /// each stage's `Plan` places the registers and its `Unit::latency` counts them.
    pub pipeline_depth: u32,
    /// A valid/ready handshake (AXI-Stream style) on the top: `ready_o` tells the source a
    /// sample is accepted, `ready_i` low stalls the whole pipeline. Off: a plain valid
    /// stream that accepts a sample every clock `valid_i` is high.
    pub handshake: bool,
    /// Prepended to every generated module name and to every file named after a module or
    /// holding memory contents (`<prefix>rmap_top.v`, `<prefix>recip_rom.hex`, the
    /// testbenches and vector files), and part of the FuseSoC core's name, so that two
    /// generated designs can live in one project. Empty (the default) or a Verilog identifier
    /// prefix: [`check_prefix`]. [`Config::prefixed`] applies it. Left out of the TOML and
    /// JSON when empty, so a design without one is written as before it existed.
    #[serde(skip_serializing_if = "String::is_empty")]
    pub prefix: String,
    /// AXI4-Stream ports: the design's top becomes `rmap_axis` (src/stages/rmap_axis), which
    /// wraps the handshake top in `s_axis_*` / `m_axis_*` ports with byte-aligned `tdata`
    /// (`Packing`, in `stages::rmap_axis`) and passes `tlast` (and `tuser`, when
    /// [`Config::axis_user`] > 0) through with each sample. Needs `handshake` (refused
    /// without it, not implied: the configuration says what is built). Left out of the TOML
    /// and JSON when off, so a design without it is written as before it existed.
    #[serde(skip_serializing_if = "is_false")]
    pub axis: bool,
    /// Width of `tuser` with [`Config::axis`] (0: no `tuser` ports; range [`AXIS_USER_MAX`]);
    /// 0 when `axis` is off. Left out of the TOML and JSON when 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub axis_user: u32,
    /// The tools the memories are written for: [`Target`]. Left out of the TOML and JSON when
    /// `generic` (the default).
    #[serde(skip_serializing_if = "Target::is_generic")]
    pub target: Target,
    /// Parallel lanes ([`LANES`]): the design's top becomes `rmap_lanes`
    /// (src/stages/rmap_lanes), which takes `lanes` gradients a clock and returns `lanes`
    /// results a clock, one rmap_top per lane behind one host write port and one `swap_i`.
    /// 1 (the default) is the single pipeline, rmap_top on top. Left out of the TOML and JSON
    /// when 1, so a design without lanes is written as before the field existed.
    #[serde(skip_serializing_if = "is_one")]
    pub lanes: u32,
    /// How the multipliers are written: [`Mult`]. Left out of the TOML and JSON when `tree`
    /// (the default), so a design without it is written as before the field existed.
    #[serde(skip_serializing_if = "Mult::is_tree")]
    pub mult: Mult,
    /// Where the compensation table's entries come from: [`CompTable`]. Left out of the TOML
    /// and JSON when `rom` (the default), so a design without it is written as before the
    /// field existed.
    #[serde(skip_serializing_if = "CompTable::is_rom")]
    pub comp_table: CompTable,
    /// A CPU bus slave around the design's top: [`Bus`]. Left out of the TOML and JSON when
    /// `none` (the default), so a design without it is written as before the field existed.
    #[serde(skip_serializing_if = "Bus::is_none")]
    pub bus: Bus,
}

/// The bus a CPU loads the maps through (docs/SOC.md): with one, the design's top becomes
/// `rmap_bus` (src/stages/rmap_bus), which puts the register block `rmap_regs`
/// (src/stages/rmap_regs: the identification block, control, status and the map and table
/// windows) on the bus and drives the host write port and the swap itself.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Bus {
    /// No bus: the host write port (`wr_*`, `swap_i`) is the top's.
    #[default]
    None,
    /// Wishbone B4 classic, 32-bit data, word addresses (`wb_*`), as LiteX's SoC bus.
    Wishbone,
    /// AXI4-Lite, 32-bit data, byte addresses (`s_axil_*`).
    #[value(name = "axi4-lite")]
    #[serde(rename = "axi4-lite")]
    Axi4Lite,
}

impl Bus {
    pub fn is_none(&self) -> bool {
        *self == Bus::None
    }

    /// `none`, `wishbone` or `axi4-lite`, as the flag and the TOML spell it.
    pub fn name(&self) -> &'static str {
        match self {
            Bus::None => "none",
            Bus::Wishbone => "wishbone",
            Bus::Axi4Lite => "axi4-lite",
        }
    }
}

/// The compensation table (docs/ARCHITECTURE.md, "Compensation table"): the fixed atan ROM of
/// the paper, or a RAM the host loads with the maps, so that the table can be fitted to each
/// frame's scene (the entries bunch where the intensity turns fastest, src/model/map_fit).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum CompTable {
    /// A ROM of round(atan(u) / (pi/4) * pos_max), fixed when the design is generated.
    #[default]
    Rom,
    /// A double-buffered RAM written through the map write port (axis slot 3, address the
    /// fraction code u, data the position) and swapped with the maps by `swap_i`, so that a
    /// frame's table and maps always change together. Both buffers hold the atan table out of
    /// reset.
    Ram,
}

impl CompTable {
    pub fn is_rom(&self) -> bool {
        *self == CompTable::Rom
    }

    /// `rom` or `ram`, as the flag and the TOML spell it.
    pub fn name(&self) -> &'static str {
        match self {
            CompTable::Rom => "rom",
            CompTable::Ram => "ram",
        }
    }
}

/// How the multipliers are written (docs/ARCHITECTURE.md, "Multipliers"). The products, the
/// ports and the results are the same for both; only the Verilog of each product and where
/// its registers sit differ, each stage's `Plan` decides both and counts the latency.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Mult {
    /// Adder trees of partial products, one LUT level and one carry chain per level
    /// (src/hdl/adder_tree.rs): for devices without multipliers (iCE40 HX).
    #[default]
    Tree,
    /// Plain `a * b` products with explicit widths, registered in front of the sum so that a
    /// DSP block (ECP5 MULT18X18D, iCE40 UltraPlus SB_MAC16) absorbs the product and its
    /// register (src/hdl/infer.rs).
    Infer,
}

impl Mult {
    pub fn is_tree(&self) -> bool {
        *self == Mult::Tree
    }

    /// `tree` or `infer`, as the flag and the TOML spell it.
    pub fn name(&self) -> &'static str {
        match self {
            Mult::Tree => "tree",
            Mult::Infer => "infer",
        }
    }
}

/// How the memories are written (docs/ARCHITECTURE.md, "Targets and FPGA families"). The arithmetic, the ports
/// and the behaviour are the same for every target; only the memories' attributes and the
/// compensation ROM's read ports differ. A family's target writes its memories for its block
/// RAM ([`crate::family::Descriptor::block_ram`]); the flag and the TOML spell it as the
/// family is spelt (`ice40`, `ecp5`), or `generic`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Target {
    /// Plain Verilog-2005 memories any tool infers: no vendor attributes, and one compensation
    /// ROM array with two synchronous read ports (a true dual-port block RAM where the device
    /// has one).
    #[default]
    Generic,
    /// Written for a family's block RAM with Yosys: `ram_style = "block"` on every memory,
    /// `no_rw_check` on the map banks, and one copy of a ROM per read port of its block.
    Family(Family),
}

/// Every target: generic, then each family's.
const TARGETS: [Target; Family::ALL.len() + 1] = {
    let mut t = [Target::Generic; Family::ALL.len() + 1];
    let mut i = 0;
    while i < Family::ALL.len() {
        t[i + 1] = Target::Family(Family::ALL[i]);
        i += 1;
    }
    t
};

/// What `--target generic` writes.
const GENERIC_HELP: &str = "Plain Verilog-2005 memories any tool infers: no vendor attributes, and one compensation ROM array with two synchronous read ports (a true dual-port block RAM where the device has one)";

impl Target {
    pub fn is_generic(&self) -> bool {
        *self == Target::Generic
    }

    /// `generic`, `ice40`, `ecp5`: as the flag and the TOML spell it.
    pub fn name(&self) -> &'static str {
        match self {
            Target::Generic => "generic",
            Target::Family(f) => f.name(),
        }
    }

    /// The target the flag or the TOML spells `name`.
    pub fn from_name(name: &str) -> Option<Target> {
        TARGETS.into_iter().find(|t| t.name() == name)
    }

    /// The family the memories are written for (none for generic).
    pub fn family(&self) -> Option<Family> {
        match self {
            Target::Generic => None,
            Target::Family(f) => Some(*f),
        }
    }

    /// Read ports of the block RAM the memories are written for: 1 (a ROM read twice gets one
    /// copy per read) or 2 (true dual port: two reads of one array, what generic assumes).
    pub fn read_ports(&self) -> u32 {
        self.family().map_or(2, |f| f.get().block_ram.read_ports)
    }

    /// Whether memories carry the Yosys block-RAM attributes (`ram_style = "block"`, and
    /// `no_rw_check` on the map banks): every target but generic.
    pub fn block_attrs(&self) -> bool {
        !self.is_generic()
    }
}

impl Serialize for Target {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Target {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Target, D::Error> {
        let name = String::deserialize(d)?;
        Target::from_name(&name).ok_or_else(|| {
            // serde's own words for an unknown variant.
            let names: Vec<String> = TARGETS.iter().map(|t| format!("`{}`", t.name())).collect();
            serde::de::Error::custom(format_args!(
                "unknown variant `{name}`, expected one of {}",
                names.join(", ")
            ))
        })
    }
}

impl clap::ValueEnum for Target {
    fn value_variants<'a>() -> &'a [Self] {
        &TARGETS
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        let help = match self {
            Target::Generic => GENERIC_HELP,
            Target::Family(f) => f.get().target_help,
        };
        Some(clap::builder::PossibleValue::new(self.name()).help(help))
    }
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn is_zero(v: &u32) -> bool {
    *v == 0
}

fn is_one(v: &u32) -> bool {
    *v == 1
}

/// Allowed values of [`Config::lanes`].
pub const LANES: (u32, u32) = (1, 8);

/// Widest `tuser` of [`Config::axis_user`].
pub const AXIS_USER_MAX: u32 = 64;

/// Longest [`Config::prefix`].
pub const PREFIX_MAX_LEN: usize = 32;

/// Why `p` is not a valid [`Config::prefix`], or `Ok` when it is: empty, or at most
/// [`PREFIX_MAX_LEN`] ASCII letters, digits and `_`, not starting with a digit (so
/// `<prefix><module>` is a plain Verilog identifier and a portable file name).
pub fn check_prefix(p: &str) -> Result<(), String> {
    let what = "a letter or _ then letters, digits and _";
    let n = p.chars().count();
    if n > PREFIX_MAX_LEN {
        return Err(format!(
            "is {n} characters long; allowed {what}, at most {PREFIX_MAX_LEN} characters"
        ));
    }
    match p.chars().next() {
        None => Ok(()),
        Some(c) if c.is_ascii_digit() => Err(format!("starts with a digit; allowed {what}")),
        Some(_) => match p
            .chars()
            .find(|c| !(c.is_ascii_alphanumeric() || *c == '_'))
        {
            Some(c) => Err(format!("has {c:?}; allowed {what}")),
            None => Ok(()),
        },
    }
}

/// Allowed values of [`Config::pipeline_depth`].
pub const PIPELINE_DEPTHS: (u32, u32) = (0, 2);

/// Width of each channel of the optional sample colour.
pub const COLOR_BITS: u32 = 8;

/// Allowed range of every width field, in one table so errors, `--help` and the README agree.
pub const RANGES: &[(&str, u32, u32)] = &[
    ("grad_bits", 8, 16),
    ("red_bits", 6, 12),
    ("recip_bits", 5, 20),
    ("frac_bits", 4, 12),
    ("index_bits", 2, 6),
    ("interp_bits", 0, 5),
    ("map_bits", 6, 12),
];

/// Bits needed to write `v` in binary (at least 1).
pub fn bit_length(v: u64) -> u32 {
    (64 - v.leading_zeros()).max(1)
}

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ConfigError {
    #[error("{field} = {value} is out of range; allowed {min}..={max}")]
    OutOfRange {
        field: &'static str,
        value: u32,
        min: u32,
        max: u32,
    },
    /// A prefix that is not a Verilog identifier prefix ([`check_prefix`]).
    #[error("prefix = {value:?} {why}")]
    BadPrefix { value: String, why: String },
    /// Two or more fields that do not go together: the fields, and what to do.
    #[error("{message}")]
    Conflict {
        fields: Vec<&'static str>,
        message: String,
    },
}

impl ConfigError {
    /// The fields the error is about (the out-of-range one, or the conflicting ones).
    pub fn fields(&self) -> Vec<&'static str> {
        match self {
            ConfigError::OutOfRange { field, .. } => vec![field],
            ConfigError::BadPrefix { .. } => vec!["prefix"],
            ConfigError::Conflict { fields, .. } => fields.clone(),
        }
    }
}

/// The allowed range of a width field from [`RANGES`], or of `pipeline_depth`, `axis_user`
/// or `lanes`.
pub fn range_of(field: &str) -> Option<(u32, u32)> {
    if field == "pipeline_depth" {
        return Some(PIPELINE_DEPTHS);
    }
    if field == "lanes" {
        return Some(LANES);
    }
    if field == "axis_user" {
        return Some((0, AXIS_USER_MAX));
    }
    RANGES
        .iter()
        .find(|r| r.0 == field)
        .map(|&(_, min, max)| (min, max))
}

impl Default for Config {
    /// The paper's configuration: 12-bit gradients, 8-bit reduced magnitudes and fractions,
    /// a 256-entry compensation ROM with 6-bit entries (3 index + 3 interpolation bits) and
    /// three 512-byte maps.
    fn default() -> Self {
        Config {
            grad_bits: 12,
            red_bits: 8,
            recip_bits: 10,
            frac_bits: 8,
            index_bits: 3,
            interp_bits: 3,
            map_bits: 8,
            compensation: true,
            interpolation: true,
            color: false,
            // Not the paper's: the depth that meets 125 MHz on an iCE40 HX8K.
            pipeline_depth: 2,
            handshake: false,
            prefix: String::new(),
            axis: false,
            axis_user: 0,
            target: Target::Generic,
            lanes: 1,
            mult: Mult::Tree,
            comp_table: CompTable::Rom,
            bus: Bus::None,
        }
    }
}

impl Config {
    pub fn field(&self, name: &str) -> u32 {
        match name {
            "grad_bits" => self.grad_bits,
            "red_bits" => self.red_bits,
            "recip_bits" => self.recip_bits,
            "frac_bits" => self.frac_bits,
            "index_bits" => self.index_bits,
            "interp_bits" => self.interp_bits,
            "map_bits" => self.map_bits,
            _ => unreachable!("no width field {name}"),
        }
    }

    /// Checks every range and every constraint between fields.
    pub fn validate(&self) -> Result<(), ConfigError> {
        for &(field, min, max) in RANGES {
            let value = self.field(field);
            if value < min || value > max {
                return Err(ConfigError::OutOfRange {
                    field,
                    value,
                    min,
                    max,
                });
            }
        }
        let (min, max) = PIPELINE_DEPTHS;
        if self.pipeline_depth < min || self.pipeline_depth > max {
            return Err(ConfigError::OutOfRange {
                field: "pipeline_depth",
                value: self.pipeline_depth,
                min,
                max,
            });
        }
        if let Err(why) = check_prefix(&self.prefix) {
            return Err(ConfigError::BadPrefix {
                value: self.prefix.clone(),
                why,
            });
        }
        let c = |fields: &[&'static str], message: String| {
            Err(ConfigError::Conflict {
                fields: fields.to_vec(),
                message,
            })
        };
        if self.red_bits > self.grad_bits {
            return c(&["red_bits", "grad_bits"], format!(
                "red_bits = {} exceeds grad_bits = {}; the reduced magnitude cannot be wider than the gradient",
                self.red_bits, self.grad_bits
            ));
        }
        if self.recip_bits < self.frac_bits + 1 {
            return c(&["recip_bits", "frac_bits"], format!(
                "recip_bits = {} must be at least frac_bits + 1 = {} so the normalised fraction keeps its precision",
                self.recip_bits,
                self.frac_bits + 1
            ));
        }
        if self.axis_user > AXIS_USER_MAX {
            return Err(ConfigError::OutOfRange {
                field: "axis_user",
                value: self.axis_user,
                min: 0,
                max: AXIS_USER_MAX,
            });
        }
        let (min, max) = LANES;
        if self.lanes < min || self.lanes > max {
            return Err(ConfigError::OutOfRange {
                field: "lanes",
                value: self.lanes,
                min,
                max,
            });
        }
        if self.lanes > 1 && self.axis {
            return c(&["lanes", "axis"], format!(
                "lanes = {} with axis: the AXI4-Stream top has one lane; use lanes = 1 with --axis, or leave out --axis",
                self.lanes
            ));
        }
        if self.axis && !self.handshake {
            return c(&["axis", "handshake"], "axis = true needs handshake = true (AXI4-Stream is a valid/ready interface); add --handshake".into());
        }
        if !self.axis && self.axis_user != 0 {
            return c(&["axis_user", "axis"], format!(
                "axis_user = {} without axis; tuser exists only on the AXI4-Stream ports (add --axis)",
                self.axis_user
            ));
        }
        if !self.comp_table.is_rom() {
            if !self.compensation {
                return c(&["comp_table", "compensation"], "comp_table = ram without compensation; the table is the compensation (leave out --no-compensation)".into());
            }
            if self.frac_bits > self.map_addr_bits() || self.pos_bits() > self.map_bits {
                return c(&["comp_table", "frac_bits"], format!(
                    "comp_table = ram writes its {} entries of {} bits through the map write port, whose address is {} bits and data {} bits; give frac_bits <= {} and index_bits + interp_bits <= map_bits",
                    self.atan_entries(), self.pos_bits(), self.map_addr_bits(), self.map_bits, self.map_addr_bits()
                ));
            }
        }
        if !self.bus.is_none() && (self.axis || self.lanes > 1) {
            return c(&["bus", if self.axis { "axis" } else { "lanes" }], format!(
                "bus = {} with {}: the bus slave is in front of one rmap_top so far (with or without the handshake); leave out {}",
                self.bus.name(),
                if self.axis { "axis".to_string() } else { format!("lanes = {}", self.lanes) },
                if self.axis { "--axis" } else { "--lanes" }
            ));
        }
        if self.interpolation && self.interp_bits == 0 {
            return c(&["interp_bits", "interpolation"], "interp_bits = 0 with interpolation on; give interp_bits >= 1 or turn interpolation off".into());
        }
        if !self.interpolation && self.interp_bits != 0 {
            return c(&["interp_bits", "interpolation"], format!(
                "interp_bits = {} with interpolation off; interp_bits must be 0 when interpolation is off",
                self.interp_bits
            ));
        }
        Ok(())
    }

    /// Loads and validates a TOML configuration file; an error is one line naming the file,
    /// the line and column and the key.
    pub fn from_toml_file(path: &Path) -> anyhow::Result<Config> {
        let text = crate::toml_input::read(path, "config")?;
        Config::from_toml_named(&text, &format!("config {}", path.display()))
    }

    /// Parses and validates a configuration; errors start with `what` (e.g. `config c.toml`).
    pub fn from_toml_named(text: &str, what: &str) -> anyhow::Result<Config> {
        let cfg: Config = crate::toml_input::parse(text, what)?;
        cfg.validate().map_err(|e| {
            let key = e.fields()[0];
            crate::toml_input::invalid(
                text,
                what,
                &crate::toml_input::Invalid::new(key, e.to_string()),
            )
        })?;
        Ok(cfg)
    }

    /// `name` with the [`Config::prefix`]: every generated module name and every generated
    /// file named after a module or holding memory contents is made here, and nowhere else.
    pub fn prefixed(&self, name: &str) -> String {
        format!("{}{name}", self.prefix)
    }

    /// Magnitude width: |-(2^(G-1))| needs all G bits.
    pub fn mag_bits(&self) -> u32 {
        self.grad_bits
    }
    /// Map entries per component per sign half.
    pub fn entries(&self) -> u32 {
        1 << self.index_bits
    }
    /// One interpolation step, 2^interp_bits.
    pub fn step(&self) -> u32 {
        1 << self.interp_bits
    }
    /// Largest position: the outer entry, (entries - 1) * step.
    pub fn pos_max(&self) -> u32 {
        (self.entries() - 1) * self.step()
    }
    /// Width of a position (index and fraction together), as stored in the compensation ROM.
    pub fn pos_bits(&self) -> u32 {
        self.index_bits + self.interp_bits
    }
    /// Width of an interpolation weight, 0..=step.
    pub fn weight_bits(&self) -> u32 {
        self.interp_bits + 1
    }
    /// Entries in the reciprocal ROM: the reduced max always has its MSB set.
    pub fn recip_entries(&self) -> u32 {
        1 << (self.red_bits - 1)
    }
    /// Address width of one axis map: {s_max, s_u, i_u, s_v, i_v}.
    pub fn map_addr_bits(&self) -> u32 {
        3 + 2 * self.index_bits
    }
    /// Entries of one axis map.
    pub fn map_entries(&self) -> u32 {
        1 << self.map_addr_bits()
    }
    /// Bits of all three maps (one buffer).
    pub fn map_total_bits(&self) -> u64 {
        3 * self.map_entries() as u64 * self.map_bits as u64
    }
    /// Bits of the fixed ROMs (reciprocal and, when on, compensation).
    pub fn rom_total_bits(&self) -> u64 {
        self.recip_entries() as u64 * self.recip_bits as u64 + self.comp_table_bits()
    }
    /// Bits of the compensation table, one buffer (2^frac_bits positions; 0 without
    /// compensation): a ROM, or with `comp_table = ram` memory the host loads each frame.
    pub fn comp_table_bits(&self) -> u64 {
        if self.compensation {
            (1u64 << self.frac_bits) * self.pos_bits() as u64
        } else {
            0
        }
    }
    pub fn map_max(&self) -> u32 {
        (1 << self.map_bits) - 1
    }
    /// A gradient component's range, two's complement in `grad_bits`:
    /// -2^(G-1) ..= 2^(G-1) - 1.
    pub fn grad_range(&self) -> std::ops::RangeInclusive<i32> {
        let half = 1i32 << (self.grad_bits - 1);
        -half..=half - 1
    }

    // Widths and constants of the generated RTL (src/stages, src/hdl, templates/). Each is defined here
    // once; the templates only name them.

    /// Reciprocal-ROM address width: the reduced max's bits below its MSB.
    pub fn recip_addr_bits(&self) -> u32 {
        self.red_bits - 1
    }
    /// Entries of the compensation (atan) ROM: one per fraction code.
    pub fn atan_entries(&self) -> u32 {
        1 << self.frac_bits
    }
    /// Largest base entry of an interpolation: the outer entry is never a base.
    pub fn base_max(&self) -> u32 {
        self.entries() - 2
    }
    /// Map RAM banks: four (by the parities of i_u and i_v) with interpolation, else one.
    pub fn bank_count(&self) -> u32 {
        if self.interpolation {
            4
        } else {
            1
        }
    }
    /// Width of an entry index inside a bank: i >> 1 with four banks, i with one.
    pub fn bank_index_bits(&self) -> u32 {
        if self.interpolation {
            self.index_bits - 1
        } else {
            self.index_bits
        }
    }
    /// Bank address {buf, axis[1:0], s_max, s_u, i_u', s_v, i_v'}: 6 + 2 * bank_index_bits
    /// (2 * index_bits + 4 with four banks, 2 * index_bits + 6 with one).
    pub fn bank_addr_bits(&self) -> u32 {
        6 + 2 * self.bank_index_bits()
    }
    /// Entries of one bank (both buffers, four axis slots of which three are used).
    pub fn bank_entries(&self) -> u32 {
        1 << self.bank_addr_bits()
    }
    /// Bits of all map banks together.
    pub fn bank_total_bits(&self) -> u64 {
        self.bank_count() as u64 * self.bank_entries() as u64 * self.map_bits as u64
    }
    /// Bits that travel through the top beside each sample: with `axis` `{tuser, tlast}`
    /// (axis_user + 1); with lanes and the handshake the lane's own valid bit (every lane's
    /// rmap_top takes the beat's valid, so that their flow control runs in step: see
    /// src/stages/rmap_lanes); else 0 (the top then has no `side_i` / `side_o`).
    pub fn side_bits(&self) -> u32 {
        if self.axis {
            self.axis_user + 1
        } else if self.lanes > 1 && self.handshake {
            1
        } else {
            0
        }
    }
    pub fn frac_max(&self) -> u32 {
        (1 << self.frac_bits) - 1
    }
    /// A short, stable description used in headers and file names.
    /// The same configuration with its memories written for `target`.
    pub fn for_target(&self, target: Target) -> Config {
        Config {
            target,
            ..self.clone()
        }
    }

    /// [`Config::summary`] with the prefix when there is one: every field, for messages that
    /// tell two configurations apart.
    pub fn summary_full(&self) -> String {
        if self.prefix.is_empty() {
            self.summary()
        } else {
            format!("{} prefix={}", self.summary(), self.prefix)
        }
    }

    /// Every field as `name=value`, with the names of a `--config` file (`grad_bits=12
    /// red_bits=8 ...`), in the file's order: what `generate` says it wrote. The empty prefix
    /// is left out.
    pub fn fields(&self) -> String {
        let text = toml::to_string(self).unwrap_or_default();
        text.lines()
            .filter_map(|l| l.split_once(" = "))
            .filter(|(k, v)| !(*k == "prefix" && *v == "\"\""))
            .map(|(k, v)| format!("{k}={}", v.trim_matches('"')))
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// One line naming every field but the prefix; the target only when it is not generic
    /// (the default), so a default design's summary reads as before the field existed.
    pub fn summary(&self) -> String {
        let target = if self.target.is_generic() {
            String::new()
        } else {
            format!(" target={}", self.target.name())
        };
        format!(
            "G{} R{} W{} F{} I{} P{} M{} comp={} interp={} color={} depth={} handshake={}{target}",
            self.grad_bits,
            self.red_bits,
            self.recip_bits,
            self.frac_bits,
            self.index_bits,
            self.interp_bits,
            self.map_bits,
            self.compensation as u8,
            self.interpolation as u8,
            self.color as u8,
            self.pipeline_depth,
            self.handshake as u8
        ) + &if self.axis {
            format!(" axis user={}", self.axis_user)
        } else {
            String::new()
        } + &if self.lanes > 1 {
            format!(" lanes={}", self.lanes)
        } else {
            String::new()
        } + &if self.mult.is_tree() {
            String::new()
        } else {
            format!(" mult={}", self.mult.name())
        } + &if self.comp_table.is_rom() {
            String::new()
        } else {
            format!(" table={}", self.comp_table.name())
        } + &if self.bus.is_none() {
            String::new()
        } else {
            format!(" bus={}", self.bus.name())
        }
    }
}

/// Eight hex digits naming a configuration: the low 32 bits of the 64-bit FNV-1a hash of
/// its TOML (what `tb/config.toml` holds, prefix included). Stable across runs, machines
/// and rmapgen versions as long as the configuration's fields are; the scene (the maps'
/// initial contents) is data, not configuration, and is not part of it.
pub fn config_hash(cfg: &Config) -> String {
    let text = toml::to_string(cfg).expect("a Config serialises");
    let h = text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    });
    format!("{:08x}", h as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_valid_and_is_the_papers_size() {
        let c = Config::default();
        c.validate().unwrap();
        assert_eq!(c.map_entries(), 512);
        assert_eq!(c.map_total_bits(), 3 * 512 * 8);
        assert_eq!(c.pos_bits(), 6);
        assert_eq!(c.pos_max(), 56);
    }

    #[test]
    fn out_of_range_names_field() {
        let c = Config {
            grad_bits: 20,
            ..Config::default()
        };
        let e = c.validate().unwrap_err().to_string();
        assert!(e.contains("grad_bits = 20") && e.contains("8..=16"), "{e}");
    }

    #[test]
    fn prefixes_are_verilog_identifier_prefixes() {
        for ok in ["", "a_", "_", "Shader2_", "x", &"a".repeat(PREFIX_MAX_LEN)] {
            assert_eq!(check_prefix(ok), Ok(()), "{ok:?}");
            let c = Config {
                prefix: ok.to_string(),
                ..Config::default()
            };
            c.validate().unwrap();
            assert_eq!(c.prefixed("rmap_top"), format!("{ok}rmap_top"));
        }
        for (bad, why) in [
            ("9a_", "starts with a digit"),
            ("a-b", "has '-'"),
            ("a b", "has ' '"),
            ("a/", "has '/'"),
            ("a$", "has '$'"),
            ("é", "has 'é'"),
            (&"a".repeat(PREFIX_MAX_LEN + 1), "33 characters long"),
        ] {
            let c = Config {
                prefix: bad.to_string(),
                ..Config::default()
            };
            let e = c.validate().unwrap_err();
            assert_eq!(e.fields(), ["prefix"]);
            let e = e.to_string();
            assert!(
                e.starts_with("prefix = ") && e.contains(why),
                "{bad:?}: {e}"
            );
        }
    }

    #[test]
    fn conflicts_say_how() {
        let c = Config {
            red_bits: 12,
            grad_bits: 10,
            ..Config::default()
        };
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .contains("exceeds grad_bits"));
        let c = Config {
            interpolation: false,
            ..Config::default()
        };
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .contains("interpolation is off"));
        let c = Config {
            interp_bits: 0,
            ..Config::default()
        };
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .contains("interpolation on"));
    }

    #[test]
    fn axis_needs_the_handshake_and_tuser_needs_axis() {
        let on = Config {
            axis: true,
            handshake: true,
            axis_user: 8,
            ..Config::default()
        };
        on.validate().unwrap();
        assert_eq!(on.side_bits(), 9);
        assert_eq!(Config::default().side_bits(), 0);
        let e = Config {
            handshake: false,
            ..on.clone()
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.fields(), ["axis", "handshake"]);
        assert!(e.to_string().contains("needs handshake"), "{e}");
        let e = Config {
            axis: false,
            ..on.clone()
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.fields(), ["axis_user", "axis"]);
        let e = Config {
            axis_user: AXIS_USER_MAX + 1,
            ..on
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("axis_user = 65"), "{e}");
    }

    #[test]
    fn lanes_are_in_range_and_not_with_axis() {
        for l in [1, 2, 4, 8] {
            Config {
                lanes: l,
                ..Config::default()
            }
            .validate()
            .unwrap();
        }
        for l in [0, 9] {
            let e = Config {
                lanes: l,
                ..Config::default()
            }
            .validate()
            .unwrap_err();
            assert_eq!(e.fields(), ["lanes"]);
            assert!(e.to_string().contains("1..=8"), "{e}");
        }
        let e = Config {
            lanes: 2,
            handshake: true,
            axis: true,
            ..Config::default()
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.fields(), ["lanes", "axis"]);
        let hs = Config {
            lanes: 2,
            handshake: true,
            ..Config::default()
        };
        assert_eq!(hs.side_bits(), 1);
        assert_eq!(
            Config {
                lanes: 2,
                ..Config::default()
            }
            .side_bits(),
            0
        );
        assert!(hs.summary().ends_with(" lanes=2"), "{}", hs.summary());
        let t = toml::to_string(&hs).unwrap();
        assert!(t.contains("lanes = 2"), "{t}");
    }

    #[test]
    fn axis_off_leaves_the_toml_as_it_was() {
        let t = toml::to_string(&Config::default()).unwrap();
        assert!(!t.contains("axis"), "{t}");
        assert!(!t.contains("lanes"), "{t}");
        assert!(!t.contains("mult"), "{t}");
        assert!(!Config::default().summary().contains("mult"));
        let infer = Config {
            mult: Mult::Infer,
            ..Config::default()
        };
        assert!(toml::to_string(&infer)
            .unwrap()
            .contains("mult = \"infer\""));
        assert!(
            infer.summary().ends_with(" mult=infer"),
            "{}",
            infer.summary()
        );
    }

    /// `comp_table = ram` needs the compensation, and a write port wide enough for the
    /// table's addresses and entries; it is left out of the TOML when `rom`, and named in
    /// the summary when `ram`.
    #[test]
    fn a_loaded_table_needs_compensation_and_a_port_that_fits_it() {
        let ram = Config {
            comp_table: CompTable::Ram,
            ..Config::default()
        };
        ram.validate().unwrap();
        assert!(ram.summary().ends_with(" table=ram"), "{}", ram.summary());
        assert!(!toml::to_string(&Config::default())
            .unwrap()
            .contains("comp_table"));
        assert!(toml::to_string(&ram)
            .unwrap()
            .contains("comp_table = \"ram\""));
        let e = Config {
            compensation: false,
            ..ram.clone()
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.fields(), vec!["comp_table", "compensation"]);
        // 2^8 table entries through a 7-bit map address (index_bits 2).
        let e = Config {
            index_bits: 2,
            ..ram.clone()
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("address is 7 bits"), "{e}");
        Config {
            index_bits: 2,
            frac_bits: 7,
            ..ram.clone()
        }
        .validate()
        .unwrap();
        // 9 position bits (index 4 + interpolation 5) into 8-bit map entries.
        let e = Config {
            index_bits: 4,
            interp_bits: 5,
            ..ram
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("data 8 bits"), "{e}");
    }
}
