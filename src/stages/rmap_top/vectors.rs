//! The top's vectors: gradients (and colours) in, the zero flag, the intensity (and colour)
//! out, in two parts, one per map buffer, so the testbench checks the buffer swap too. The
//! expected values are `Model::shade`.

use super::RmapTop;
use crate::config::{Config, COLOR_BITS};
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::stages::testbench::TbData;
use crate::stages::unit::{port_of, Traced, Unit, Vectors, RESET_AT};
use crate::vectors::field::Field;
use crate::vectors::inputs::{
    dec_grad, gradient_corners, grads, random_top_gradient, COLOR_CORNERS,
};
use anyhow::Result;
use askama::Template;

crate::tb_template!(Testbench, "rmap_top/rmap_top_tb.v");

/// The top's hand-picked inputs for one map: every gradient corner, colours cycling.
pub fn corners_for_map(cfg: &Config, map: u64) -> Vec<Vec<u64>> {
    gradient_corners(cfg)
        .into_iter()
        .enumerate()
        .map(|(i, g)| {
            let mut v = vec![map];
            v.extend(grads(cfg, g));
            if cfg.color {
                v.extend(
                    COLOR_CORNERS[i % COLOR_CORNERS.len()]
                        .iter()
                        .map(|&c| c as u64),
                );
            }
            v
        })
        .collect()
}

/// One random input of the top for one map.
pub fn random_for_map(cfg: &Config, rng: &mut SplitMix64, map: u64) -> Vec<u64> {
    let mut v = vec![map];
    v.extend(grads(cfg, random_top_gradient(cfg, rng)));
    if cfg.color {
        for _ in 0..3 {
            v.push(rng.bits(COLOR_BITS));
        }
    }
    v
}

/// Lines of a top stream of `random` random vectors: both parts' corner cases, the random
/// vectors and the repeated swap witness (see [`RmapTop::inputs`]).
pub fn stream_lines(cfg: &Config, random: u64) -> u64 {
    (corners_for_map(cfg, 0).len() + corners_for_map(cfg, 1).len()) as u64 + 1 + random
}

impl Vectors for RmapTop {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        let (g, m, c) = (cfg.grad_bits, cfg.map_bits, COLOR_BITS);
        let mut v = vec![
            Field::input("map", 1),
            Field::input("gx", g),
            Field::input("gy", g),
            Field::input("gz", g),
        ];
        if cfg.color {
            v.extend([
                Field::input("r", c),
                Field::input("g", c),
                Field::input("b", c),
            ]);
        }
        v.extend([Field::output("zero", 1), Field::output("i", m)]);
        if cfg.color {
            v.extend([
                Field::output("r_o", c),
                Field::output("g_o", c),
                Field::output("b_o", c),
            ]);
        }
        v
    }

    /// The first part's corners (map 0); the second part repeats them with map 1.
    fn corners(&self, model: &Model, _maps: &MapSet) -> Vec<Vec<u64>> {
        corners_for_map(&model.cfg, 0)
    }

    /// A first-part (map 0) random input.
    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        random_for_map(cfg, rng, 0)
    }

    fn expected(&self, model: &Model, maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        let cfg = &model.cfg;
        let u = |k: usize| inp[k] as u32;
        let g = |k: usize| dec_grad(cfg, inp[k]);
        let rgb = if cfg.color {
            [u(4), u(5), u(6)]
        } else {
            [0; 3]
        };
        let o = model.shade(maps.buffer(inp[0]), [g(1), g(2), g(3)], rgb);
        let mut v = vec![o.zero as u64, o.intensity as u64];
        if cfg.color {
            v.extend(o.rgb.map(u64::from));
        }
        v
    }

    fn traced(&self, cfg: &Config, s: &Traced) -> Vec<u64> {
        let mut v = vec![s.buf];
        v.extend(grads(cfg, s.g));
        if cfg.color {
            v.extend(s.rgb.map(u64::from));
        }
        v
    }

    /// Two parts: with map 0 the corners, the first half of the random vectors (rounded up)
    /// and the swap witness; then with map 1 the witness again, the other corners and the
    /// rest of the random vectors. The witness is the first corner gradient whose result
    /// differs between the two maps, so the vectors on both sides of the swap tell the
    /// buffers apart: the testbench swaps with the first map-1 vector.
    fn inputs(
        &self,
        model: &Model,
        maps: &MapSet,
        random: usize,
        seed: u64,
        emit: &mut dyn FnMut(&[u64]) -> Result<()>,
    ) -> Result<()> {
        let cfg = &model.cfg;
        let mut rng = SplitMix64::for_stream(seed, self.name());
        let first = random.div_ceil(2);
        let mut corners1 = corners_for_map(cfg, 1);
        let witness = corners1
            .iter()
            .position(|c| {
                self.expected(model, maps, c)
                    != self.expected(model, maps, &[&[0], &c[1..]].concat())
            })
            .unwrap_or(0);
        let w1 = corners1.remove(witness);
        let mut w0 = w1.clone();
        w0[0] = 0;
        for c in corners_for_map(cfg, 0) {
            emit(&c)?;
        }
        for _ in 0..first {
            emit(&random_for_map(cfg, &mut rng, 0))?;
        }
        emit(&w0)?;
        emit(&w1)?;
        for c in corners1 {
            emit(&c)?;
        }
        for _ in first..random {
            emit(&random_for_map(cfg, &mut rng, 1))?;
        }
        Ok(())
    }

    /// `map` steers the testbench (which buffer to expect), not a port.
    fn port(&self, field: &Field) -> Option<String> {
        match field.name {
            "map" => None,
            _ => Some(port_of(field)),
        }
    }

    /// At most half the map-0 corners, so the reset comes before the swap.
    fn reset_at(&self, cfg: &Config) -> u32 {
        RESET_AT.min(corners_for_map(cfg, 0).len() as u32 / 2)
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
