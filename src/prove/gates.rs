//! The front's gate-level engine (`--front-engine gates`, the default): the front modules
//! (the design's `zero_detect.v` and `sort_shift.v`, unchanged, in the wrapper of
//! [`super::build::front_wrapper`] with one copy) read by Yosys, every flip-flop made a wire
//! from D to Q, mapped to an and-inverter graph ([`crate::toolchain::yosys::aig`]) and
//! evaluated here on every gradient of the range, 512 at a time (one bit of a machine word per
//! gradient), against the model.
//!
//! Why: the front sees all 2^(3G) gradients, 2^36 for the default design. Verilator spends
//! about 40 ns a gradient in its modules' logic and its `eval` calls; the graph of the default
//! front has about 1,500 AND gates, and with a row's gy and gz fixed (4,096 gradients,
//! one compile of the graph for their constants) fewer, so a gradient costs a few ns of gates
//! and the model check dominates.
//!
//! Why the wires are the clocked front's behaviour: part `structure` shows from the same
//! Yosys reading that every register the gradient reaches moves on one enable and that every
//! path from a sample input to the output register crosses the same number of registers. So
//! every path from the gradient to a front output that reaches the output register crosses
//! the same number of registers, and in a stream each register holds the value computed from
//! the sample that entered as many enabled clocks before: the output for a sample is the
//! combinational function with the registers as wires (docs/VERIFICATION.md, "The front by
//! gates").

use super::front::{differences, gradient, missing_state, pack, widths, FRONT};
use super::states::StateSet;
use super::{build, Failures, Progress};
use crate::config::Config;
use crate::design_dir::DesignDir;
use crate::model::{sort_shift, zero_detect};
use crate::prove::aig::{self, Aig};
use crate::stages;
use crate::toolchain::yosys;
use crate::vectors::inputs::dec_grad;
use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use std::ops::Range;
use std::path::Path;

/// Machine words per evaluation: 8 x 64 = 512 gradients of a row at once.
const WORDS: usize = 8;
const LANES: u64 = 64 * WORDS as u64;
/// Rows (gradients sharing gy and gz) per parallel batch between progress reports.
const BATCH_ROWS: u64 = 64;

/// What a graph input is.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    /// Bit `b` of component `c` (0 gx, 1 gy, 2 gz).
    Grad(usize, u32),
    /// A control input held at this value for a stream of samples.
    Held(bool),
}

/// The front as a graph, its inputs and outputs placed.
pub struct GateFront {
    aig: Aig,
    roles: Vec<Role>,
    /// For each graph output: the front module (index in [`FRONT`]) and the bit of its packed
    /// outputs, or None for an output that is not sample data (the valid bits).
    places: Vec<Option<(usize, u32)>>,
    /// AND gates of the whole graph.
    pub gates: usize,
}

/// Which wrapper input is which: the gradient ports of copy 0, the reset released, `valid_i`
/// high (a stream of samples), the clock unused once the registers are wires.
fn role(name: &str, bit: u32) -> Option<Role> {
    Some(match name {
        "gx0_i" => Role::Grad(0, bit),
        "gy0_i" => Role::Grad(1, bit),
        "gz0_i" => Role::Grad(2, bit),
        "rst_ni" | "valid_i" => Role::Held(true),
        "clk_i" => Role::Held(false),
        _ => return None,
    })
}

/// Builds the graph of `d`'s front in `build/gates` (the wrapper, the techmap file, Yosys's
/// log and the graph), then reads it ([`load`]).
pub fn build(d: &DesignDir, build: &Path) -> Result<GateFront> {
    let dir = build.join("gates");
    crate::disk::create_dir_all(&dir)?;
    for u in FRONT {
        no_undefined_literal(&d.path().join(u.file(&d.config)))?;
    }
    let wrapper = dir.join(format!("{}.v", build::FRONT_MODULE));
    crate::disk::write(&wrapper, build::front_wrapper(&d.config, 1, false))?;
    let transparent = dir.join(crate::prove::mult::TRANSPARENT_FILE);
    crate::disk::write(&transparent, crate::prove::mult::TRANSPARENT)?;
    let mut files: Vec<String> = FRONT
        .iter()
        .map(|u| crate::toolchain::quoted(&d.path().join(u.file(&d.config)).to_string_lossy()))
        .collect();
    files.push(crate::toolchain::quoted(&wrapper.to_string_lossy()));
    yosys::aig(
        build::FRONT_MODULE,
        &files,
        crate::prove::mult::TRANSPARENT_FILE,
        &dir,
    )?;
    load(d, build)
}

