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
pub struct Batch<'a> {
    top: &'a mut ffi::Top,
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

impl<'a> Batch<'a> {
    /// A batch whose first sample is ordinal `first`.
    pub fn new(
        top: &'a mut ffi::Top,
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
