//! The Verilog generator: one template per module (`templates/<module>.v`), the ROM and map
//! init files, and `manifest.json`. docs/ARCHITECTURE.md is the specification; the module
//! list, the ports and the latencies below are its tables in code, and everything that needs
//! them (the templates, the manifest, the testbenches) reads them from here.

pub mod adder_tree;
pub mod banks;
pub mod fpga;
pub mod manifest;
pub mod package;
pub mod pipe;
pub mod ports;
pub mod tb;
pub mod templates;
pub mod verilated;

use crate::config::Config;
use crate::hexfile;
use crate::output::StagedDir;
use crate::vectors::MapSet;
use anyhow::Result;
pub use manifest::Manifest;
pub use ports::{Dir, Port, Width};
use serde::Serialize;

/// Every module the generator can emit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Module {
    ZeroDetect,
    SortShift,
    RecipRom,
    Normalise,
    AtanRom,
    LinearIndex,
    MapLookup,
    MapBank,
    Interpolate,
    ColorMul,
    PipeDelay,
    RmapTop,
}

impl Module {
    pub const ALL: [Module; 12] = [
        Module::ZeroDetect,
        Module::SortShift,
        Module::RecipRom,
        Module::Normalise,
        Module::AtanRom,
        Module::LinearIndex,
        Module::MapLookup,
        Module::MapBank,
        Module::Interpolate,
        Module::ColorMul,
        Module::PipeDelay,
        Module::RmapTop,
    ];

    /// The Verilog module name, which is also its file's stem and its template's.
    pub fn name(self) -> &'static str {
        match self {
            Module::ZeroDetect => "zero_detect",
            Module::SortShift => "sort_shift",
            Module::RecipRom => "recip_rom",
            Module::Normalise => "normalise",
            Module::AtanRom => "atan_rom",
            Module::LinearIndex => "linear_index",
            Module::MapLookup => "map_lookup",
            Module::MapBank => "map_bank",
            Module::Interpolate => "interpolate",
            Module::ColorMul => "color_mul",
            Module::PipeDelay => "pipe_delay",
            Module::RmapTop => "rmap_top",
        }
    }

    pub fn from_name(name: &str) -> Option<Module> {
        Module::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The generated file, `<name>.v`.
    pub fn file(self) -> String {
        format!("{}.v", self.name())
    }

    /// The module that instantiates this one (None for the top).
    pub fn parent(self) -> Option<Module> {
        match self {
            Module::RmapTop => None,
            Module::RecipRom => Some(Module::Normalise),
            Module::MapBank => Some(Module::MapLookup),
            _ => Some(Module::RmapTop),
        }
    }
}

/// The top's output register (it applies the zero flag).
pub const OUTPUT_LATENCY: u32 = 1;

/// Clock cycles from a module's inputs to its registered outputs (valid_i to valid_o for a
/// stage, address to data for a ROM or bank); `None` for `pipe_delay`, whose latency is its
/// DEPTH parameter. This is the one place latencies are defined; they follow
/// `pipeline_depth` through the register plans of [`pipe`].
pub fn latency(cfg: &Config, m: Module) -> Option<u32> {
    Some(match m {
        Module::ZeroDetect => 1,
        Module::SortShift => pipe::sort_shift_latency(cfg),
        Module::RecipRom => 1,
        Module::Normalise => pipe::normalise(cfg).latency,
        Module::AtanRom => 1 + pipe::atan_out_reg(cfg) as u32,
        Module::LinearIndex => pipe::linear_index(cfg).latency,
        Module::MapLookup => 3 + pipe::bank_out_reg(cfg) as u32,
        Module::MapBank => 1,
        Module::Interpolate => pipe::interpolate(cfg).latency,
        Module::ColorMul => pipe::color_mul(cfg).latency,
        Module::PipeDelay => return None,
        Module::RmapTop => return Some(top_latency(cfg)),
    })
}

/// [`latency`] by module name, for callers that hold names (testbench generation).
pub fn stage_latency(cfg: &Config, name: &str) -> Option<u32> {
    latency(cfg, Module::from_name(name)?)
}

