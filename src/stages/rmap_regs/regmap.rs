//! The register map of the bus slave, described once as data (docs/SOC.md): every view is
//! generated from [`regmap`] — the register block's Verilog (`rmap_regs.v`: its addresses,
//! its read-back and its write strobes), the C header and the driver (`rmap_regs.h`,
//! `rmap_driver.[ch]`), the SystemRDL file that PeakRDL compiles (`rmap_regs.rdl`), the
//! design's README table and the Python constants (`rmap_regs.py`, and the manifest's `bus`).
//!
//! The bus is 32 bits wide. Byte addresses: the registers from 0, one word each; then the
//! write windows, one word per entry, from [`RegMap::window_base`]: the three axis maps and,
//! with `comp_table = ram`, the compensation table, at word `(axis << A) | address` of the
//! window (A = [`Config::map_addr_bits`]), so that a write's offset is the host write port's
//! `{wr_axis_i, wr_addr_i}` times 4.

use crate::config::{Config, LANES};
use crate::model::map_set::AXES;
use serde::Serialize;

/// The identification word every design answers at offset 0: "RMAP" in ASCII.
pub const MAGIC: u32 = 0x524D_4150;

/// The version of this register map (VERSION.REGMAP): a driver checks it before anything
/// else. Raise it whenever an offset, a field or a meaning changes.
pub const REGMAP_VERSION: u32 = 1;

/// Bits of the bus's data.
pub const DATA_BITS: u32 = 32;

/// How software sees a register.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Access {
    /// Read-only; a write is refused (an error response, counted in ERRORS).
    Ro,
    /// Write-only strobes (a field written 1 acts once); reads as 0.
    Wo,
}

impl Access {
    pub fn name(&self) -> &'static str {
        match self {
            Access::Ro => "RO",
            Access::Wo => "WO",
        }
    }
}

/// Where a field's value comes from, or what writing it does.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Source {
    /// A constant of the configuration: what a driver compares with the one it was built for.
    Const(u64),
    /// A register of the block (its Verilog name), read as it is.
    Status(&'static str),
    /// A write strobe (its Verilog wire), high for the write that sets the field to 1.
    Strobe(&'static str),
}

/// One field of a register: bits `[lsb + bits - 1 : lsb]`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Field {
    pub name: &'static str,
    pub lsb: u32,
    pub bits: u32,
    pub source: Source,
    pub doc: String,
}

impl Field {
    /// The field's bits in place: `((1 << bits) - 1) << lsb`.
    pub fn mask(&self) -> u32 {
        (((1u64 << self.bits) - 1) << self.lsb) as u32
    }
    /// `[msb:lsb]`, or `[lsb]` for one bit.
    pub fn range(&self) -> String {
        if self.bits == 1 {
            format!("[{}]", self.lsb)
        } else {
            format!("[{}:{}]", self.lsb + self.bits - 1, self.lsb)
        }
    }
    /// The constant's value, for a [`Source::Const`] field.
    pub fn value(&self) -> Option<u64> {
        match self.source {
            Source::Const(v) => Some(v),
            _ => None,
        }
    }
}

/// One 32-bit register.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Reg {
    pub name: &'static str,
    /// Byte offset from the slave's base.
    pub offset: u32,
    pub access: Access,
    pub doc: &'static str,
    /// Fields from bit 0 up, none overlapping; the bits between them read 0.
    pub fields: Vec<Field>,
}

impl Reg {
    /// The Verilog expression the register reads as: its fields from the top bit down, the
    /// bits between them 0 (a write-only register reads 0).
    pub fn read_expr(&self) -> String {
        if self.access == Access::Wo {
            return format!("{DATA_BITS}'d0");
        }
        let mut parts = Vec::new();
        let mut at = DATA_BITS;
        for f in self.fields.iter().rev() {
            let top = f.lsb + f.bits;
            if at > top {
                parts.push(format!("{}'d0", at - top));
            }
            parts.push(match &f.source {
                Source::Const(v) => format!("{}'h{v:x}", f.bits),
                Source::Status(s) => s.to_string(),
                Source::Strobe(_) => unreachable!("a strobe in a readable register"),
            });
            at = f.lsb;
        }
        if at > 0 {
            parts.push(format!("{at}'d0"));
        }
        format!("{{{}}}", parts.join(", "))
    }