/// The graph of `d`'s front that [`build`] wrote in `build/gates` (by this run, or by a
/// `--build-only` run whose build a shard reuses), its inputs and outputs placed.
pub fn load(d: &DesignDir, build: &Path) -> Result<GateFront> {
    let dir = build.join("gates");
    let (aag, map) = (dir.join(yosys::AIG_FILES.0), dir.join(yosys::AIG_FILES.1));
    let read = |p: &Path| std::fs::read_to_string(p).with_context(|| format!("{}", p.display()));
    let graph = Aig::parse(&read(&aag)?, &read(&map)?)
        .with_context(|| format!("the front's graph {}", aag.display()))?;
    place(graph, &d.config)
}

/// The front's files must not write an undefined value (`'bx`, `'hz`, ...): the gates take
/// every `x` as "any value" (see [`yosys::aig`]), which is right only for the defaults
/// Yosys itself writes where no path selects them. Comments are skipped.
fn no_undefined_literal(file: &Path) -> Result<()> {
    let text =
        std::fs::read_to_string(file).with_context(|| format!("cannot read {}", file.display()))?;
    for (n, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(q) = rest.find('\'') {
            let lit: String = rest[q + 1..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == '?')
                .collect();
            let lower = lit.to_ascii_lowercase();
            let base = lower.trim_start_matches('s');
            if base.starts_with(['b', 'o', 'd', 'h']) && base[1..].contains(['x', 'z', '?']) {
                bail!(
                    "{}:{}: the undefined literal '{lit} (the front's gates cannot keep an x or z)",
                    file.display(),
                    n + 1
                );
            }
            rest = &rest[q + 1..];
        }
    }
    Ok(())
}

/// Places every input and output of the front's graph; anything the wrapper does not have is
/// an error, as is an output bit missing.
fn place(aig: Aig, cfg: &Config) -> Result<GateFront> {
    let roles = aig
        .inputs
        .iter()
        .map(|(n, b)| {
            role(n, *b).with_context(|| format!("the front's graph has the input {n}[{b}]"))
        })
        .collect::<Result<Vec<_>>>()?;
    let widths: Vec<u32> = FRONT
        .iter()
        .map(|u| widths(*u, cfg).iter().map(|(_, w)| w).sum())
        .collect();
    let mut seen: Vec<Vec<bool>> = widths.iter().map(|&w| vec![false; w as usize]).collect();
    let mut places = Vec::with_capacity(aig.outputs.len());
    for (name, bit) in &aig.outputs {
        let unit = FRONT
            .iter()
            .position(|u| *name == format!("{}0_o", u.name()));
        if let Some(u) = unit {
            let slot = seen[u]
                .get_mut(*bit as usize)
                .with_context(|| format!("the front's output {name}[{bit}] is past its width"))?;
            *slot = true;
            places.push(Some((u, *bit)));
        } else if FRONT
            .iter()
            .any(|u| *name == format!("{}_valid_o", u.name()))
        {
            places.push(None);
        } else if name.is_empty() {
            bail!("the front's graph has an output its map does not name (Yosys leaves out a constant output, so the front cannot be placed)");
        } else {
            bail!("the front's graph has the output {name}[{bit}]");
        }
    }
    for (u, s) in seen.iter().enumerate() {
        if let Some(b) = s.iter().position(|x| !x) {
            bail!("the front's graph lacks {}0_o[{b}]", FRONT[u].name());
        }
    }
    let gates = aig.gates();
    Ok(GateFront {
        aig,
        roles,
        places,
        gates,
    })
}

/// Transposes a 64 x 64 bit matrix in place: bit `j` of word `i` goes to bit `i` of word
/// `j` (Hacker's Delight 7-3, least significant bit first).
fn transpose64(a: &mut [u64; 64]) {
    let mut j = 32;
    let mut m: u64 = 0x0000_0000_FFFF_FFFF;
    while j != 0 {
        let mut k = 0;
        while k < 64 {
            let t = ((a[k] >> j) ^ a[k + j]) & m;
            a[k] ^= t << j;
            a[k + j] ^= t;
            k = (k + j + 1) & !j;
        }
        j >>= 1;
        m ^= m << j;
    }
}

