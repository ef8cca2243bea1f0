//! Part 1 of the proof: the front of the top (the modules that read the gradient) over every
//! gradient of a range, against the model, and each gradient's sort & shift state found in
//! the set part 2 drives through the top.

use super::ffi;
use super::states::StateSet;
use super::{Failures, Progress};
use crate::config::Config;
use crate::model::{sort_shift, zero_detect};
use crate::stages::{self, Vectors};
use crate::vectors::field::Dir;
use crate::vectors::inputs::dec_grad;
use anyhow::Result;
use std::ops::Range;

/// The modules of the top that read the gradient, in the order the wrapper and the report
/// list them. `structure::check` shows from the generated top that no other module does.
pub const FRONT: [&dyn Vectors; 2] = [
    &stages::zero_detect::ZeroDetect,
    &stages::sort_shift::SortShift,
];

/// Gradients per call into the Verilated front.
pub(super) const CHUNK: usize = 1 << 20;

/// The output fields' widths of a front module, in field order.
pub fn widths(unit: &dyn Vectors, cfg: &Config) -> Vec<(&'static str, u32)> {
    unit.fields(cfg)
        .into_iter()
        .filter(|f| f.dir == Dir::Out)
        .map(|f| (f.name, f.bits))
        .collect()
}

/// Output fields packed as the wrapper packs them: the first in the low bits.
#[inline]
pub fn pack(values: &[u64], widths: &[(&str, u32)]) -> u64 {
    let mut word = 0;
    let mut lsb = 0;
    for (v, (_, w)) in values.iter().zip(widths) {
        word |= v << lsb;
        lsb += w;
    }
    word
}

/// "m: expected 0x80, got 0x40; ..." for the fields that differ.
pub(super) fn differences(want: u64, got: u64, widths: &[(&str, u32)]) -> String {
    let mut lsb = 0;
    let mut out = Vec::new();
    for (name, w) in widths {
        let mask = (1u64 << w) - 1;
        let (a, b) = ((want >> lsb) & mask, (got >> lsb) & mask);
        if a != b {
            out.push(format!("{name} expected {a:#x}, got {b:#x}"));
        }
        lsb += w;
    }
    out.join(", ")
}

/// The gradient of input index `idx`: gx in the low G bits, then gy, then gz.
#[inline]
pub fn gradient(cfg: &Config, idx: u64) -> [u64; 3] {
    let g = cfg.grad_bits;
    let mask = (1u64 << g) - 1;
    [idx & mask, (idx >> g) & mask, (idx >> (2 * g)) & mask]
}

/// The message for a gradient whose state is not in the set, rebuilt from its index: out of
/// line, so that the hot loop's gradient and state never have their address taken and stay
/// in registers (taken, they went through the stack and every gradient paid a
/// store-forwarding stall).
#[cold]
#[inline(never)]
pub(super) fn missing_state(cfg: &Config, idx: u64) -> String {
    let g = gradient(cfg, idx).map(|v| dec_grad(cfg, v));
    let s = sort_shift::eval(cfg, g);
    format!(
        "front: gradient {g:?}: its sort & shift state {s:?} is not among the states driven through the top"
    )
}