/// The stages a sample's valid bit passes through, in order (zero_detect runs beside
/// sort_shift and is not in this chain).
pub fn pipeline(cfg: &Config) -> Vec<Module> {
    let mut v = vec![
        Module::SortShift,
        Module::Normalise,
        position_stage(cfg),
        Module::MapLookup,
    ];
    if cfg.interpolation {
        v.push(Module::Interpolate);
    }
    if cfg.color {
        v.push(Module::ColorMul);
    }
    v
}

/// atan_rom with distortion compensation, linear_index without.
pub fn position_stage(cfg: &Config) -> Module {
    if cfg.compensation {
        Module::AtanRom
    } else {
        Module::LinearIndex
    }
}

fn lat(cfg: &Config, m: Module) -> u32 {
    latency(cfg, m).expect("a pipeline stage has a fixed latency")
}

/// Clock cycles from accepting a sample (valid_i high at a rising edge) to its result on
/// valid_o of rmap_top: the stages in [`pipeline`] and the output register.
pub fn top_latency(cfg: &Config) -> u32 {
    pipeline(cfg).iter().map(|&m| lat(cfg, m)).sum::<u32>() + OUTPUT_LATENCY
}

/// DEPTH of each of the top's sideband delay lines.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct SidebandDelays {
    /// Axis and signs, from sort_shift's outputs to map_lookup's inputs.
    pub sign: u32,
    /// The read buffer, from acceptance to map_lookup's inputs.
    pub buf: u32,
    /// The zero flag, from zero_detect's output to the output register's input.
    pub zero: u32,
    /// The sample colour, from acceptance to color_mul's inputs (colour only).
    pub rgb: Option<u32>,
    /// The intensity beside color_mul (colour only).
    pub intensity: Option<u32>,
}

pub fn sideband_delays(cfg: &Config) -> SidebandDelays {
    let sort = lat(cfg, Module::SortShift);
    let to_lookup = lat(cfg, Module::Normalise) + lat(cfg, position_stage(cfg));
    let before_color = sort
        + to_lookup
        + lat(cfg, Module::MapLookup)
        + if cfg.interpolation {
            lat(cfg, Module::Interpolate)
        } else {
            0
        };
    let color = cfg.color.then(|| lat(cfg, Module::ColorMul));
    SidebandDelays {
        sign: to_lookup,
        buf: sort + to_lookup,
        zero: top_latency(cfg) - OUTPUT_LATENCY - lat(cfg, Module::ZeroDetect),
        rgb: color.map(|_| before_color),
        intensity: color,
    }
}

/// The modules of a configuration in instantiation order: the top, then what it instantiates
/// in the order its file does (each child right after its parent), pipe_delay last. Stages
/// the configuration leaves out are absent.
pub fn modules(cfg: &Config) -> Vec<Module> {
    let mut v = vec![
        Module::RmapTop,
        Module::ZeroDetect,
        Module::SortShift,
        Module::Normalise,
        Module::RecipRom,
    ];
    v.push(position_stage(cfg));
    v.push(Module::MapLookup);
    v.push(Module::MapBank);
    if cfg.interpolation {
        v.push(Module::Interpolate);
    }
    if cfg.color {
        v.push(Module::ColorMul);
    }
    v.push(Module::PipeDelay);
    v
}

/// Every `$readmemh` file of a design: recip_rom.hex, atan_rom.hex (with compensation), the
/// scene's logical maps map_<axis>.hex, the second map map2_<axis>.hex (the alternate scene's,
/// which testbenches load through the host port) and the map banks' init files. `generate`
/// and `roms` both write exactly these.
pub fn hex_files(cfg: &Config, maps: &MapSet) -> Vec<(String, String)> {
    let mut v = hexfile::all(cfg, &maps.scene);
    let alt = &maps.second;
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        let what = format!(
            "second reflectance map (scene two_lights), max axis {name}, address {{s_max, s_u, i_u, s_v, i_v}}"
        );
        v.push((
            format!("map2_{name}.hex"),
            hexfile::format(cfg, &what, cfg.map_bits, alt.axis(axis as u32)),
        ));
    }
    v.extend(banks::bank_files(cfg, &maps.scene));
    v
}

