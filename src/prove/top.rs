//! The top driven with chosen gradients: one representative of every sort & shift state
//! (part 2), the zero gradient (part 3), or, for a narrow gradient, every gradient itself
//! (`--direct`). Every result is compared with the model's output for the same gradient.

use super::ffi::{self, TOP_IN, TOP_OUT};
use super::{Failures, Progress};
use crate::model::{Maps, Model};
use crate::rng::SplitMix64;
use crate::vectors::inputs::{dec_grad, enc_grad};
use anyhow::Result;

/// Samples per call into the Verilated top.
const CHUNK: usize = 1 << 18;

/// What runs the samples: the Verilated top ([`ffi::Top`]), or in the tests a stand-in.
pub trait Runner {
    /// Runs `input` ([`TOP_IN`] words a sample) and writes [`TOP_OUT`] words a result into
    /// `out`: the number of results, or None if the design lost or added one.
    fn run(&mut self, input: &[u32], out: &mut [u32]) -> Option<u64>;
}

impl Runner for ffi::Top {
    fn run(&mut self, input: &[u32], out: &mut [u32]) -> Option<u64> {
        ffi::Top::run(self, input, out)
    }
}

/// The colour a sample carries with colour multiply on: drawn from its ordinal, so every run
/// of the same range drives the same colours.
fn colour(model: &Model, ordinal: u64) -> [u32; 3] {
    if !model.cfg.color {
        return [0; 3];
    }
    let mut r = SplitMix64::new(ordinal);
    [0; 3].map(|_| r.bits(model.cfg.map_bits) as u32)
}

/// Gradients queued for the top, run and checked a chunk at a time. The samples must come
/// in order of their ordinals, none left out: a gap is a failure of the part, so that a
/// part can never claim samples it did not drive ([`Failures::checked`] counts those it did).
pub struct Batch<'a, R: Runner = ffi::Top> {
    top: &'a mut R,
    model: &'a Model,
    maps: &'a Maps,
    part: &'static str,
    /// The map-buffer pass the samples belong to, for messages (empty: none).
    pass: &'static str,
    /// The ordinal the next sample must have.
    next: u64,
    input: Vec<u32>,
    ordinals: Vec<u64>,
    out: Vec<u32>,
}

impl<'a, R: Runner> Batch<'a, R> {
    /// A batch whose first sample is ordinal `first`.
    pub fn new(
        top: &'a mut R,
        model: &'a Model,
        maps: &'a Maps,
        part: &'static str,
        first: u64,
    ) -> Self {
        Batch {
            top,
            model,
            maps,
            part,
            pass: "",
            next: first,
            input: Vec::with_capacity(TOP_IN * CHUNK),
            ordinals: Vec::with_capacity(CHUNK),
            out: vec![0; TOP_OUT * CHUNK],
        }
    }

    /// Queues gradient `g` (sample `ordinal` of its part); runs the batch when full.
    pub fn push(
        &mut self,
        ordinal: u64,
        g: [i32; 3],
        failures: &mut Failures,
        progress: &Progress,
    ) -> Result<()> {
        if ordinal != self.next {
            failures.add(format!(
                "{}: samples {}..{ordinal} were never driven",
                self.part, self.next
            ));
        }
        self.next = ordinal + 1;
        let cfg = &self.model.cfg;
        self.input.extend(g.map(|v| enc_grad(cfg, v) as u32));
        self.input.extend(colour(self.model, ordinal));
        self.ordinals.push(ordinal);
        if self.ordinals.len() == CHUNK {
            self.flush(failures, progress)?;
        }
        Ok(())
    }

    /// Names the map-buffer pass in failure messages.
    pub fn pass(&mut self, label: &'static str) {
        self.pass = label;
    }

    /// The ordinal the next sample would have: one past the last pushed.
    pub fn next(&self) -> u64 {
        self.next
    }