/// Runs the front over the gradients `range` (input indices, [`gradient`]).
///
/// Each chunk takes one pass of the model over its gradients, which writes the harness's
/// input, the model's outputs of both modules packed as the wrapper packs them, and checks the
/// state's membership; then one call into the Verilated front; then a plain comparison of the
/// two output arrays. The model is evaluated once per gradient (the gradient decoded once),
/// and the comparison loop, which runs on every gradient, does no model work; the messages of
/// the gradients that differ are rebuilt from the model only then.
pub fn check(
    front: &mut ffi::Front,
    cfg: &Config,
    states: &StateSet,
    range: Range<u64>,
    failures: &mut Failures,
    progress: &Progress,
) -> Result<()> {
    let [zw, sw] = FRONT.map(|u| widths(u, cfg));
    let (zname, sname) = (FRONT[0].name(), FRONT[1].name());
    let room = CHUNK.next_multiple_of(front.lanes);
    let mut gin = vec![0u16; 3 * room];
    let mut want_zero = vec![0u8; room];
    let mut want_ss = vec![0u64; room];
    let mut zero = vec![0u8; room];
    let mut ss = vec![0u64; room];
    let mut lo = range.start;
    while lo < range.end {
        let n = (range.end - lo).min(CHUNK as u64) as usize;
        for k in 0..n {
            let e = gradient(cfg, lo + k as u64);
            gin[3 * k..3 * k + 3].copy_from_slice(&e.map(|v| v as u16));
            let g = e.map(|v| dec_grad(cfg, v));
            let z = zero_detect::eval(g);
            let s = sort_shift::eval(cfg, g);
            want_zero[k] = z as u8;
            want_ss[k] = pack(&stages::sort_shift::outputs(&s), &sw);
            if !z && !states.contains(&s) {
                failures.add(missing_state(cfg, lo + k as u64));
            }
        }
        // Whole groups of lanes: the last gradient repeated, its extra results unread.
        let padded = n.next_multiple_of(front.lanes);
        for k in n..padded {
            gin.copy_within(3 * (n - 1)..3 * n, 3 * k);
        }
        front.run(&gin[..3 * padded], &mut zero[..padded], &mut ss[..padded])?;
        failures.checked += n as u64;
        for k in 0..n {
            if zero[k] == want_zero[k] && ss[k] == want_ss[k] {
                continue;
            }
            let g = gradient(cfg, lo + k as u64).map(|v| dec_grad(cfg, v));
            if zero[k] != want_zero[k] {
                failures.add(format!(
                    "front: {zname} on gradient {g:?}: {}",
                    differences(want_zero[k] as u64, zero[k] as u64, &zw)
                ));
            }
            if ss[k] != want_ss[k] {
                failures.add(format!(
                    "front: {sname} on gradient {g:?}: {}",
                    differences(want_ss[k], ss[k], &sw)
                ));
            }
        }
        progress(n as u64);
        lo += n as u64;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg8() -> Config {
        Config {
            grad_bits: 8,
            red_bits: 6,
            ..Config::default()
        }
    }

    #[test]
    fn widths_are_the_output_fields_in_order() {
        let cfg = cfg8();
        assert_eq!(widths(FRONT[0], &cfg), vec![("zero", 1)]);
        assert_eq!(
            widths(FRONT[1], &cfg),
            vec![
                ("axis", 2),
                ("s_max", 1),
                ("s_u", 1),
                ("s_v", 1),
                ("m", 6),
                ("a", 6),
                ("b", 6)
            ]
        );
    }

    #[test]
    fn pack_puts_the_first_field_in_the_low_bits() {
        let w = [("p", 1), ("q", 3), ("r", 5)];
        assert_eq!(
            pack(&[1, 0b101, 0b10011], &w),
            1 | 0b101 << 1 | 0b10011 << 4
        );
        assert_eq!(pack(&[0, 0, 1], &w), 1 << 4);
        // The sort & shift fields of one state, against the fields placed by hand.
        let cfg = cfg8();
        let sw = widths(FRONT[1], &cfg);
        let s = sort_shift::eval(&cfg, [-3, 100, -57]);
        let v = stages::sort_shift::outputs(&s);
        let mut want = 0;
        for (k, shift) in [0, 2, 3, 4, 5, 11, 17].into_iter().enumerate() {
            want += v[k] << shift;
        }
        assert_eq!(pack(&v, &sw), want);
    }

    #[test]
    fn differences_name_each_differing_field_with_both_values() {
        let w = [("p", 1), ("q", 3), ("r", 5)];
        let want = pack(&[1, 0b101, 0b10011], &w);
        assert_eq!(differences(want, want, &w), "");
        let got = pack(&[1, 0b011, 0b10010], &w);
        assert_eq!(
            differences(want, got, &w),
            "q expected 0x5, got 0x3, r expected 0x13, got 0x12"
        );
        let got = pack(&[0, 0b101, 0b10011], &w);
        assert_eq!(differences(want, got, &w), "p expected 0x1, got 0x0");
        // Bits above the last field are not a field's.
        assert_eq!(differences(want, want | 1 << 9, &w), "");
    }

    #[test]
    fn an_index_is_gx_then_gy_then_gz() {
        let cfg = cfg8();
        assert_eq!(gradient(&cfg, 0x03_02_01), [1, 2, 3]);
        assert_eq!(gradient(&cfg, 0xff_80_7f), [0x7f, 0x80, 0xff]);
        assert_eq!(gradient(&cfg, (1 << 24) - 1), [0xff; 3]);
        let msg = missing_state(&cfg, 0x03_02_01);
        assert!(
            msg.starts_with("front: gradient [1, 2, 3]: its sort & shift state"),
            "{msg}"
        );
    }
}
