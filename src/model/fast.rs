//! A fast, bit-exact batch path for the model: [`FastShader`] gives `Model::intensity` for
//! many gradients at a time, by reading two fused tables that are filled by calling the
//! stage functions themselves, so the two paths cannot drift apart.
//!
//! - **positions** (fixed per configuration): (reduced max m, reduced component a) → map
//!   position, fusing the reciprocal ROM, the normalise lane and the atan ROM (or the linear
//!   index). Without fusion (wide `red_bits`, where the table would not fit in cache) the
//!   reciprocal ROM and the normalise lane are evaluated per sample and only the position
//!   stage is a table.
//! - **intensities** (per frame, from the maps): (axis, sign bits, p_u, p_v) → intensity,
//!   fusing the map look-up and the interpolator. Without fusion (very fine positions) the
//!   look-up and interpolation stages are called per sample.
//!
//! What stays per sample is sort & shift: absolute values, the max axis under the tie rule, the
//! leading-zero shift and the truncation to `red_bits`, all branch-free.

use super::{interpolate, map_lookup, normalise, recip_rom, Maps, Model};
use crate::config::Config;
use rayon::prelude::*;

/// Largest fused position table, in entries: 2^(2 red_bits - 1), so `red_bits` <= 10.
const FUSED_POSITIONS_MAX: usize = 1 << 19;
/// Largest fused intensity table, in entries: 24 (pos_max + 1)^2.
const FUSED_INTENSITIES_MAX: usize = 1 << 21;
/// Samples per rayon task in [`FastShader::shade_batch_par`].
const PAR_CHUNK: usize = 1 << 14;

/// The model's output stage, fused: see the module documentation.
#[derive(Clone, Debug)]
pub struct FastShader {
    cfg: Config,
    /// The reciprocal ROM and the table the positions were fused from: with `comp_table =
    /// ram` a new frame may bring a new table ([`FastShader::set_maps_for`]).
    model: Model,
    table: Option<Vec<u32>>,
    positions: Positions,
    intensities: Intensities,
}

/// Table entries one byte wide when they fit, for a smaller cache footprint.
#[derive(Clone, Debug)]
enum Table {
    U8(Vec<u8>),
    U16(Vec<u16>),
}

impl Table {
    /// A table of `len` entries, each `f(index)`, all below 2^bits (bits <= 16).
    fn build(len: usize, bits: u32, mut f: impl FnMut(usize) -> u32) -> Table {
        debug_assert!(bits <= 16);
        if bits <= 8 {
            Table::U8((0..len).map(|k| f(k) as u8).collect())
        } else {
            Table::U16((0..len).map(|k| f(k) as u16).collect())
        }
    }

    #[inline(always)]
    fn get(&self, k: usize) -> u32 {
        match self {
            Table::U8(t) => t[k] as u32,
            Table::U16(t) => t[k] as u32,
        }
    }
}

#[derive(Clone, Debug)]
enum Positions {
    /// table[((m - 2^(R-1)) << R) | a].
    Fused { table: Table, red_bits: u32 },
    /// Reciprocal ROM and lane per sample, then table[u].
    Split { recip: Vec<u32>, position: Vec<u32> },
}

#[derive(Clone, Debug)]
enum Intensities {
    /// table[offset[axis * 8 + sign code] + p_u * stride + p_v], stride = pos_max + 1.
    Fused {
        table: Table,
        stride: u32,
        offset: [u32; 24],
    },
    /// Map look-up and interpolation per sample.
    Direct { maps: Maps },
}

/// Sort & shift of one sample, as the fused stages need it.
#[derive(Clone, Copy, Debug)]
struct Sorted {
    zero: bool,
    axis: u32,
    /// Sign bits of the gradient as x | y << 1 | z << 2 (not yet in (max, u, v) order).
    code: u32,
    m: u32,
    a: u32,
    b: u32,
}

/// Sign bits (s_max, s_u, s_v) of a sign code for a max axis, in the model's (max, u, v)
/// order: max x gives (x, y, z), max y gives (y, x, z), max z gives (z, x, y).
pub fn ordered_signs(axis: u32, code: u32) -> (u32, u32, u32) {
    let (sx, sy, sz) = (code & 1, (code >> 1) & 1, (code >> 2) & 1);
    match axis {
        0 => (sx, sy, sz),
        1 => (sy, sx, sz),
        _ => (sz, sx, sy),
    }
}