    pub fn flush(&mut self, failures: &mut Failures, progress: &Progress) -> Result<()> {
        let n = self.ordinals.len();
        if n == 0 {
            return Ok(());
        }
        let cfg = &self.model.cfg;
        let pass = if self.pass.is_empty() {
            String::new()
        } else {
            format!(" ({})", self.pass)
        };
        let Some(ran) = self.top.run(&self.input, &mut self.out[..TOP_OUT * n]) else {
            // The results cannot be matched to their samples: none of them was checked.
            failures.add(format!(
                "{}{pass}: samples {}..={}: the top lost or added a result (valid_o did not \
                 pulse once per sample driven)",
                self.part,
                self.ordinals[0],
                self.ordinals[n - 1],
            ));
            progress(n as u64);
            self.input.clear();
            self.ordinals.clear();
            return Ok(());
        };
        failures.checked += ran;
        for k in 0..n {
            let i = &self.input[TOP_IN * k..TOP_IN * k + TOP_IN];
            let g = [i[0], i[1], i[2]].map(|v| dec_grad(cfg, v as u64));
            let rgb = [i[3], i[4], i[5]];
            let want = self.model.shade(self.maps, g, rgb);
            let o = &self.out[TOP_OUT * k..TOP_OUT * k + TOP_OUT];
            let got = (o[0] == 1, o[1], [o[2], o[3], o[4]]);
            if (want.zero, want.intensity, want.rgb) != got {
                let colour = if cfg.color {
                    format!(" colour {rgb:?}")
                } else {
                    String::new()
                };
                failures.add(format!(
                    "{}{pass}: sample {} gradient {g:?}{colour}: expected zero={} i={:#x}{}, got zero={} i={:#x}{}",
                    self.part,
                    self.ordinals[k],
                    want.zero as u8,
                    want.intensity,
                    if cfg.color { format!(" rgb={:?}", want.rgb) } else { String::new() },
                    o[0],
                    o[1],
                    if cfg.color { format!(" rgb={:?}", got.2) } else { String::new() },
                ));
            }
        }
        progress(n as u64);
        self.input.clear();
        self.ordinals.clear();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    /// A top that is the model, with the results of the samples at `wrong` (positions in a
    /// run) given a flipped intensity bit, and every run after `lose` runs losing a result.
    struct Fake<'a> {
        model: &'a Model,
        maps: &'a Maps,
        wrong: Vec<usize>,
        lose: Option<usize>,
        runs: usize,
        sizes: Vec<usize>,
    }

