//! Interval bounds of the light model over a box of directions, for the exhaustive stress:
//! every gradient whose direction lies in the box has a reference intensity inside the bound,
//! so a box whose bound cannot beat the worst error found so far needs no exact evaluation.
//!
//! A box is given on one cube face: the max axis with its sign, and for each of the two other
//! components a sign and a range of tangents [t_lo, t_hi] (component / max, 0 <= t <= 1). The
//! unnormalised direction d then has one component exactly ±1 and two in ±[t_lo, t_hi].
//! Every operation below is plain interval arithmetic, rounded outwards by [`SLACK`] at the
//! end, and mirrors [`PreparedScene::shade`] term by term (two-sided flip, lights facing away
//! skipped, specular only where r.v > 0).

use crate::scene::PreparedScene;
use glam::DVec3;

/// Outward rounding of the final bound: far above the f64 rounding of either computation.
pub const SLACK: f64 = 1e-9;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub lo: f64,
    pub hi: f64,
}

impl Interval {
    pub fn new(lo: f64, hi: f64) -> Interval {
        debug_assert!(lo <= hi, "[{lo}, {hi}]");
        Interval { lo, hi }
    }
    pub fn point(x: f64) -> Interval {
        Interval { lo: x, hi: x }
    }
    fn add(self, o: Interval) -> Interval {
        Interval::new(self.lo + o.lo, self.hi + o.hi)
    }
    fn scale(self, k: f64) -> Interval {
        if k >= 0.0 {
            Interval::new(self.lo * k, self.hi * k)
        } else {
            Interval::new(self.hi * k, self.lo * k)
        }
    }
    fn mul(self, o: Interval) -> Interval {
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        Interval::new(
            p.iter().copied().fold(f64::INFINITY, f64::min),
            p.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    }
    /// self / l for a positive interval l.
    fn div_pos(self, l: Interval) -> Interval {
        debug_assert!(l.lo > 0.0);
        let lo = if self.lo >= 0.0 {
            self.lo / l.hi
        } else {
            self.lo / l.lo
        };
        let hi = if self.hi >= 0.0 {
            self.hi / l.lo
        } else {
            self.hi / l.hi
        };
        Interval::new(lo, hi)
    }
    fn neg(self) -> Interval {
        Interval::new(-self.hi, -self.lo)
    }
    fn union(self, o: Interval) -> Interval {
        Interval::new(self.lo.min(o.lo), self.hi.max(o.hi))
    }
}

/// A box of unnormalised directions: each component an interval (one of them is ±1).
#[derive(Clone, Copy, Debug)]
pub struct DirBox {
    pub c: [Interval; 3],
}

impl DirBox {
    /// The box on the face of `axis` with signs (s_max, s_u, s_v) (1 = negative) and tangent
    /// ranges `tu`, `tv` of the u and v components, in the model's (max, u, v) order.
    pub fn on_face(axis: u32, signs: (u32, u32, u32), tu: (f64, f64), tv: (f64, f64)) -> DirBox {
        let sgn = |s: u32, t: (f64, f64)| {
            if s == 1 {
                Interval::new(-t.1, -t.0)
            } else {
                Interval::new(t.0, t.1)
            }
        };
        let m = sgn(signs.0, (1.0, 1.0));
        let u = sgn(signs.1, tu);
        let v = sgn(signs.2, tv);
        let c = crate::geometry::place(axis, m, u, v);
        DirBox { c }
    }

    /// |d| over the box (every component's magnitude is bounded by its interval).
    fn length(&self) -> Interval {
        let sq = |i: &Interval| {
            let (a, b) = (i.lo.abs(), i.hi.abs());
            let lo = if i.lo <= 0.0 && i.hi >= 0.0 {
                0.0
            } else {
                a.min(b)
            };
            Interval::new(lo * lo, a.max(b) * a.max(b))
        };
        let s = sq(&self.c[0]).add(sq(&self.c[1])).add(sq(&self.c[2]));
        Interval::new(s.lo.sqrt(), s.hi.sqrt())
    }

    /// n.w for the unit normal n = d / |d| and a unit vector w.
    fn dot_unit(&self, len: Interval, w: DVec3) -> Interval {
        let d = self.c[0]
            .scale(w.x)
            .add(self.c[1].scale(w.y))
            .add(self.c[2].scale(w.z));
        d.div_pos(len)
    }