/// The words of gx bit `b` for evaluation `pass` of a row: gradient `pass * 512 + w * 64 +
/// lane` of the row has gx equal to its number.
fn gx_pattern(b: u32, pass: u64) -> [u64; WORDS] {
    aig::number_bit(b, pass * LANES)
}

/// Checks the gradients `range` of one row (`row` = the gradient index >> G: gy and gz
/// fixed) and returns its failures.
fn check_row(
    gf: &GateFront,
    cfg: &Config,
    states: &StateSet,
    row: u64,
    range: Range<u64>,
    scratch: &mut Vec<[u64; WORDS]>,
) -> Failures {
    let g = cfg.grad_bits;
    let mut fails = Failures::default();
    let [zw, sw] = FRONT.map(|u| widths(u, cfg));
    // The row's constants: gy and gz, the held controls. gx stays free, bit by bit.
    let (mut fixed, mut free, mut free_bits) = (Vec::new(), Vec::new(), Vec::new());
    for (i, r) in gf.roles.iter().enumerate() {
        fixed.push(match *r {
            Role::Held(v) => Some(v),
            Role::Grad(0, b) => {
                free.push(i);
                free_bits.push(b);
                None
            }
            Role::Grad(c, b) => Some((row >> ((c - 1) as u32 * g + b)) & 1 == 1),
        });
    }
    let p = aig::compile(&gf.aig, &fixed, &free);
    let mut out = vec![[0u64; WORDS]; gf.places.len()];
    let first = row << g;
    let (lo, hi) = (range.start - first, range.end - first);
    for pass in lo / LANES..hi.div_ceil(LANES) {
        p.eval(scratch, |k| gx_pattern(free_bits[k], pass), &mut out);
        for w in 0..WORDS {
            // Each module's packed outputs for the word's 64 gradients.
            let mut got = [[0u64; 64]; 2];
            for (words, place) in out.iter().zip(&gf.places) {
                if let Some((u, bit)) = *place {
                    got[u][bit as usize] = words[w];
                }
            }
            // A one-bit module's word is already its 64 results; wider ones are transposed to
            // one packed word per gradient.
            let wide = [zw.len() > 1 || zw[0].1 > 1, true];
            for (m, &w) in got.iter_mut().zip(&wide) {
                if w {
                    transpose64(m);
                }
            }
            let base = pass * LANES + 64 * w as u64;
            for lane in 0..64 {
                let gx = base + lane;
                if gx < lo || gx >= hi {
                    continue;
                }
                let idx = first + gx;
                fails.checked += 1;
                let gr = gradient(cfg, idx).map(|v| dec_grad(cfg, v));
                let z = zero_detect::eval(gr);
                let s = sort_shift::eval(cfg, gr);
                let want_z = z as u64;
                let want_s = pack(&stages::sort_shift::outputs(&s), &sw);
                let gz = if wide[0] {
                    got[0][lane as usize]
                } else {
                    (got[0][0] >> lane) & 1
                };
                let gs = got[1][lane as usize];
                if !z && !states.contains(&s) {
                    fails.add(missing_state(cfg, idx));
                }
                if gz != want_z {
                    fails.add(format!(
                        "front: {} on gradient {gr:?}: {}",
                        FRONT[0].name(),
                        differences(want_z, gz, &zw)
                    ));
                }
                if gs != want_s {
                    fails.add(format!(
                        "front: {} on gradient {gr:?}: {}",
                        FRONT[1].name(),
                        differences(want_s, gs, &sw)
                    ));
                }
            }
        }
    }
    fails
}

