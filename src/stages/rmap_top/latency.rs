//! The top's timing, computed from the stages' own latencies (each counted from its register
//! plan): the pipeline a sample's valid bit passes through, the top's latency, and the
//! depths of the sideband delay lines that carry values beside the stages.

use crate::config::Config;
use crate::stages::atan_rom::AtanRom;
use crate::stages::color_mul::ColorMul;
use crate::stages::interpolate::Interpolate;
use crate::stages::linear_index::LinearIndex;
use crate::stages::map_lookup::MapLookup;
use crate::stages::normalise::Normalise;
use crate::stages::sort_shift::SortShift;
use crate::stages::unit::Unit;
use crate::stages::zero_detect::ZeroDetect;
use serde::Serialize;

/// The top's output register (it applies the zero flag).
pub const OUTPUT_LATENCY: u32 = 1;

/// The position stage: atan_rom with distortion compensation, linear_index without.
pub fn position(cfg: &Config) -> &'static dyn Unit {
    if cfg.compensation {
        &AtanRom
    } else {
        &LinearIndex
    }
}

/// The stages a sample's valid bit passes through, in order (zero_detect runs beside
/// sort_shift and is not in this chain).
pub fn pipeline(cfg: &Config) -> Vec<&'static dyn Unit> {
    let mut v: Vec<&'static dyn Unit> = vec![&SortShift, &Normalise, position(cfg), &MapLookup];
    if cfg.interpolation {
        v.push(&Interpolate);
    }
    if cfg.color {
        v.push(&ColorMul);
    }
    v
}

fn lat(cfg: &Config, m: &dyn Unit) -> u32 {
    m.latency(cfg)
        .expect("a pipeline stage has a fixed latency")
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
    /// `side_i` (tuser and tlast with `axis`, the lane's valid bit with lanes and the
    /// handshake), from acceptance to the output register's input: the whole pipeline (only
    /// with [`Config::side_bits`] > 0; left out of the manifest without it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub side: Option<u32>,
    /// The read buffer, from acceptance to the compensation table's inputs (only with
    /// `comp_table = ram`, whose table is double-buffered; left out of the manifest without
    /// it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub table_buf: Option<u32>,
}

pub fn sideband_delays(cfg: &Config) -> SidebandDelays {
    let sort = lat(cfg, &SortShift);
    let to_lookup = lat(cfg, &Normalise) + lat(cfg, position(cfg));
    let before_color = sort
        + to_lookup
        + lat(cfg, &MapLookup)
        + if cfg.interpolation {
            lat(cfg, &Interpolate)
        } else {
            0
        };
    let color = cfg.color.then(|| lat(cfg, &ColorMul));
    SidebandDelays {
        sign: to_lookup,
        buf: sort + to_lookup,
        zero: top_latency(cfg) - OUTPUT_LATENCY - lat(cfg, &ZeroDetect),
        rgb: color.map(|_| before_color),
        intensity: color,
        side: (cfg.side_bits() > 0).then(|| top_latency(cfg) - OUTPUT_LATENCY),
        table_buf: (!cfg.comp_table.is_rom()).then(|| sort + lat(cfg, &Normalise)),
    }
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
        let cm = lat(&deep, &ColorMul);
        assert!(cm > 2);
        assert_eq!(d.intensity, Some(cm));
        assert_eq!(d.rgb, Some(top_latency(&deep) - OUTPUT_LATENCY - cm));
    }

    #[test]
    fn compact_keeps_the_legacy_latencies() {
        let cfg = Config {
            color: true,
            pipeline_depth: 0,
            ..Config::default()
        };
        assert_eq!(lat(&cfg, &Normalise), 3);
        assert_eq!(lat(&cfg, &Interpolate), 2);
        assert_eq!(lat(&cfg, &ColorMul), 2);
        let lin = Config {
            compensation: false,
            ..cfg
        };
        assert_eq!(lat(&lin, &LinearIndex), 1);
    }

    #[test]
    fn deeper_is_never_shorter() {
        for depth in 0..2 {
            let a = Config {
                color: true,
                pipeline_depth: depth,
                ..Config::default()
            };
            let b = Config {
                pipeline_depth: depth + 1,
                ..a.clone()
            };
            let units: [&dyn Unit; 4] = [&Normalise, &Interpolate, &ColorMul, &LinearIndex];
            for u in units {
                assert!(lat(&a, u) <= lat(&b, u), "{}", u.name());
            }
        }
    }
}