    /// Its word address: the byte offset over 4.
    pub fn word(&self) -> u32 {
        self.offset / 4
    }
}

/// A write window: one word per entry of a memory behind the host write port.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Window {
    /// `MAP_X`, `MAP_Y`, `MAP_Z`, `TABLE`.
    pub name: String,
    /// The host write port's `wr_axis_i` for it.
    pub axis: u32,
    /// Byte offset of entry 0.
    pub offset: u32,
    /// Entries: the rest of its slot (up to 2^A words) is undefined.
    pub entries: u32,
    /// Bits of an entry, in the word's low bits; the bits above are ignored.
    pub bits: u32,
    pub doc: String,
}

/// The whole map: registers, windows and the address width they need.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct RegMap {
    pub regs: Vec<Reg>,
    pub windows: Vec<Window>,
    /// Byte address bits the slave decodes: the span is 2^addr_bits bytes.
    pub addr_bits: u32,
    /// Byte offset of the windows: word `(axis << A) | address` of them is the entry.
    pub window_base: u32,
    /// Bytes of one axis slot of the windows: 4 << A.
    pub axis_stride: u32,
}

impl RegMap {
    /// The register of this name.
    pub fn reg(&self, name: &str) -> &Reg {
        self.regs
            .iter()
            .find(|r| r.name == name)
            .unwrap_or_else(|| panic!("no register {name}"))
    }
    /// Word address bits the slave decodes (byte address bits less 2).
    pub fn word_bits(&self) -> u32 {
        self.addr_bits - 2
    }
    /// Bytes the slave spans: what a SoC reserves for it.
    pub fn span(&self) -> u32 {
        1 << self.addr_bits
    }
}

/// Register space before the windows: 16 words (more than the registers need, so that a
/// later version can add registers without moving the windows of a design).
const REG_WORDS: u32 = 16;

/// The version rmapgen writes into VERSION: (major, minor, patch) of the crate.
pub fn rmapgen_version() -> (u32, u32, u32) {
    let mut it = env!("CARGO_PKG_VERSION")
        .split(['.', '-'])
        .map(|s| s.parse::<u32>().unwrap_or(0));
    (
        it.next().unwrap_or(0),
        it.next().unwrap_or(0),
        it.next().unwrap_or(0),
    )
}

/// The configuration hash CFG_HASH holds: [`config_hash`] (the manifest and the FuseSoC
/// core's name carry the same eight hex digits).
///
/// [`config_hash`]: crate::config::config_hash
pub fn cfg_hash(cfg: &Config) -> u32 {
    u32::from_str_radix(&crate::config::config_hash(cfg), 16).expect("eight hex digits")
}

fn field(name: &'static str, lsb: u32, bits: u32, source: Source, doc: impl Into<String>) -> Field {
    Field {
        name,
        lsb,
        bits,
        source,
        doc: doc.into(),
    }
}