/// Runs the front's graph over the gradients `range` (input indices,
/// [`super::front::gradient`]), on all cores, row by row.
pub fn check(
    gf: &GateFront,
    cfg: &Config,
    states: &StateSet,
    range: Range<u64>,
    failures: &mut Failures,
    progress: &Progress,
) -> Result<()> {
    if range.is_empty() {
        return Ok(());
    }
    let g = cfg.grad_bits;
    let (first_row, end_row) = (range.start >> g, (range.end - 1) >> g);
    let mut row = first_row;
    while row <= end_row {
        let last = (row + BATCH_ROWS - 1).min(end_row);
        let results: Vec<(u64, Failures)> = (row..=last)
            .into_par_iter()
            .map_init(Vec::new, |scratch, r| {
                let lo = range.start.max(r << g);
                let hi = range.end.min((r + 1) << g);
                (hi - lo, check_row(gf, cfg, states, r, lo..hi, scratch))
            })
            .collect();
        for (n, f) in results {
            failures.checked += f.checked;
            failures.count += f.count - f.kept.len() as u64;
            for m in f.kept {
                failures.add(m);
            }
            progress(n);
        }
        row = last + 1;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transpose64_moves_bit_j_of_word_i_to_bit_i_of_word_j() {
        let mut a = [0u64; 64];
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        for w in a.iter_mut() {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            *w = x;
        }
        let orig = a;
        transpose64(&mut a);
        for (i, row) in orig.iter().enumerate() {
            for (j, col) in a.iter().enumerate() {
                assert_eq!((col >> i) & 1, (row >> j) & 1, "word {i} bit {j}");
            }
        }
    }

    #[test]
    fn gx_patterns_number_the_gradients_of_a_pass() {
        for pass in [0u64, 3, 7] {
            for w in 0..WORDS {
                for lane in 0..64u64 {
                    let n = pass * LANES + 64 * w as u64 + lane;
                    let got: u64 = (0..12)
                        .map(|b| ((gx_pattern(b, pass)[w] >> lane) & 1) << b)
                        .sum();
                    assert_eq!(got, n);
                }
            }
        }
    }

    #[test]
    fn undefined_literals_are_refused_outside_comments() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("m.v");
        std::fs::write(
            &f,
            "assign a = 4'hF; // 4'bx in a comment\nassign b = 8'd3;\n",
        )
        .unwrap();
        assert!(no_undefined_literal(&f).is_ok());
        std::fs::write(&f, "assign a = 4'hF;\nassign b = c ? 2'b1x : 2'b00;\n").unwrap();
        let e = no_undefined_literal(&f).unwrap_err().to_string();
        assert!(e.contains("m.v:2") && e.contains("'b1x"), "{e}");
        std::fs::write(&f, "assign b = 1'bz;\n").unwrap();
        assert!(no_undefined_literal(&f).is_err());
        // Digits grouped by `_`, and `?` (Verilog's z), belong to the literal.
        for bad in ["assign b = 4'b1_x0;\n", "assign b = 4'b10?1;\n"] {
            std::fs::write(&f, bad).unwrap();
            assert!(no_undefined_literal(&f).is_err(), "{bad}");
        }
        // A literal ends where its digits do: an x or z in a name after it is not its own.
        std::fs::write(&f, "assign a = 4'hF + max_z;\nassign b = 2'b1_0 ^ x;\n").unwrap();
        assert!(no_undefined_literal(&f).is_ok());
    }

    /// An and-inverter graph built by hand: literals as AIGER writes them (2 x variable, +1
    /// complemented), gates structurally hashed.
    struct Builder {
        ands: Vec<(u32, u32, u32)>,
        next: u32,
        seen: std::collections::HashMap<(u32, u32), u32>,
    }

    impl Builder {
        fn new(inputs: u32) -> Builder {
            Builder {
                ands: Vec::new(),
                next: inputs + 1,
                seen: Default::default(),
            }
        }

        fn and(&mut self, a: u32, b: u32) -> u32 {
            let (a, b) = (a.max(b), a.min(b));
            if b == 0 || a == b ^ 1 {
                return 0;
            }
            if b == 1 || a == b {
                return a;
            }
            if let Some(&l) = self.seen.get(&(a, b)) {
                return l;
            }
            let l = 2 * self.next;
            self.next += 1;
            self.ands.push((l, a, b));
            self.seen.insert((a, b), l);
            l
        }

        fn or(&mut self, a: u32, b: u32) -> u32 {
            self.and(a ^ 1, b ^ 1) ^ 1
        }

        /// The function of `vars` (least significant first) whose value at input `k` is
        /// `table[k]`: a tree of multiplexers.
        fn table(&mut self, vars: &[u32], table: &[bool]) -> u32 {
            match vars.split_last() {
                None => table[0] as u32,
                Some((&top, rest)) => {
                    let half = table.len() / 2;
                    let lo = self.table(rest, &table[..half]);
                    let hi = self.table(rest, &table[half..]);
                    let t = self.and(2 * top, hi);
                    let e = self.and(2 * top + 1, lo);
                    self.or(t, e)
                }
            }
        }
    }

    /// The front of `cfg` (G = 8) as a graph that is the model on the gradient rows `rows`
    /// (gy and gz fixed, every gx) and 0 elsewhere, with the bits `flip` ((gradient index,
    /// module, bit)) inverted; placed as [`build`] places Yosys's graph.
    fn model_front(cfg: &Config, rows: &[u64], flip: &[(u64, usize, u32)]) -> GateFront {
        let (aag, map) = model_graph(cfg, rows, flip);
        place(Aig::parse(&aag, &map).unwrap(), cfg).unwrap()
    }

    /// [`model_front`]'s graph as AIGER text and its map, before placing.
    fn model_graph(cfg: &Config, rows: &[u64], flip: &[(u64, usize, u32)]) -> (String, String) {
        let g = cfg.grad_bits;
        let [zw, sw] = FRONT.map(|u| widths(u, cfg));
        let width = |w: &[(&str, u32)]| w.iter().map(|(_, b)| b).sum::<u32>();
        let (zb, sb) = (width(&zw), width(&sw));
        // Inputs: gx, gy, gz bits (variables 1..=3G), then rst_ni, valid_i, clk_i.
        let mut map = String::new();
        let names = ["gx0_i", "gy0_i", "gz0_i"];
        for (c, n) in names.iter().enumerate() {
            for b in 0..g {
                map += &format!("input {} {b} {n}\n", c as u32 * g + b);
            }
        }
        for (k, n) in ["rst_ni", "valid_i", "clk_i"].iter().enumerate() {
            map += &format!("input {} 0 {n}\n", 3 * g + k as u32);
        }
        let inputs = 3 * g + 3;
        let mut b = Builder::new(inputs);
        let gx: Vec<u32> = (1..=g).collect();
        // Per output bit: the OR over the rows of (row selected) AND (the row's table).
        let mut outs = vec![0u32; (zb + sb) as usize];
        for &row in rows {
            let mut sel = 1;
            for k in 0..2 * g {
                let v = g + 1 + k;
                let lit = if (row >> k) & 1 == 1 {
                    2 * v
                } else {
                    2 * v + 1
                };
                sel = b.and(sel, lit);
            }
            let words: Vec<(u64, u64)> = (0..1u64 << g)
                .map(|x| {
                    let idx = (row << g) | x;
                    let gr = gradient(cfg, idx).map(|v| dec_grad(cfg, v));
                    let z = zero_detect::eval(gr) as u64;
                    let s = pack(
                        &stages::sort_shift::outputs(&sort_shift::eval(cfg, gr)),
                        &sw,
                    );
                    let mut w = (z, s);
                    for &(at, m, bit) in flip {
                        if at == idx {
                            if m == 0 {
                                w.0 ^= 1 << bit;
                            } else {
                                w.1 ^= 1 << bit;
                            }
                        }
                    }
                    w
                })
                .collect();
            for (o, out) in outs.iter_mut().enumerate() {
                let o = o as u32;
                let table: Vec<bool> = words
                    .iter()
                    .map(|&(z, s)| {
                        if o < zb {
                            (z >> o) & 1 == 1
                        } else {
                            (s >> (o - zb)) & 1 == 1
                        }
                    })
                    .collect();
                let f = b.table(&gx, &table);
                let t = b.and(sel, f);
                *out = b.or(*out, t);
            }
        }
        let mut aag = format!(
            "aag {} {inputs} 0 {} {}\n",
            b.next - 1,
            outs.len() + 2,
            b.ands.len()
        );
        for v in 1..=inputs {
            aag += &format!("{}\n", 2 * v);
        }
        for (k, o) in outs.iter().enumerate() {
            aag += &format!("{o}\n");
            let (name, bit) = if (k as u32) < zb {
                ("zero_detect0_o", k as u32)
            } else {
                ("sort_shift0_o", k as u32 - zb)
            };
            map += &format!("output {k} {bit} {name}\n");
        }
        // The valid bits: the held valid_i.
        for (k, name) in ["zero_detect_valid_o", "sort_shift_valid_o"]
            .iter()
            .enumerate()
        {
            aag += &format!("{}\n", 2 * (3 * g + 2));
            map += &format!("output {} 0 {name}\n", outs.len() + k);
        }
        for (l, x, y) in &b.ands {
            aag += &format!("{l} {x} {y}\n");
        }
        (aag, map)
    }

    /// Placing refuses a graph that is not the wrapper's: an input or output it does not
    /// have, an output bit past a module's width, an output the map leaves unnamed, a module
    /// output bit missing.
    #[test]
    fn a_graph_that_is_not_the_wrappers_is_refused_naming_what_is_wrong() {
        let cfg = &crate::grid::narrowest();
        let (aag, map) = model_graph(cfg, &[0], &[]);
        let placed = |map: &str| place(Aig::parse(&aag, map).unwrap(), cfg).map(|_| ());
        assert!(placed(&map).is_ok());
        let err = |map: String| format!("{:#}", placed(&map).unwrap_err());
        let e = err(map.replace(" rst_ni\n", " en_i\n"));
        assert!(e.contains("the front's graph has the input en_i[0]"), "{e}");
        let e = err(map.replace(" sort_shift_valid_o\n", " other_o\n"));
        assert!(
            e.contains("the front's graph has the output other_o[0]"),
            "{e}"
        );
        let e = err(map.replace(" 0 zero_detect0_o\n", " 7 zero_detect0_o\n"));
        assert!(e.contains("zero_detect0_o[7] is past its width"), "{e}");
        let unnamed: String = map
            .lines()
            .filter(|l| !l.ends_with(" sort_shift_valid_o"))
            .map(|l| format!("{l}\n"))
            .collect();
        let e = err(unnamed);
        assert!(e.contains("an output its map does not name"), "{e}");
        // sort_shift0_o bit 0 renamed as a valid output: the module lacks that bit.
        let lacking: String = map
            .lines()
            .map(|l| {
                if l.ends_with(" 0 sort_shift0_o") {
                    l.replace(" 0 sort_shift0_o", " 0 zero_detect_valid_o")
                } else {
                    l.to_string()
                }
            })
            .map(|l| format!("{l}\n"))
            .collect();
        let e = err(lacking);
        assert!(
            e.contains("the front's graph lacks sort_shift0_o[0]"),
            "{e}"
        );
    }

    /// The gates engine on a front that is the model, built here gate by gate on a few rows:
    /// every gradient of a row checked, each once (also of part of a row and across rows), no
    /// failure; every flipped output bit found at its gradient and module, whichever word and
    /// lane it is in; a gradient whose state is not in the set reported; a row the graph
    /// gets wrong (all 0) failed. Kills what the integration tests (Yosys's graph of a real
    /// front) would, without Yosys.
    #[test]
    fn a_front_that_is_the_model_passes_and_every_flipped_bit_is_found_where_it_is() {
        let cfg = &crate::grid::narrowest();
        let g = cfg.grad_bits;
        assert_eq!(g, 8);
        let states = crate::prove::states::enumerate(cfg, |_, _| Ok(())).unwrap();
        // Row 0 holds the zero gradient; 0x80 has gy = -128; 0xFF01 and 0xFF02 are neighbours.
        let rows = [0u64, 0x80, 0xFF01, 0xFF02];
        let gf = model_front(cfg, &rows, &[]);
        let mut scratch = Vec::new();
        for &r in &rows {
            let f = check_row(&gf, cfg, &states, r, (r << g)..((r + 1) << g), &mut scratch);
            assert_eq!(
                (f.checked, f.count),
                (1 << g, 0),
                "row {r:#x}: {:?}",
                f.kept
            );
        }
        let first = 0x80 << g;
        let f = check_row(
            &gf,
            cfg,
            &states,
            0x80,
            first + 10..first + 200,
            &mut scratch,
        );
        assert_eq!((f.checked, f.count), (190, 0));
        // Across two rows, in part.
        let mut all = Failures::default();
        let (a, z) = ((0xFF01 << g) + 100, (0xFF03 << g) - 7);
        let told = std::sync::atomic::AtomicU64::new(0);
        let progress = |n: u64| {
            told.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
        };
        check(&gf, cfg, &states, a..z, &mut all, &progress).unwrap();
        assert_eq!((all.checked, all.count), (z - a, 0), "{:?}", all.kept);
        // The progress told is the gradients checked.
        assert_eq!(told.into_inner(), z - a);
        // A range that ends one short of a row's end.
        let mut short = Failures::default();
        let (a, z) = (0xFF01 << g, (0xFF02 << g) - 1);
        check(&gf, cfg, &states, a..z, &mut short, &|_| ()).unwrap();
        assert_eq!((short.checked, short.count), (z - a, 0), "{:?}", short.kept);
        // A row the graph does not compute: its gradients fail, more than are kept: every one
        // counted, the first 20 kept.
        let mut wrong = Failures::default();
        let bad = (3 << g)..(3 << g) + 100;
        check(&gf, cfg, &states, bad, &mut wrong, &|_| ()).unwrap();
        assert_eq!((wrong.checked, wrong.count), (100, 100));
        assert_eq!(wrong.kept.len(), 20);
        assert!(check(&gf, cfg, &states, 7..7, &mut wrong, &|_| ()).is_ok());
        assert_eq!(wrong.checked, 100);

        // Flipped bits in several words and lanes, of both modules.
        let sb: u32 = widths(FRONT[1], cfg).iter().map(|(_, w)| w).sum();
        let flips = [
            (0u64, 0usize, 0u32),
            (0x80 << g | 63, 1, 0),
            (0x80 << g | 64, 1, sb - 1),
            (0x80 << g | 200, 1, 3),
            (0x80 << g | 255, 0, 0),
        ];
        let bad = model_front(cfg, &rows, &flips);
        for &(idx, m, _) in &flips {
            let r = idx >> g;
            let f = check_row(&bad, cfg, &states, r, idx..idx + 1, &mut scratch);
            let gr = gradient(cfg, idx).map(|v| dec_grad(cfg, v));
            assert_eq!((f.checked, f.count), (1, 1), "{idx:#x}");
            let want = format!("front: {} on gradient {gr:?}: ", FRONT[m].name());
            assert!(f.kept[0].starts_with(&want), "{} / {want}", f.kept[0]);
        }
        let f = check_row(&bad, cfg, &states, 0x80, first..first + 256, &mut scratch);
        assert_eq!((f.checked, f.count), (256, 4), "{:?}", f.kept);

        // No state in the set: every non-zero gradient is reported, the zero one is not.
        let none = crate::prove::states::StateSet::new(cfg).unwrap();
        let f = check_row(&gf, cfg, &none, 0, 0..256, &mut scratch);
        assert_eq!((f.checked, f.count), (256, 255));
        assert!(
            f.kept[0].contains("is not among the states"),
            "{}",
            f.kept[0]
        );
    }

    /// At G = 10 a row is two evaluations of 512 gradients: the second pass's gradients are
    /// numbered from 512 (a flipped bit there is found at its own gradient).
    #[test]
    fn a_row_of_more_than_one_pass_numbers_its_gradients_by_pass() {
        let cfg = &Config {
            grad_bits: 10,
            ..crate::grid::narrowest()
        };
        let states = crate::prove::states::enumerate(cfg, |_, _| Ok(())).unwrap();
        let row = 0x1_23u64;
        let idx = (row << 10) | 700;
        let gf = model_front(cfg, &[row], &[(idx, 1, 2)]);
        let mut scratch = Vec::new();
        let f = check_row(
            &gf,
            cfg,
            &states,
            row,
            (row << 10)..((row + 1) << 10),
            &mut scratch,
        );
        assert_eq!((f.checked, f.count), (1024, 1), "{:?}", f.kept);
        let gr = gradient(cfg, idx).map(|v| dec_grad(cfg, v));
        assert!(f.kept[0].contains(&format!("{gr:?}")), "{}", f.kept[0]);
    }

    #[test]
    fn the_wrapper_inputs_have_their_roles_and_nothing_else_is_taken() {
        assert_eq!(role("gx0_i", 3), Some(Role::Grad(0, 3)));
        assert_eq!(role("gy0_i", 0), Some(Role::Grad(1, 0)));
        assert_eq!(role("gz0_i", 7), Some(Role::Grad(2, 7)));
        assert_eq!(role("rst_ni", 0), Some(Role::Held(true)));
        assert_eq!(role("valid_i", 0), Some(Role::Held(true)));
        assert_eq!(role("clk_i", 0), Some(Role::Held(false)));
        assert_eq!(role("gx1_i", 0), None);
        assert_eq!(role("en_i", 0), None);
    }
}
