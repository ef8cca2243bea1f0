//! Where each pair (M, c) of an exhaustive run lands: its position ([`PairPositions`]),
//! computed once per pair, and for each (M, position) the run of c that has it ([`Runs`]).
//! Separate because both the input pass and the error search read them.

use anyhow::{ensure, Result};

/// Positions of every pair (M, c), 1 <= M <= 2^(G-1), 0 <= c <= M.
pub(super) struct PairPositions {
    pub(super) stride: usize,
    pub(super) p: Vec<u16>,
}

impl PairPositions {
    pub(super) fn row(&self, max: u32) -> &[u16] {
        let s = max as usize * self.stride;
        &self.p[s..s + max as usize + 1]
    }
}

/// For every (M, position): the first and last c with that position (positions are
/// monotonic in c for a fixed M, so each is one run), or lo > hi when there is none.
pub(super) struct Runs {
    ps: usize,
    run: Vec<(u16, u16)>,
}

impl Runs {
    pub(super) fn new(cfg: &crate::config::Config, pos: &PairPositions) -> Result<Runs> {
        let full = 1u32 << (cfg.grad_bits - 1);
        let ps = cfg.pos_max() as usize + 1;
        let mut run = vec![(1u16, 0u16); (full as usize + 1) * ps];
        for max in 1..=full {
            let row = pos.row(max);
            ensure!(
                row.windows(2).all(|w| w[0] <= w[1]),
                "positions are not monotonic for max {max}"
            );
            for (c, &p) in row.iter().enumerate() {
                let r = &mut run[max as usize * ps + p as usize];
                if r.0 > r.1 {
                    *r = (c as u16, c as u16);
                } else {
                    r.1 = c as u16;
                }
            }
        }
        Ok(Runs { ps, run })
    }

    pub(super) fn get(&self, max: u32, p: u32) -> (u32, u32) {
        let (lo, hi) = self.run[max as usize * self.ps + p as usize];
        (lo as u32, hi as u32)
    }
}
