//! One ray through the volume: where its samples lie (`Ray`), the trilinear value and
//! gradient at each, and the front-to-back march with empty-space skipping and early ray
//! termination. Separate from the caster's image loops ([`super::Caster::render`],
//! [`super::Caster::collect`]), which march every pixel's ray.

use super::frame::Stats;
use super::Caster;

/// Rounds half away from zero, like `f32::round` for |v| < 2^23, without a libm call on
/// baseline x86-64: adds the largest float below 0.5 with v's sign and truncates.
#[inline]
pub fn round_half_away(v: f32) -> i32 {
    (v + 0.499_999_97f32.copysign(v)) as i32
}

/// One ray in voxel coordinates: sample k (0..count) at start + delta * k.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ray {
    start: [f32; 3],
    delta: [f32; 3],
    count: u32,
}

impl Caster<'_> {
    /// The samples of pixel (x, y), or `None` when its ray misses the box.
    pub(super) fn ray(&self, x: u32, y: u32) -> Option<Ray> {
        let (o, d) = self.camera.ray(x, y);
        let s = self.vol.spacing;
        let (o, d) = (
            [o.x / s[0], o.y / s[1], o.z / s[2]],
            [d.x / s[0], d.y / s[1], d.z / s[2]],
        );
        let (mut near, mut far) = (f64::NEG_INFINITY, f64::INFINITY);
        for a in 0..3 {
            let hi = (self.vol.dims[a] - 1) as f64;
            if d[a] == 0.0 {
                if o[a] < 0.0 || o[a] > hi {
                    return None;
                }
            } else {
                let (t0, t1) = ((0.0 - o[a]) / d[a], (hi - o[a]) / d[a]);
                near = near.max(t0.min(t1));
                far = far.min(t0.max(t1));
            }
        }
        if near > far {
            return None;
        }
        let h = self.opts.step * self.vol.unit();
        let (m0, m1) = ((near / h).ceil(), (far / h).floor());
        let count = if m1 >= m0 { (m1 - m0) as u32 + 1 } else { 0 };
        let t0 = m0 * h;
        Some(Ray {
            start: [0, 1, 2].map(|a| (o[a] + d[a] * t0) as f32),
            delta: [0, 1, 2].map(|a| (d[a] * h) as f32),
            count,
        })
    }

    /// The cell holding a position (clamped to the volume) and the position within it.
    #[inline]
    fn locate(&self, p: [f32; 3]) -> ([usize; 3], [f32; 3]) {
        let mut c = [0usize; 3];
        let mut f = [0f32; 3];
        for a in 0..3 {
            // Truncation equals floor for p > -1, and both clamp to 0 below that (NaN too).
            let ci = (p[a] as i32).clamp(0, self.vol.dims[a] as i32 - 2);
            c[a] = ci as usize;
            f[a] = (p[a] - ci as f32).clamp(0.0, 1.0);
        }
        (c, f)
    }

    /// First sample index at or after where the ray leaves the box of brick `cell / size`.
    #[inline]
    fn brick_exit(&self, r: &Ray, cell: [usize; 3]) -> u32 {
        let b = self.bricks.size;
        let mut exit = f32::INFINITY;
        for (a, &c) in cell.iter().enumerate() {
            let lo = (c & !(b - 1)) as f32;
            let face = if r.delta[a] > 0.0 {
                lo + b as f32
            } else if r.delta[a] < 0.0 {
                lo
            } else {
                continue;
            };
            exit = exit.min((face - r.start[a]) / r.delta[a]);
        }
        // Ceiling; `as` saturates: a huge or NaN exit gives u32::MAX or 0, both clamped by
        // the caller.
        let e = exit as u32;
        if (e as f32) < exit {
            e + 1
        } else {
            e
        }
    }

    #[inline]
    fn value(&self, i: usize, f: [f32; 3]) -> f32 {
        let d = &self.vol.data;
        let (sy, sz) = (self.vol.dims[0], self.vol.dims[0] * self.vol.dims[1]);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let c00 = lerp(d[i], d[i + 1], f[0]);
        let c10 = lerp(d[i + sy], d[i + sy + 1], f[0]);
        let c01 = lerp(d[i + sz], d[i + sz + 1], f[0]);
        let c11 = lerp(d[i + sy + sz], d[i + sy + sz + 1], f[0]);
        lerp(lerp(c00, c10, f[1]), lerp(c01, c11, f[1]), f[2])
    }

    #[inline]
    fn gradient(&self, i: usize, f: [f32; 3]) -> [i32; 3] {
        let g = self.grads;
        let (sy, sz) = (self.vol.dims[0], self.vol.dims[0] * self.vol.dims[1]);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let mut out = [0i32; 3];
        for (c, o) in out.iter_mut().enumerate() {
            let v = |j: usize| g[j][c] as f32;
            let c00 = lerp(v(i), v(i + 1), f[0]);
            let c10 = lerp(v(i + sy), v(i + sy + 1), f[0]);
            let c01 = lerp(v(i + sz), v(i + sz + 1), f[0]);
            let c11 = lerp(v(i + sy + sz), v(i + sy + sz + 1), f[0]);
            *o = round_half_away(lerp(lerp(c00, c10, f[1]), lerp(c01, c11, f[1]), f[2]));
        }
        out
    }

    /// Marches one ray front to back, handing each sample to be shaded to `sink` with its
    /// weight; returns the accumulated opacity.
    #[inline]
    pub(super) fn march<F: FnMut(f32, [i32; 3])>(
        &self,
        r: &Ray,
        st: &mut Stats,
        mut sink: F,
    ) -> f32 {
        let skip = self.opts.skip;
        let ert = self.opts.ert as f32;
        let mut acc = 0.0f32;
        let mut k = 0u32;
        st.rays += 1;
        st.samples += r.count as u64;
        while k < r.count {
            let kf = k as f32;
            let p = [
                r.start[0] + r.delta[0] * kf,
                r.start[1] + r.delta[1] * kf,
                r.start[2] + r.delta[2] * kf,
            ];
            let (cell, f) = self.locate(p);
            if skip && self.empty[self.bricks.of_cell(cell)] {
                let next = self.brick_exit(r, cell).clamp(k + 1, r.count);
                st.empty_skipped += (next - k) as u64;
                k = next;
                continue;
            }
            st.evaluated += 1;
            let i = self.vol.index(cell[0], cell[1], cell[2]);
            let o = self.tf.value_opacity(self.value(i, f));
            if skip && o == 0.0 {
                k += 1;
                continue;
            }
            let g = self.gradient(i, f);
            // The gradient-magnitude ramp only lowers the opacity, so a sample the value
            // makes transparent stays so and the test above skips nothing visible.
            let a = self.tf.correct(self.tf.with_gradient(o, g));
            if skip && a == 0.0 {
                k += 1;
                continue;
            }
            let w = (1.0 - acc) * a;
            if !skip || g != [0; 3] {
                st.shaded += 1;
                sink(w, g);
            }
            acc += w;
            if acc >= ert {
                acc = 1.0;
                if skip {
                    st.terminated += (r.count - k - 1) as u64;
                    break;
                }
            }
            k += 1;
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding() {
        for v in [
            0.5f32,
            -0.5,
            0.49999997,
            -0.49999997,
            1.5,
            -2.5,
            3.2,
            -3.7,
            2047.0,
            -2046.5,
            0.0,
        ] {
            assert_eq!(round_half_away(v), v.round() as i32, "{v}");
        }
    }
}