/// The register map of a configuration with a bus.
pub fn regmap(cfg: &Config) -> RegMap {
    use Source::{Const, Status, Strobe};
    let (major, minor, patch) = rmapgen_version();
    let c = |v: u32| Const(v as u64);
    let b = |v: bool| Const(v as u64);
    // LANES' largest value must fit its field.
    const _: () = assert!(LANES.1 < 16);
    let regs = vec![
        Reg {
            name: "ID",
            offset: 0x00,
            access: Access::Ro,
            doc: "Identification: \"RMAP\" in ASCII. A driver reads it first: anything else is not an rmapgen slave.",
            fields: vec![field("MAGIC", 0, 32, c(MAGIC), "0x524D4150")],
        },
        Reg {
            name: "VERSION",
            offset: 0x04,
            access: Access::Ro,
            doc: "The rmapgen that generated the design, and the version of this register map.",
            fields: vec![
                field("PATCH", 0, 8, c(patch), "rmapgen's patch version"),
                field("MINOR", 8, 8, c(minor), "rmapgen's minor version"),
                field("MAJOR", 16, 8, c(major), "rmapgen's major version"),
                field("REGMAP", 24, 8, c(REGMAP_VERSION), "the register map's version: a driver refuses any other"),
            ],
        },
        Reg {
            name: "LAYOUT0",
            offset: 0x08,
            access: Access::Ro,
            doc: "The widths that decide the map layout and the samples.",
            fields: vec![
                field("GRAD_BITS", 0, 5, c(cfg.grad_bits), "gradient component width"),
                field("MAP_BITS", 8, 4, c(cfg.map_bits), "map entry width (the low bits of a window word)"),
                field("INDEX_BITS", 12, 3, c(cfg.index_bits), "map index bits per component"),
                field("INTERP_BITS", 16, 3, c(cfg.interp_bits), "interpolation fraction bits (0: nearest entry)"),
                field("FRAC_BITS", 20, 4, c(cfg.frac_bits), "fraction width: the compensation table has 2^FRAC_BITS entries"),
                field("ADDR_BITS", 24, 4, c(cfg.map_addr_bits()), "map address bits A: 2^A entries per axis map"),
            ],
        },
        Reg {
            name: "LAYOUT1",
            offset: 0x0C,
            access: Access::Ro,
            doc: "The options that change what a frame loads and how samples flow.",
            fields: vec![
                field("LANES", 0, 4, c(cfg.lanes), "samples per clock"),
                field("COLOR", 4, 1, b(cfg.color), "1: an RGB colour multiplies the intensity"),
                field("TABLE_RAM", 5, 1, b(!cfg.comp_table.is_rom()), "1: the compensation table is loaded with the maps (the TABLE window)"),
                field("HANDSHAKE", 6, 1, b(cfg.handshake), "1: valid/ready flow control"),
                field("AXIS", 7, 1, b(cfg.axis), "1: the samples are on AXI4-Stream ports"),
                field("COMPENSATION", 8, 1, b(cfg.compensation), "1: distortion compensation"),
                field("INTERPOLATION", 9, 1, b(cfg.interpolation), "1: bilinear interpolation"),
            ],
        },
        Reg {
            name: "CFG_HASH",
            offset: 0x10,
            access: Access::Ro,
            doc: "The configuration's hash (its tb/config.toml, prefix included; the FuseSoC core's name carries it): a driver built for another configuration sees another value.",
            fields: vec![field("HASH", 0, 32, c(cfg_hash(cfg)), "FNV-1a of the configuration's TOML, low 32 bits")],
        },
        Reg {
            name: "CONTROL",
            offset: 0x14,
            access: Access::Wo,
            doc: "Commands: each bit written 1 acts once; reads 0.",
            fields: vec![
                field("SWAP", 0, 1, Strobe("swap_req"), "request a buffer swap: it happens at the next frame boundary (STATUS.SWAP_PENDING until then)"),
                field("CLEAR_ERRORS", 1, 1, Strobe("clear_errors"), "set ERRORS to 0"),
            ],
        },
        Reg {
            name: "STATUS",
            offset: 0x18,
            access: Access::Ro,
            doc: "What the slave is waiting for.",
            fields: vec![
                field("SWAP_PENDING", 0, 1, Status("pending_q"), "a swap is requested and waits for the frame boundary"),
                field("DRAINING", 1, 1, Status("draining"), "samples accepted before the last swap are still in the pipeline: a window write waits for them"),
                field("IN_FRAME", 2, 1, Status("in_frame_q"), "a sample without the frame's last flag was accepted and the frame's last was not yet"),
            ],
        },
        Reg {
            name: "FRAMES",
            offset: 0x1C,
            access: Access::Ro,
            doc: "Swaps performed since reset (wraps): a driver that requested a swap waits until it changes.",
            fields: vec![field("COUNT", 0, 32, Status("frames_q"), "")],
        },
        Reg {
            name: "ERRORS",
            offset: 0x20,
            access: Access::Ro,
            doc: "Accesses answered with an error since reset or CONTROL.CLEAR_ERRORS (saturates): an undefined address, a write to a read-only register, a read of a window, a partial write.",
            fields: vec![field("COUNT", 0, 16, Status("errors_q"), "")],
        },
    ];
    debug_assert!(regs.iter().all(|r| r.word() < REG_WORDS));
    let a = cfg.map_addr_bits();
    let axis_stride = 4u32 << a;
    // The windows take four axis slots of 2^A words: the upper half of the span.
    let window_base = axis_stride * 4;
    let mut windows: Vec<Window> = AXES
        .iter()
        .enumerate()
        .map(|(k, name)| Window {
            name: format!("MAP_{}", name.to_uppercase()),
            axis: k as u32,
            offset: window_base + k as u32 * axis_stride,
            entries: cfg.map_entries(),
            bits: cfg.map_bits,
            doc: format!(
                "the back buffer's map of max axis {name}: entry `{{s_max, s_u, i_u, s_v, i_v}}` at word address"
            ),
        })
        .collect();
    if !cfg.comp_table.is_rom() {
        windows.push(Window {
            name: "TABLE".into(),
            axis: 3,
            offset: window_base + 3 * axis_stride,
            entries: cfg.atan_entries(),
            bits: cfg.pos_bits(),
            doc: "the back buffer's compensation table: entry u (the fraction code) at word u"
                .into(),
        });
    }
    debug_assert!(REG_WORDS * 4 <= window_base);
    RegMap {
        regs,
        windows,
        addr_bits: crate::config::bit_length(window_base as u64 * 2 - 1),
        window_base,
        axis_stride,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::CompTable;

    /// Fields in order, inside 32 bits, none overlapping; every constant fits its field.
    #[test]
    fn fields_fit_and_do_not_overlap() {
        for cfg in [
            Config::default(),
            Config {
                comp_table: CompTable::Ram,
                lanes: 8,
                grad_bits: 16,
                index_bits: 6,
                ..Config::default()
            },
        ] {
            let m = regmap(&cfg);
            let mut offsets: Vec<u32> = m.regs.iter().map(|r| r.offset).collect();
            offsets.dedup();
            assert_eq!(offsets.len(), m.regs.len());
            for r in &m.regs {
                assert_eq!(r.offset % 4, 0);
                let mut used = 0u32;
                for f in &r.fields {
                    assert!(f.lsb + f.bits <= 32, "{}.{}", r.name, f.name);
                    assert_eq!(used & f.mask(), 0, "{}.{} overlaps", r.name, f.name);
                    used |= f.mask();
                    if let Some(v) = f.value() {
                        assert!(v < 1 << f.bits, "{}.{} = {v}", r.name, f.name);
                    }
                }
            }
        }
    }

    #[test]
    fn the_default_layout() {
        let m = regmap(&Config::default());
        assert_eq!(m.axis_stride, 2048);
        assert_eq!(m.window_base, 8192);
        assert_eq!(m.addr_bits, 14);
        assert_eq!(m.span(), 16384);
        assert_eq!(m.windows.len(), 3);
        assert_eq!(m.windows[2].offset, 8192 + 4096);
        assert_eq!(m.reg("ID").read_expr(), "{32'h524d4150}",);
        assert_eq!(
            m.reg("STATUS").read_expr(),
            "{29'd0, in_frame_q, draining, pending_q}"
        );
        assert_eq!(m.reg("CONTROL").read_expr(), "32'd0");
        let ram = regmap(&Config {
            comp_table: CompTable::Ram,
            ..Config::default()
        });
        assert_eq!(ram.windows[3].name, "TABLE");
        assert_eq!(ram.windows[3].entries, 256);
    }
}