    fn negated(&self) -> DirBox {
        DirBox {
            c: self.c.map(Interval::neg),
        }
    }
}

/// One light's term for normals whose n.l and n.v lie in the given intervals.
fn light_term(s: &PreparedScene, l: DVec3, li: f64, nl: Interval, nv: Interval) -> Interval {
    if nl.hi <= 0.0 {
        return Interval::point(0.0);
    }
    let spec = |rv: f64| {
        if s.specular > 0.0 && rv > 0.0 {
            s.specular * rv.powf(s.shininess)
        } else {
            0.0
        }
    };
    let rv = nl.mul(nv).scale(2.0).add(Interval::point(-l.dot(s.view)));
    // Where n.l <= 0 the light adds nothing, so the low end is 0 unless n.l > 0 everywhere.
    let lo = if nl.lo > 0.0 {
        s.diffuse * nl.lo + spec(rv.lo)
    } else {
        0.0
    };
    let hi = s.diffuse * nl.hi + spec(rv.hi);
    Interval::new(lo * li, hi * li)
}

/// The light model over one side (n as given, not flipped).
fn shade_side(s: &PreparedScene, b: &DirBox) -> Interval {
    let len = b.length();
    let nv = b.dot_unit(len, s.view);
    let mut total = Interval::point(s.ambient);
    for &(l, li) in &s.lights {
        total = total.add(light_term(s, l, li, b.dot_unit(len, l), nv));
    }
    total
}

/// Bounds of the unclamped light model `s.shade(n)` for every unit normal n = d / |d| with d
/// in the box, widened by [`SLACK`].
pub fn shade_bounds(s: &PreparedScene, b: &DirBox) -> Interval {
    let bound = if s.two_sided {
        let nv = b.dot_unit(b.length(), s.view);
        // Normals facing away are flipped: take the side(s) the box can be on.
        let front = (nv.hi >= 0.0).then(|| shade_side(s, b));
        let back = (nv.lo < 0.0).then(|| shade_side(s, &b.negated()));
        match (front, back) {
            (Some(f), Some(k)) => f.union(k),
            (Some(f), None) => f,
            (None, Some(k)) => k,
            (None, None) => unreachable!("n.v is somewhere"),
        }
    } else {
        shade_side(s, b)
    };
    Interval::new(bound.lo - SLACK, bound.hi + SLACK)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    /// Random points of random small boxes stay inside the bound, for every scene shape.
    #[test]
    fn bounds_contain_the_light_model() {
        let mut scenes = vec![Scene::standard(), Scene::alternate()];
        let mut two = Scene::standard();
        two.view.two_sided = true;
        scenes.push(two);
        let mut rng = crate::rng::SplitMix64::new(5);
        let mut unit = || rng.below(1 << 30) as f64 / (1u64 << 30) as f64;
        for scene in &scenes {
            let p = scene.prepared();
            for k in 0..3000 {
                let axis = k % 3;
                let signs = ((k / 3) % 2, (k / 6) % 2, (k / 12) % 2);
                let w = [0.001, 0.02, 0.2][(k / 24) as usize % 3];
                let (u0, v0) = (unit() * (1.0 - w), unit() * (1.0 - w));
                let b = DirBox::on_face(axis, signs, (u0, u0 + w), (v0, v0 + w));
                let bound = shade_bounds(&p, &b);
                for _ in 0..20 {
                    let (tu, tv) = (u0 + unit() * w, v0 + unit() * w);
                    let sg = |s: u32, t: f64| if s == 1 { -t } else { t };
                    let (m, u, v) = (sg(signs.0, 1.0), sg(signs.1, tu), sg(signs.2, tv));
                    let d = DVec3::from_array(crate::geometry::place(axis, m, u, v));
                    let i = p.shade(d.normalize());
                    assert!(bound.lo <= i && i <= bound.hi, "{i} outside {bound:?}");
                }
                // Tiny boxes get tight bounds.
                if w < 0.01 {
                    assert!(bound.hi - bound.lo < 0.05, "{bound:?}");
                }
            }
        }
    }

    #[test]
    fn a_point_box_is_tight() {
        let p = Scene::standard().prepared();
        let b = DirBox::on_face(2, (0, 0, 0), (0.5, 0.5), (0.5, 0.5));
        let i = p.shade(DVec3::new(0.5, 0.5, 1.0).normalize());
        let bound = shade_bounds(&p, &b);
        assert!(
            bound.lo <= i && i <= bound.hi && bound.hi - bound.lo < 1e-8,
            "{bound:?}"
        );
    }
}
