//! Table look-up: split each position into a base entry and an interpolation weight, and
//! read the base entry and its three higher neighbours from the map of the max axis.
//!
//! Map address: [`crate::model::map_addr`].
//! With interpolation the base index is min(position >> interp_bits, entries - 2), so the
//! outer entry is never a base, and the weight is position - base * step, in 0..=step.
//! Without interpolation the position is the entry index and one entry is read.

use crate::config::Config;
use crate::model::map_addr::addr;
use crate::model::reflectance_map::Maps;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub struct Lookup {
    pub base_u: u32,
    pub base_v: u32,
    pub w_u: u32,
    pub w_v: u32,
    /// e[du + 2 * dv]: base, u + 1, v + 1, both + 1. Without interpolation only e[0].
    pub e: [u32; 4],
}

/// Base index and weight of one position.
#[inline]
pub fn split(cfg: &Config, pos: u32) -> (u32, u32) {
    if !cfg.interpolation {
        return (pos, 0);
    }
    let base = (pos >> cfg.interp_bits).min(cfg.entries() - 2);
    (base, pos - base * cfg.step())
}

#[inline]
#[allow(clippy::too_many_arguments)]
pub fn eval(
    cfg: &Config,
    maps: &Maps,
    axis: u32,
    s_max: u32,
    s_u: u32,
    s_v: u32,
    p_u: u32,
    p_v: u32,
) -> Lookup {
    let (base_u, w_u) = split(cfg, p_u);
    let (base_v, w_v) = split(cfg, p_v);
    let read =
        |du: u32, dv: u32| maps.get(axis, addr(cfg, s_max, s_u, base_u + du, s_v, base_v + dv));
    let e = if cfg.interpolation {
        [read(0, 0), read(1, 0), read(0, 1), read(1, 1)]
    } else {
        [read(0, 0), 0, 0, 0]
    };
    Lookup {
        base_u,
        base_v,
        w_u,
        w_v,
        e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outer_entry_is_never_a_base() {
        let c = Config::default();
        assert_eq!(split(&c, 56), (6, 8));
        assert_eq!(split(&c, 55), (6, 7));
        assert_eq!(split(&c, 48), (6, 0));
        assert_eq!(split(&c, 47), (5, 7));
        assert_eq!(split(&c, 0), (0, 0));
    }
}