/// The integer output of the stages after the positions: map look-up and, when on,
/// interpolation, exactly as `Model::trace` chains them.
pub fn intensity_at(
    cfg: &Config,
    maps: &Maps,
    axis: u32,
    signs: (u32, u32, u32),
    p_u: u32,
    p_v: u32,
) -> u32 {
    let (s_max, s_u, s_v) = signs;
    let l = map_lookup::eval(cfg, maps, axis, s_max, s_u, s_v, p_u, p_v);
    if cfg.interpolation {
        interpolate::eval(cfg, l.e, l.w_u, l.w_v)
    } else {
        l.e[0]
    }
}

impl Positions {
    /// The positions of `model`, reading the compensation table `maps` carries when it
    /// carries one (`comp_table = ram`).
    fn new(model: &Model, maps: &Maps, limit: usize) -> Positions {
        let cfg = &model.cfg;
        let lane = |m: u32, a: u32| {
            let recip = model.recip[recip_rom::addr(cfg, m) as usize];
            model.position_in(maps, normalise::lane(cfg, a, m, recip))
        };
        let r = cfg.red_bits;
        if 1usize << (2 * r - 1) <= limit.min(FUSED_POSITIONS_MAX) {
            let half = 1u32 << (r - 1);
            // Entry ((m - half) << r) | a; unreachable entries (a > m) are filled too.
            let table = Table::build(1 << (2 * r - 1), cfg.pos_bits(), |k| {
                let k = k as u32;
                lane(half + (k >> r), k & ((1 << r) - 1))
            });
            Positions::Fused { table, red_bits: r }
        } else {
            let position = (0..=cfg.frac_max())
                .map(|u| model.position_in(maps, u))
                .collect();
            Positions::Split {
                recip: model.recip.clone(),
                position,
            }
        }
    }
}

impl Intensities {
    fn new(cfg: &Config, maps: &Maps, limit: usize) -> Intensities {
        let stride = cfg.pos_max() + 1;
        let per_face = (stride * stride) as usize;
        if 24 * per_face > limit.min(FUSED_INTENSITIES_MAX) {
            return Intensities::Direct { maps: maps.clone() };
        }
        // One block per (axis, s_max, s_u, s_v), in that order, each p_u-major.
        let table = Table::build(24 * per_face, cfg.map_bits, |k| {
            let (block, within) = ((k / per_face) as u32, (k % per_face) as u32);
            let signs = ((block >> 2) & 1, (block >> 1) & 1, block & 1);
            intensity_at(
                cfg,
                maps,
                block >> 3,
                signs,
                within / stride,
                within % stride,
            )
        });
        let mut offset = [0u32; 24];
        for axis in 0..3 {
            for code in 0..8 {
                let (s_max, s_u, s_v) = ordered_signs(axis, code);
                let block = axis * 8 + s_max * 4 + s_u * 2 + s_v;
                offset[(axis * 8 + code) as usize] = block * per_face as u32;
            }
        }
        Intensities::Fused {
            table,
            stride,
            offset,
        }
    }
}

impl FastShader {
    /// Fuses the model's ROMs (once per configuration) and the maps (once per frame).
    pub fn new(model: &Model, maps: &Maps) -> FastShader {
        FastShader::for_samples(model, maps, usize::MAX)
    }

    /// [`FastShader::new`] for a one-off batch of about `samples` gradients: a stage is fused
    /// only when its table has at most `samples` entries, so building the tables never costs
    /// more than the batch (`rmapgen fit` shades one image per configuration).
    pub fn for_samples(model: &Model, maps: &Maps, samples: usize) -> FastShader {
        FastShader {
            cfg: model.cfg.clone(),
            model: model.clone(),
            table: maps.table.clone(),
            positions: Positions::new(model, maps, samples),
            intensities: Intensities::new(&model.cfg, maps, samples),
        }
    }

    /// Replaces the maps (a new frame), keeping the position table unless the frame brings
    /// its own compensation table.
    pub fn set_maps(&mut self, maps: &Maps) {
        self.set_maps_for(maps, usize::MAX);
    }

    /// [`FastShader::set_maps`] for a frame of about `samples` gradients: the intensity
    /// table is fused only when it has at most `samples` entries (as
    /// [`FastShader::for_samples`]), so a frame that shades few samples does not pay for a
    /// table much larger than its work.
    pub fn set_maps_for(&mut self, maps: &Maps, samples: usize) {
        if maps.table != self.table {
            self.positions = Positions::new(&self.model, maps, samples);
            self.table = maps.table.clone();
        }
        self.intensities = Intensities::new(&self.cfg, maps, samples);
    }