    impl Runner for Fake<'_> {
        fn run(&mut self, input: &[u32], out: &mut [u32]) -> Option<u64> {
            let n = input.len() / TOP_IN;
            self.runs += 1;
            self.sizes.push(n);
            if self.lose.is_some_and(|l| self.runs > l) {
                return None;
            }
            let cfg = &self.model.cfg;
            for k in 0..n {
                let i = &input[TOP_IN * k..TOP_IN * k + TOP_IN];
                let g = [i[0], i[1], i[2]].map(|v| dec_grad(cfg, v as u64));
                let o = self.model.shade(self.maps, g, [i[3], i[4], i[5]]);
                let flip = self.wrong.contains(&k) as u32;
                out[TOP_OUT * k..TOP_OUT * k + TOP_OUT].copy_from_slice(&[
                    o.zero as u32,
                    o.intensity ^ flip,
                    o.rgb[0],
                    o.rgb[1],
                    o.rgb[2],
                ]);
            }
            Some(n as u64)
        }
    }

    fn fake<'a>(model: &'a Model, maps: &'a Maps) -> Fake<'a> {
        Fake {
            model,
            maps,
            wrong: Vec::new(),
            lose: None,
            runs: 0,
            sizes: Vec::new(),
        }
    }

    /// The batch on a stand-in top: what the model gives passes, each sample counted once;
    /// a wrong result is reported with its part, pass, ordinal and gradient; a gap in the
    /// ordinals fails the part; a run that loses a result checks none of it; the colour a
    /// sample carries is its ordinal's, and none without colour.
    #[test]
    fn the_batch_checks_each_sample_once_and_reports_what_differs_where() {
        let cfg = Config {
            color: true,
            ..crate::grid::narrowest()
        };
        let model = Model::new(&cfg);
        let maps = crate::model::reflectance_map::contents(&cfg, |_| 0.7);
        let grads: Vec<[i32; 3]> = (0..40).map(|k| [k - 20, 3 * k - 50, 7]).collect();
        let quiet: &Progress = &|_| ();

        let mut top = fake(&model, &maps);
        let mut f = Failures::default();
        let mut b = Batch::new(&mut top, &model, &maps, "states", 100);
        for (k, g) in grads.iter().enumerate() {
            b.push(100 + k as u64, *g, &mut f, quiet).unwrap();
        }
        assert_eq!(b.next(), 140);
        b.flush(&mut f, quiet).unwrap();
        b.flush(&mut f, quiet).unwrap();
        assert_eq!((f.checked, f.count), (40, 0), "{:?}", f.kept);
        assert_eq!(top.sizes, [40]);

        let mut top = fake(&model, &maps);
        top.wrong = vec![0, 17];
        let mut f = Failures::default();
        let mut b = Batch::new(&mut top, &model, &maps, "states", 0);
        b.pass("buffer 1");
        for (k, g) in grads.iter().enumerate() {
            b.push(k as u64, *g, &mut f, quiet).unwrap();
        }
        b.flush(&mut f, quiet).unwrap();
        assert_eq!((f.checked, f.count), (40, 2), "{:?}", f.kept);
        let g17 = grads[17];
        assert!(
            f.kept[1].starts_with(&format!(
                "states (buffer 1): sample 17 gradient {g17:?} colour"
            )),
            "{}",
            f.kept[1]
        );

        // A gap: samples 5..9 never pushed.
        let mut top = fake(&model, &maps);
        let mut f = Failures::default();
        let mut b = Batch::new(&mut top, &model, &maps, "zero", 0);
        for k in (0..5).chain(9..12) {
            b.push(k, grads[k as usize], &mut f, quiet).unwrap();
        }
        b.flush(&mut f, quiet).unwrap();
        assert_eq!((f.checked, f.count), (8, 1));
        assert_eq!(f.kept[0], "zero: samples 5..9 were never driven");

        // A lost result: nothing of that run is checked.
        let mut top = fake(&model, &maps);
        top.lose = Some(0);
        let mut f = Failures::default();
        let mut b = Batch::new(&mut top, &model, &maps, "states", 3);
        for k in 3..10 {
            b.push(k, grads[k as usize], &mut f, quiet).unwrap();
        }
        b.flush(&mut f, quiet).unwrap();
        assert_eq!((f.checked, f.count), (0, 1));
        assert!(f.kept[0].starts_with("states: samples 3..=9: the top lost or added"));

        // A full chunk runs by itself; the rest on the flush.
        let mut top = fake(&model, &maps);
        let mut f = Failures::default();
        let mut b = Batch::new(&mut top, &model, &maps, "states", 0);
        for k in 0..CHUNK as u64 + 3 {
            b.push(k, grads[(k % 40) as usize], &mut f, quiet).unwrap();
        }
        b.flush(&mut f, quiet).unwrap();
        assert_eq!((f.checked, f.count), (CHUNK as u64 + 3, 0));
        assert_eq!(top.sizes, [CHUNK, 3]);

        // Colours: drawn from the ordinal, map_bits wide; none without colour.
        assert_eq!(colour(&model, 5), colour(&model, 5));
        assert_ne!(colour(&model, 5), colour(&model, 6));
        assert!(colour(&model, 9).iter().all(|c| *c < 1 << cfg.map_bits));
        let grey = Model::new(&crate::grid::narrowest());
        assert_eq!(colour(&grey, 5), [0; 3]);
    }
}