/// Writes every module's `.v`, the ROM and map init files, the logical maps of the scene
/// (`map_<axis>.hex`) and of the alternate scene (`map2_<axis>.hex`, which testbenches load
/// through the host port), the FuseSoC core and README of [`package`], and `manifest.json`.
/// Returns the manifest. `maps` are built once by the caller, which hands the same value to
/// the vectors.
pub fn write_design(cfg: &Config, maps: &MapSet, out: &StagedDir) -> Result<Manifest> {
    cfg.validate()?;
    let mut files = Vec::new();
    let mut write = |name: String, text: &str| -> Result<()> {
        out.write_text(&name, text)?;
        files.push(name);
        Ok(())
    };
    for m in modules(cfg) {
        write(m.file(), &templates::render(cfg, m)?)?;
    }
    let mut hex = Vec::new();
    for (name, text) in hex_files(cfg, maps) {
        hex.push(name.clone());
        write(name, &text)?;
    }
    write(package::CORE_FILE.into(), &package::core(cfg, &hex)?)?;
    write(package::README_FILE.into(), &package::readme(cfg)?)?;
    files.push(manifest::FILE.to_string());
    let manifest = Manifest::new(cfg, files);
    out.write_text(manifest::FILE, &manifest.to_json())?;
    Ok(manifest)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at_depth(depth: u32, cfg: Config) -> Config {
        Config {
            pipeline_depth: depth,
            ..cfg
        }
    }

    #[test]
    fn compact_latency_is_the_documented_twelve() {
        let cfg = at_depth(0, Config::default());
        assert_eq!(top_latency(&cfg), 12);
        let d = sideband_delays(&cfg);
        assert_eq!((d.sign, d.buf, d.zero, d.rgb), (4, 6, 10, None));
    }

    #[test]
    fn default_depth_two_registers_every_adder_level() {
        let cfg = Config::default();
        assert_eq!(cfg.pipeline_depth, 2);
        let stages: Vec<u32> = pipeline(&cfg).iter().map(|&m| lat(&cfg, m)).collect();
        // sort_shift: magnitude, compare, select, shift; normalise: ROM, ROM register, three
        // adder levels, saturation; atan ROM and its register; map_lookup with the bank
        // register; interpolate: complements, three levels per pass.
        assert_eq!(stages, [4, 6, 2, 4, 7]);
        assert_eq!(top_latency(&cfg), 24);
        let d = sideband_delays(&cfg);
        assert_eq!((d.sign, d.buf, d.zero), (8, 12, 22));
        assert_eq!(top_latency(&at_depth(1, cfg)), 19);
    }

    #[test]
    fn colour_adds_its_stage_and_lines_up_the_colour() {
        let cfg = at_depth(
            0,
            Config {
                color: true,
                ..Config::default()
            },
        );
        assert_eq!(top_latency(&cfg), 14);
        let d = sideband_delays(&cfg);
        assert_eq!((d.zero, d.rgb, d.intensity), (12, Some(11), Some(2)));
        let off = Config {
            interpolation: false,
            interp_bits: 0,
            compensation: false,
            ..cfg.clone()
        };
        assert_eq!(top_latency(&off), 2 + 3 + 1 + 3 + 2 + 1);
        // Deeper: the colour waits for the deeper stages, the intensity beside color_mul too.
        let deep = at_depth(2, cfg);
        let d = sideband_delays(&deep);
        let cm = lat(&deep, Module::ColorMul);
        assert!(cm > 2);
        assert_eq!(d.intensity, Some(cm));
        assert_eq!(d.rgb, Some(top_latency(&deep) - OUTPUT_LATENCY - cm));
    }

    #[test]
    fn names_round_trip_and_absent_stages_are_absent() {
        for m in Module::ALL {
            assert_eq!(Module::from_name(m.name()), Some(m));
        }
        let off = Config {
            compensation: false,
            interpolation: false,
            interp_bits: 0,
            ..Config::default()
        };
        let ms = modules(&off);
        assert!(ms.contains(&Module::LinearIndex));
        for absent in [Module::AtanRom, Module::Interpolate, Module::ColorMul] {
            assert!(!ms.contains(&absent), "{absent:?}");
        }
    }
}