    /// Whether each stage runs from a fused table: (positions, intensities).
    pub fn fused(&self) -> (bool, bool) {
        (
            matches!(self.positions, Positions::Fused { .. }),
            matches!(self.intensities, Intensities::Fused { .. }),
        )
    }

    /// The position the model gives component `a` under max `m` (both reduced, a <= m).
    #[inline]
    pub fn position(&self, m: u32, a: u32) -> u32 {
        match &self.positions {
            Positions::Fused { table, red_bits } => {
                let row = m & ((1 << (red_bits - 1)) - 1);
                table.get(((row << red_bits) | a) as usize)
            }
            Positions::Split { recip, position } => {
                let r = recip[recip_rom::addr(&self.cfg, m) as usize];
                position[normalise::lane(&self.cfg, a, m, r) as usize]
            }
        }
    }

    /// The intensity of the fused table at (axis, sign code, p_u, p_v): what any gradient
    /// with these sort results and positions shades to (before the zero flag).
    #[inline]
    pub fn intensity_at(&self, axis: u32, code: u32, p_u: u32, p_v: u32) -> u32 {
        match &self.intensities {
            Intensities::Fused {
                table,
                stride,
                offset,
            } => table.get((offset[(axis * 8 + code) as usize] + p_u * stride + p_v) as usize),
            Intensities::Direct { maps } => {
                intensity_at(&self.cfg, maps, axis, ordered_signs(axis, code), p_u, p_v)
            }
        }
    }

    /// Sort & shift without branches on the data.
    #[inline(always)]
    fn sort(&self, g: [i32; 3]) -> Sorted {
        debug_assert!(
            g.iter().all(|&c| super::sort_shift::in_range(&self.cfg, c)),
            "gradient {g:?} out of range"
        );
        let [x, y, z] = g;
        let (mx, my, mz) = (x.unsigned_abs(), y.unsigned_abs(), z.unsigned_abs());
        let code = (x as u32 >> 31) | ((y as u32 >> 31) << 1) | ((z as u32 >> 31) << 2);
        let x_wins = (mx >= my) & (mx >= mz);
        let y_wins = !x_wins & (my >= mz);
        let axis = (!x_wins) as u32 + (!x_wins & !y_wins) as u32;
        let max = mx.max(my).max(mz);
        let mu = if x_wins { my } else { mx };
        let mv = if axis == 2 { my } else { mz };
        // Shifting the max's MSB to bit 31 and keeping the top red_bits is the model's shift
        // by its leading zeros in grad_bits followed by dropping grad_bits - red_bits.
        let lz = (max | 1).leading_zeros();
        let down = 32 - self.cfg.red_bits;
        Sorted {
            zero: max == 0,
            axis,
            code,
            m: (max << lz) >> down,
            a: (mu << lz) >> down,
            b: (mv << lz) >> down,
        }
    }

    /// The intensity of one gradient: equal to `Model::intensity`.
    #[inline(always)]
    pub fn shade(&self, g: [i32; 3]) -> u32 {
        let s = self.sort(g);
        let p_u = self.position(s.m, s.a);
        let p_v = self.position(s.m, s.b);
        let i = self.intensity_at(s.axis, s.code, p_u, p_v);
        if s.zero {
            0
        } else {
            i
        }
    }

    /// Intensities of many gradients on the calling thread; `out[k]` = `Model::intensity` of
    /// `grads[k]`.
    pub fn shade_batch(&self, grads: &[[i32; 3]], out: &mut [u16]) {
        assert_eq!(grads.len(), out.len(), "one output per gradient");
        // One monomorphised loop per pair of stage kinds, so the hot path has no match.
        match (&self.positions, &self.intensities) {
            (
                Positions::Fused {
                    table: pt,
                    red_bits,
                },
                Intensities::Fused {
                    table: it,
                    stride,
                    offset,
                },
            ) => match (pt, it) {
                (Table::U8(p), Table::U8(i)) => {
                    self.fused_loop(p, *red_bits, i, *stride, offset, grads, out)
                }
                (Table::U8(p), Table::U16(i)) => {
                    self.fused_loop(p, *red_bits, i, *stride, offset, grads, out)
                }
                (Table::U16(p), Table::U8(i)) => {
                    self.fused_loop(p, *red_bits, i, *stride, offset, grads, out)
                }
                (Table::U16(p), Table::U16(i)) => {
                    self.fused_loop(p, *red_bits, i, *stride, offset, grads, out)
                }
            },
            _ => {
                for (g, o) in grads.iter().zip(out.iter_mut()) {
                    *o = self.shade(*g) as u16;
                }
            }
        }
    }

    /// The hot loop with both stages fused, for each pair of table entry widths.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn fused_loop<P: Copy + Into<u32>, I: Copy + Into<u16>>(
        &self,
        pt: &[P],
        red_bits: u32,
        it: &[I],
        stride: u32,
        offset: &[u32; 24],
        grads: &[[i32; 3]],
        out: &mut [u16],
    ) {
        let half_mask = (1u32 << (red_bits - 1)) - 1;
        for (g, o) in grads.iter().zip(out.iter_mut()) {
            let s = self.sort(*g);
            let row = (s.m & half_mask) << red_bits;
            let p_u: u32 = pt[(row | s.a) as usize].into();
            let p_v: u32 = pt[(row | s.b) as usize].into();
            let i: u16 =
                it[(offset[(s.axis * 8 + s.code) as usize] + p_u * stride + p_v) as usize].into();
            *o = if s.zero { 0 } else { i };
        }
    }

    /// [`FastShader::shade_batch`] on all rayon threads.
    pub fn shade_batch_par(&self, grads: &[[i32; 3]], out: &mut [u16]) {
        assert_eq!(grads.len(), out.len(), "one output per gradient");
        grads
            .par_chunks(PAR_CHUNK)
            .zip(out.par_chunks_mut(PAR_CHUNK))
            .for_each(|(g, o)| self.shade_batch(g, o));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::reflectance_map;

    #[test]
    fn default_is_fully_fused_and_matches_corners() {
        let cfg = Config::default();
        let model = Model::new(&cfg);
        let maps = reflectance_map::contents(&cfg, |n| 0.5 + 0.5 * n.x * n.y.abs() - 0.25 * n.z);
        let fast = FastShader::new(&model, &maps);
        assert_eq!(fast.fused(), (true, true));
        let corners = [
            [0, 0, 0],
            [1, 0, 0],
            [0, -1, 0],
            [0, 0, 1],
            [-2048, -2048, -2048],
            [-2048, 2047, 0],
            [2047, 2047, 2047],
            [9, 9, -9],
            [1, 9, 9],
            [5, -700, 700],
        ];
        let mut out = vec![0u16; corners.len()];
        fast.shade_batch(&corners, &mut out);
        for (g, o) in corners.iter().zip(&out) {
            assert_eq!(*o as u32, model.intensity(&maps, *g), "{g:?}");
            assert_eq!(fast.shade(*g), model.intensity(&maps, *g), "{g:?}");
        }
    }

    /// With `comp_table = ram` a frame's table is the buffer's own: out of reset (the atan
    /// table) the design shades as the ROM design does; with another table, the fast path,
    /// fused and split, follows it and equals the model; a new frame's table replaces the
    /// positions, and a frame with the same table keeps them.
    #[test]
    fn a_loaded_table_is_read_by_the_model_and_the_fast_path() {
        let rom_cfg = Config::default();
        let cfg = Config {
            comp_table: crate::config::CompTable::Ram,
            ..Config::default()
        };
        let light = |n: glam::DVec3| 0.3 + 0.7 * (n.x * 0.6 + n.z * 0.8).max(0.0).powi(20);
        let (model, rom_model) = (Model::new(&cfg), Model::new(&rom_cfg));
        let maps = reflectance_map::contents(&cfg, light);
        let rom_maps = reflectance_map::contents(&rom_cfg, light);
        assert_eq!(maps.table.as_deref(), rom_model.atan.as_deref());
        let mut rng = crate::rng::SplitMix64::new(7);
        let grads: Vec<[i32; 3]> = (0..20_000)
            .map(|_| [0; 3].map(|_| (rng.next_u64() % 4096) as i32 - 2048))
            .collect();
        for g in &grads {
            assert_eq!(
                model.intensity(&maps, *g),
                rom_model.intensity(&rom_maps, *g)
            );
        }
        // A monotone table of its own: positions squeezed towards the axis (u^2).
        let max = cfg.pos_max() as u64;
        let n = cfg.atan_entries() as u64;
        let table: Vec<u32> = (0..n)
            .map(|u| (u * u * max / ((n - 1) * (n - 1))) as u32)
            .collect();
        let loaded = maps.clone().with_table(&cfg, table).unwrap();
        let mut fast = FastShader::new(&model, &maps);
        let mut split = FastShader::for_samples(&model, &maps, 1);
        assert_eq!((fast.fused().0, split.fused().0), (true, false));
        let mut differ = 0;
        for (f, frame) in [&loaded, &maps, &loaded].into_iter().enumerate() {
            fast.set_maps(frame);
            split.set_maps_for(frame, 1);
            let mut out = vec![0u16; grads.len()];
            fast.shade_batch(&grads, &mut out);
            for (g, o) in grads.iter().zip(&out) {
                let want = model.intensity(frame, *g);
                assert_eq!(
                    (*o as u32, split.shade(*g)),
                    (want, want),
                    "frame {f} {g:?}"
                );
                differ += (f == 0 && want != model.intensity(&maps, *g)) as u32;
            }
        }
        assert!(differ > 1000, "the table changes the results: {differ}");
        // Tables that do not fit are refused, and a ROM design takes none.
        let e = |r: anyhow::Result<Maps>| r.unwrap_err().to_string();
        assert!(e(maps.clone().with_table(&cfg, vec![0; 3])).contains("3 entries"));
        let mut past = vec![0; n as usize];
        past[5] = cfg.pos_max() + 1;
        assert!(e(maps.clone().with_table(&cfg, past)).contains("entry 5"));
        assert!(e(rom_maps.with_table(&rom_cfg, vec![0; n as usize])).contains("comp_table = rom"));
    }

    /// Each kind of table the fast path builds (one- and two-byte entries, positions fused
    /// or split, intensities fused or direct) gives the model's intensity, one sample at a
    /// time, in a batch and in a parallel batch of several chunks.
    #[test]
    fn every_table_kind_and_the_parallel_batch_equal_the_model() {
        let base = Config::default();
        let cases = [
            // (configuration, fused, positions two bytes, intensities two bytes)
            (base.clone(), (true, true), false, false),
            (
                Config {
                    map_bits: 10,
                    ..base.clone()
                },
                (true, true),
                false,
                true,
            ),
            // pos_bits 9: two-byte positions, and too many positions to fuse intensities.
            (
                Config {
                    index_bits: 5,
                    interp_bits: 4,
                    map_bits: 10,
                    ..base.clone()
                },
                (true, false),
                true,
                false,
            ),
            // red_bits 11: 2^21 position entries, past FUSED_POSITIONS_MAX.
            (
                Config {
                    red_bits: 11,
                    ..base.clone()
                },
                (false, true),
                false,
                false,
            ),
        ];
        let mut rng = crate::rng::SplitMix64::new(5);
        let grads: Vec<[i32; 3]> = (0..3 * PAR_CHUNK + 5)
            .map(|k| {
                let span = if k % 3 == 0 { 64 } else { 4096 };
                [0; 3].map(|_| (rng.next_u64() % span) as i32 - span as i32 / 2)
            })
            .collect();
        for (cfg, fused, wide_positions, wide_intensities) in cases {
            let model = Model::new(&cfg);
            let data = (0..3 * cfg.map_entries())
                .map(|_| (rng.next_u64() % (cfg.map_max() as u64 + 1)) as u32)
                .collect();
            let maps = Maps::from_data(&cfg, data);
            let fast = FastShader::new(&model, &maps);
            assert_eq!(fast.fused(), fused, "{}", cfg.summary());
            if let Positions::Fused { table, .. } = &fast.positions {
                assert_eq!(matches!(table, Table::U16(_)), wide_positions);
            }
            if let Intensities::Fused { table, .. } = &fast.intensities {
                assert_eq!(matches!(table, Table::U16(_)), wide_intensities);
            }
            let want: Vec<u16> = grads
                .iter()
                .map(|g| model.intensity(&maps, *g) as u16)
                .collect();
            assert!(want.iter().any(|&i| i > 255) == (cfg.map_bits > 8));
            let (mut out, mut par) = (vec![0u16; grads.len()], vec![0u16; grads.len()]);
            fast.shade_batch(&grads, &mut out);
            fast.shade_batch_par(&grads, &mut par);
            assert!(out == want && par == want, "{}", cfg.summary());
            for (g, w) in grads.iter().zip(&want).step_by(97) {
                assert_eq!(fast.shade(*g), *w as u32, "{g:?} {}", cfg.summary());
            }
        }
    }
}
