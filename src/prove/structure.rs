//! Part 1 of the proof: what the factoring assumes about the RTL, read from the design's own
//! netlist (Yosys `proc`, then flattened with the memories kept as `$mem_v2` cells), not
//! assumed:
//!
//! - **the gradient reaches only the front**: in the top, every connection of a gradient
//!   input bit is an input of a module of [`super::front::FRONT`], and no output is one;
//! - **one sample at a time**: in the flattened design, no loop passes through a signal the
//!   sample inputs (gradient, colour, sideband) reach; no control input (a register's clock,
//!   enable, reset or load; a memory's read enable, clock or reset; any write-port input)
//!   depends on them; the control outputs (valid, ready) do not depend on them; every
//!   register and memory read the samples reach moves on the same enable (or always); and every
//!   path from a sample input to the output register's inputs (the top's `out_*` wires)
//!   passes through exactly latency − 1 registers (a memory's synchronous read counts one).
//!
//! Together: each output register's input for a sample is a function of that sample's inputs
//! alone, read through the front's outputs, whatever came before or after it and whatever
//! the control did; which result leaves when is the handshake's business, proven by `make
//! formal` and exercised by every testbench.

use super::front::FRONT;
use super::report::Part;
use super::Failures;
use crate::design_dir::DesignDir;
use crate::stages::TOP;
use crate::toolchain::yosys;
use crate::vectors::field::Dir;
use anyhow::{bail, Context, Result};
use serde_json::Value;
use std::collections::HashMap;
use std::path::Path;

/// A netlist bit: a signal number, or None for a constant.
type Bit = Option<u64>;

fn bits(v: &Value) -> Vec<Bit> {
    v.as_array()
        .map(|a| a.iter().map(Value::as_u64).collect())
        .unwrap_or_default()
}

struct Cell {
    name: String,
    kind: String,
    inputs: Vec<(String, Vec<Bit>)>,
    outputs: Vec<(String, Vec<Bit>)>,
    params: HashMap<String, String>,
    /// The input pins with an undefined bit (`x` or `z`).
    undefined: Vec<String>,
    /// Where the RTL writes it (Yosys's `src` attribute, `normalise.v:73.3-75.6`).
    src: String,
}

struct Module {
    ports: HashMap<String, (String, Vec<Bit>)>,
    netnames: HashMap<String, Vec<Bit>>,
    cells: Vec<Cell>,
}

fn module(json: &Value, name: &str) -> Result<Module> {
    let m = &json["modules"][name];
    if m.is_null() {
        bail!("the netlist has no module {name}");
    }
    let ports = m["ports"]
        .as_object()
        .into_iter()
        .flatten()
        .map(|(k, p)| {
            (
                k.clone(),
                (
                    p["direction"].as_str().unwrap_or("").to_string(),
                    bits(&p["bits"]),
                ),
            )
        })
        .collect();
    let netnames = m["netnames"]
        .as_object()
        .into_iter()
        .flatten()
        .map(|(k, n)| (k.clone(), bits(&n["bits"])))
        .collect();
    let cells = m["cells"]
        .as_object()
        .into_iter()
        .flatten()
        .map(|(k, c)| {
            let dirs = &c["port_directions"];
            let mut inputs = Vec::new();
            let mut outputs = Vec::new();
            let mut undefined = Vec::new();
            for (pin, b) in c["connections"].as_object().into_iter().flatten() {
                let entry = (pin.clone(), bits(b));
                if dirs[pin].as_str() == Some("output") {
                    outputs.push(entry);
                } else {
                    let x = b.as_array().into_iter().flatten();
                    if x.filter_map(Value::as_str).any(|v| v == "x" || v == "z") {
                        undefined.push(pin.clone());
                    }
                    inputs.push(entry);
                }
            }
            let params = c["parameters"]
                .as_object()
                .into_iter()
                .flatten()
                .map(|(k, v)| (k.clone(), v.as_str().unwrap_or("").to_string()))
                .collect();
            Cell {
                name: k.clone(),
                kind: c["type"].as_str().unwrap_or("").to_string(),
                inputs,
                outputs,
                params,
                undefined,
                src: c["attributes"]["src"].as_str().unwrap_or("").to_string(),
            }
        })
        .collect();
    Ok(Module {
        ports,
        netnames,
        cells,
    })
}

fn read(path: &Path) -> Result<Value> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))
}

/// The registers of `m` (a flattened netlist with constants folded, before `opt_dff`) with
/// bits that are never loaded: `$dff` or `$dffe` (no reset or load that defines them) whose D
/// bit is its own Q bit. Each as (a name of its output, its source, the bits, `[0]`,
/// `[3, 5]`).
fn never_loaded(m: &Module) -> Vec<(String, String, String)> {
    let mut v = Vec::new();
    for c in &m.cells {
        if c.kind != "$dff" && c.kind != "$dffe" {
            continue;
        }
        let pin = |list: &[(String, Vec<Bit>)], p: &str| {
            list.iter()
                .find(|(n, _)| n == p)
                .map(|(_, b)| b.clone())
                .unwrap_or_default()
        };
        let (d, q) = (pin(&c.inputs, "D"), pin(&c.outputs, "Q"));
        let held: Vec<usize> = (0..d.len().min(q.len()))
            .filter(|&i| d[i].is_some() && d[i] == q[i])
            .collect();
        if held.is_empty() {
            continue;
        }
        // The register's own name: among the nets that are exactly its Q, a register's name
        // (`_q`, `_q2`: the generated RTL's naming) first, then the shortest.
        let reg_name = |n: &str| {
            let t = n.trim_end_matches(|ch: char| ch.is_ascii_digit());
            t.ends_with("_q")
        };
        let name = m
            .netnames
            .iter()
            .filter(|(_, b)| **b == q)
            .map(|(n, _)| n.as_str())
            .min_by_key(|n| (n.starts_with('$'), !reg_name(n), n.len(), n.to_string()))
            .unwrap_or(&c.name)
            .to_string();
        // `rmap_top.v:210.15-223.4|interpolate.v:240.3-240.44`: the innermost, line only.
        let inner = c.src.rsplit('|').next().unwrap_or_default();
        let src = inner.split('.').take(2).collect::<Vec<_>>().join(".");
        v.push((name, src, format!("{held:?}")));
    }
    v.sort();
    v
}

fn is_register(kind: &str) -> bool {
    kind.contains("dff") || kind.contains("dlatch") || kind == "$sr"
}

/// Cells whose output bit k reads only bit k of each data input (bit k of every word, for a
/// parallel case multiplexer's B).
fn bitwise(kind: &str) -> bool {
    is_register(kind)
        || matches!(
            kind,
            "$mux" | "$pmux" | "$and" | "$or" | "$xor" | "$xnor" | "$not" | "$pos" | "$bwmux"
        )
}

fn is_memory(kind: &str) -> bool {
    kind.starts_with("$mem")
}

/// Whether an undefined bit on input `pin` of `cell` is harmless: a multiplexer's data input
/// (`proc` writes `x` as the default of a variable assigned on every path, into an input no
/// path selects), or the clock or enable of an asynchronous memory read, which it ignores.
fn may_be_undefined(cell: &Cell, pin: &str) -> bool {
    let mux =
        matches!(cell.kind.as_str(), "$mux" | "$pmux" | "$bwmux") && (pin == "A" || pin == "B");
    let sync = cell
        .params
        .get("CLK_ENABLE")
        .is_some_and(|v| v.contains('1'));
    let async_read = cell.kind.starts_with("$memrd") && !sync && (pin == "CLK" || pin == "EN");
    mux || async_read
}

/// How an input pin of a cell passes to its outputs: registered data (one register), a
/// memory read address (one register for a synchronous read), combinational, or control.
#[derive(Clone, Copy, PartialEq)]
enum Pin {
    Data(u32),
    Control,
}

fn pin_class(cell: &Cell, pin: &str) -> Pin {
    if is_register(&cell.kind) {
        if pin == "D" {
            Pin::Data(1)
        } else {
            Pin::Control
        }
    } else if is_memory(&cell.kind) {
        // A read passes its address to its data (a clocked read through one register);
        // every other memory pin, write ports' included, is control.
        let read = cell.kind.starts_with("$memrd") && pin == "ADDR";
        if read {
            let sync = cell
                .params
                .get("CLK_ENABLE")
                .is_some_and(|v| v.contains('1'));
            Pin::Data(sync as u32)
        } else {
            Pin::Control
        }
    } else {
        Pin::Data(0)
    }
}

/// The sample inputs and data outputs of the top, as its vector fields name them.
fn sample_ports(d: &DesignDir) -> (Vec<String>, Vec<String>) {
    let cfg = &d.config;
    let top = TOP.vectors().expect("the top has vectors");
    let mut ins = Vec::new();
    let mut outs = Vec::new();
    for f in top.fields(cfg) {
        if let Some(p) = top.port(&f) {
            match f.dir {
                Dir::In => ins.push(p),
                Dir::Out => outs.push(p),
            }
        }
    }
    if cfg.side_bits() > 0 {
        ins.push("side_i".into());
        outs.push("side_o".into());
    }
    (ins, outs)
}

/// Checks the design in `d`; Yosys writes its netlists under `build/structure`.
pub fn check(d: &DesignDir, build: &Path) -> Result<Part> {
    let cfg = &d.config;
    let top_name = TOP.module(cfg);
    let logs = build.join("structure");
    let mut files: Vec<String> = d.file_names().to_vec();
    if cfg.axis {
        // The proof is of rmap_top; the AXI4-Stream wrapper is checked by its testbench.
        let axis = crate::stages::top(cfg).file(cfg);
        files.retain(|f| *f != axis);
    }
    let netlists = yosys::structure(d.path(), &top_name, &files, &logs)?;
    let (hier, flat) = (&netlists.hier, &netlists.flat);
    let mut fails = Failures::default();
    let (sample_in, data_out) = sample_ports(d);

    // The gradient reaches only the front.
    let hier = read(hier)?;
    let top = module(&hier, &top_name)?;
    let front: Vec<String> = FRONT.iter().map(|u| u.module(cfg)).collect();
    let grad: Vec<u64> = ["gx_i", "gy_i", "gz_i"]
        .iter()
        .flat_map(|p| {
            top.ports
                .get(*p)
                .map(|(_, b)| b.clone())
                .unwrap_or_default()
        })
        .flatten()
        .collect();
    if grad.len() != 3 * cfg.grad_bits as usize {
        fails.add(format!(
            "structure: the top {top_name} has no {}-bit gradient ports",
            cfg.grad_bits
        ));
    }
    for c in &top.cells {
        let reads = c
            .inputs
            .iter()
            .chain(&c.outputs)
            .any(|(_, b)| b.iter().flatten().any(|x| grad.contains(x)));
        if reads && !front.contains(&c.kind) {
            fails.add(format!(
                "structure: {} ({}) in {top_name} reads the gradient; only {} may",
                c.name,
                c.kind,
                front.join(" and ")
            ));
        }
        for (pin, b) in &c.outputs {
            if b.iter().flatten().any(|x| grad.contains(x)) {
                fails.add(format!("structure: {}.{pin} drives the gradient", c.name));
            }
        }
    }
    for (name, (dir, b)) in &top.ports {
        if dir == "output" && b.iter().flatten().any(|x| grad.contains(x)) {
            fails.add(format!("structure: output {name} is wired to the gradient"));
        }
    }

    // One sample at a time, in the flattened design.
    let flat = read(flat)?;
    let m = module(&flat, &top_name)?;
    let mut sources: Vec<u64> = Vec::new();
    for p in &sample_in {
        match m.ports.get(p) {
            Some((_, b)) => sources.extend(b.iter().flatten()),
            None => fails.add(format!("structure: the top has no sample input {p}")),
        }
    }
    // No register is never loaded. With constants folded, a register bit whose D is its own
    // Q, with no reset to load it, holds its power-up value for ever: Verilog leaves that
    // value undefined, Verilator's two-state simulation (the proof's, and its ground
    // truth's) gives it 0, synthesis any value it likes. Checked on the registers as `proc`
    // wrote them, whatever reads them: after `opt_dff` such a register is an `x`, which the
    // check below finds only where no multiplexer's data input hides it.
    let folded = read(&netlists.folded)?;
    for (reg, src, held) in never_loaded(&module(&folded, &top_name)?) {
        fails.add(format!(
            "structure: register {reg} ({src}) is never loaded: bits {held} hold their power-up value, which Verilog leaves undefined (simulation reads 0, synthesis any value)"
        ));
    }
    // No undefined value is read. A register that is never loaded (its enable inverted, its
    // input its own output) is removed by opt_dff and read as `x`: Verilator's two-state
    // simulation (the proof's, and its ground truth's) gives it 0, synthesis any value it
    // likes (found by `rmapgen mutants`: an inverted enable in normalise that the proof and
    // `--direct` passed and the synthesised netlist got wrong, docs/VERIFICATION.md).
    for c in &m.cells {
        if let Some(pin) = c.undefined.iter().find(|p| !may_be_undefined(c, p)) {
            fails.add(format!(
                "structure: {} ({}) reads an undefined value on {pin}: a register that is never loaded, or a signal nothing drives (simulation and synthesis give it different values)",
                c.name, c.kind
            ));
        }
    }
    // Drivers: bit -> (cell, output pin, bit position).
    let mut driver: HashMap<u64, (usize, usize)> = HashMap::new();
    for (ci, c) in m.cells.iter().enumerate() {
        for (pi, (_, b)) in c.outputs.iter().enumerate() {
            for x in b.iter().flatten() {
                driver.insert(*x, (ci, pi));
            }
        }
    }
    // ... and no signal that nothing drives (an input of the top, a cell's output).
    let inputs: std::collections::HashSet<u64> = m
        .ports
        .values()
        .filter(|(dir, _)| dir == "input")
        .flat_map(|(_, b)| b.iter().flatten().copied())
        .collect();
    for c in &m.cells {
        let undriven = c.inputs.iter().find(|(_, b)| {
            b.iter()
                .flatten()
                .any(|x| !driver.contains_key(x) && !inputs.contains(x))
        });
        if let Some((pin, _)) = undriven {
            fails.add(format!(
                "structure: {} ({}) reads a signal that nothing drives on {pin}",
                c.name, c.kind
            ));
        }
    }
    // Readers, for the forward reach: bit -> cells.
    let mut readers: HashMap<u64, Vec<usize>> = HashMap::new();
    for (ci, c) in m.cells.iter().enumerate() {
        for (_, b) in &c.inputs {
            for x in b.iter().flatten() {
                readers.entry(*x).or_default().push(ci);
            }
        }
    }
    let mut reached: std::collections::HashSet<u64> = sources.iter().copied().collect();
    let mut reached_cells = vec![false; m.cells.len()];
    let mut stack: Vec<u64> = sources.clone();
    while let Some(x) = stack.pop() {
        for &ci in readers.get(&x).map(Vec::as_slice).unwrap_or(&[]) {
            if !reached_cells[ci] {
                reached_cells[ci] = true;
                for (_, b) in &m.cells[ci].outputs {
                    for y in b.iter().flatten() {
                        if reached.insert(*y) {
                            stack.push(*y);
                        }
                    }
                }
            }
        }
    }
    // No control input depends on the samples.
    for c in &m.cells {
        for (pin, b) in &c.inputs {
            if pin_class(c, pin) == Pin::Control && b.iter().flatten().any(|x| reached.contains(x))
            {
                fails.add(format!(
                    "structure: the sample data reach control input {pin} of {} ({})",
                    c.name, c.kind
                ));
            }
        }
    }
    let mut outs: Vec<(&String, &Vec<Bit>)> = m
        .netnames
        .iter()
        .filter(|(n, _)| n.starts_with("out_") && *n != "out_valid")
        .collect();
    outs.sort();
    // The cells in front of the output register: the backward cone of the out_* wires.
    let mut cone = vec![false; m.cells.len()];
    let mut stack: Vec<u64> = outs
        .iter()
        .flat_map(|(_, b)| b.iter().flatten().copied())
        .collect();
    let mut seen: std::collections::HashSet<u64> = stack.iter().copied().collect();
    while let Some(x) = stack.pop() {
        if let Some(&(ci, _)) = driver.get(&x) {
            if !cone[ci] {
                cone[ci] = true;
                for (_, b) in &m.cells[ci].inputs {
                    for y in b.iter().flatten() {
                        if seen.insert(*y) {
                            stack.push(*y);
                        }
                    }
                }
            }
        }
    }
    // Every register in front of the output register that the samples reach moves on one
    // enable: a constant, or the same net for all (the pipeline's clock enable), so none
    // holds a sample while the others move.
    let mut enables: std::collections::BTreeMap<String, Vec<String>> = Default::default();
    // ... and on one clock edge: the same clock net, the same polarity (a register clocked
    // on the other edge, or on an inverted or other clock, moves half a clock apart from
    // the rest: a stage skipped that a full-rate stream of similar samples can hide).
    let mut clocks: std::collections::BTreeMap<String, Vec<String>> = Default::default();
    for (ci, c) in m.cells.iter().enumerate() {
        // An asynchronous read is combinational; its data register is a register here.
        let clocked_read = c.kind.starts_with("$memrd")
            && c.params.get("CLK_ENABLE").is_some_and(|v| v.contains('1'));
        if !reached_cells[ci] || !cone[ci] || !(is_register(&c.kind) || clocked_read) {
            continue;
        }
        let pin = "EN";
        let en = c
            .inputs
            .iter()
            .find(|(p, _)| p == pin)
            .map(|(_, b)| b.clone())
            .unwrap_or_default();
        let name = if en.iter().all(Option::is_none) {
            "constant".to_string()
        } else {
            format!("{en:?}")
        };
        let polarity = |p: &str| {
            c.params.get(p).map_or("1", |v| {
                if v.trim_start_matches('0').is_empty() {
                    "0"
                } else {
                    "1"
                }
            })
        };
        let name = if name == "constant" {
            name
        } else {
            format!("{name} polarity {}", polarity("EN_POLARITY"))
        };
        enables.entry(name).or_default().push(c.name.clone());
        let clk = c
            .inputs
            .iter()
            .find(|(p, _)| p == "CLK")
            .map(|(_, b)| format!("{b:?}"))
            .unwrap_or_else(|| "none".into());
        clocks
            .entry(format!("{clk} polarity {}", polarity("CLK_POLARITY")))
            .or_default()
            .push(c.name.clone());
    }
    if clocks.len() > 1 {
        let (odd, cells) = clocks
            .iter()
            .min_by_key(|(_, c)| c.len())
            .expect("more than one");
        fails.add(format!(
            "structure: the registers the samples reach move on {} different clock edges; {} on {odd} ({} of them) apart from the rest",
            clocks.len(),
            cells[0],
            cells.len()
        ));
    }
    let moving: Vec<_> = enables.iter().collect();
    if moving.len() > 1 {
        let (odd, cells) = moving
            .iter()
            .min_by_key(|(_, c)| c.len())
            .expect("more than one");
        fails.add(format!(
            "structure: the registers the samples reach move on {} different enables; {} on net {odd} ({} of them) apart from the rest",
            moving.len(),
            cells[0],
            cells.len()
        ));
    }
    for (name, (dir, b)) in &m.ports {
        if dir == "output"
            && !data_out.contains(name)
            && b.iter().flatten().any(|x| reached.contains(x))
        {
            fails.add(format!(
                "structure: control output {name} depends on the sample data"
            ));
        }
    }
    // Register depths from the sample inputs, over the reached part (a DAG, or a loop is
    // reported).
    let mut depth: HashMap<u64, u128> = sources.iter().map(|&x| (x, 1u128)).collect();
    let mut on_path: std::collections::HashSet<u64> = Default::default();
    let mut looped = false;
    fn depths(
        x: u64,
        m: &Module,
        driver: &HashMap<u64, (usize, usize)>,
        reached: &std::collections::HashSet<u64>,
        depth: &mut HashMap<u64, u128>,
        on_path: &mut std::collections::HashSet<u64>,
        looped: &mut bool,
    ) -> u128 {
        if let Some(&d) = depth.get(&x) {
            return d;
        }
        if !reached.contains(&x) {
            return 0;
        }
        if !on_path.insert(x) {
            *looped = true;
            return 0;
        }
        let mut set = 0u128;
        if let Some(&(ci, pi)) = driver.get(&x) {
            let c = &m.cells[ci];
            let out_width = c.outputs[pi].1.len();
            let pos = c.outputs[pi]
                .1
                .iter()
                .position(|b| *b == Some(x))
                .unwrap_or(0);
            for (pin, b) in &c.inputs {
                if let Pin::Data(delay) = pin_class(c, pin) {
                    // Registers and bitwise cells pass bit k to bit k (a parallel case
                    // multiplexer's B holds one word per case); other cells mix every bit.
                    let ins: Vec<u64> =
                        if bitwise(&c.kind) && pin != "S" && b.len() % out_width == 0 {
                            b.iter()
                                .skip(pos)
                                .step_by(out_width)
                                .flatten()
                                .copied()
                                .collect()
                        } else {
                            b.iter().flatten().copied().collect()
                        };
                    for y in ins {
                        let s = depths(y, m, driver, reached, depth, on_path, looped);
                        set |= s.checked_shl(delay).unwrap_or(0);
                    }
                }
            }
        }
        on_path.remove(&x);
        depth.insert(x, set);
        set
    }
    let want = TOP.latency(cfg).unwrap_or(0).saturating_sub(1);
    if outs.is_empty() {
        fails.add(format!(
            "structure: {top_name} has no out_* wires at its output register"
        ));
    }
    for (name, b) in outs {
        let mut set = 0u128;
        for x in b.iter().flatten() {
            set |= depths(
                *x,
                &m,
                &driver,
                &reached,
                &mut depth,
                &mut on_path,
                &mut looped,
            );
        }
        let list: Vec<u32> = (0..128).filter(|k| set >> k & 1 == 1).collect();
        if list != [want] {
            fails.add(format!(
                "structure: {name} is {list:?} registers from the sample inputs, not exactly {want} (the latency before the output register)"
            ));
        }
    }
    if looped {
        fails.add(
            "structure: a loop through the sample data (a register or wire that feeds back)".into(),
        );
    }
    // The one input of this part, the netlist, has been checked.
    fails.checked = 1;
    Ok(Part::new("structure", 0..1, 1, fails))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A design directory holding only the manifest of `cfg`.
    fn design(cfg: &crate::config::Config) -> (tempfile::TempDir, DesignDir) {
        let tmp = tempfile::tempdir().unwrap();
        let manifest = serde_json::json!({ "top": "rmap_top", "config": cfg, "modules": [] });
        std::fs::write(tmp.path().join("manifest.json"), manifest.to_string()).unwrap();
        let d = DesignDir::open(tmp.path()).unwrap();
        (tmp, d)
    }

    /// The sample ports are the top's gradient inputs and its result outputs (not the clock,
    /// the handshake or the host port), with the side channel exactly when the design
    /// carries one (an AXI4-Stream tuser, the lanes' tag under the handshake).
    #[test]
    fn the_sample_ports_are_the_gradient_in_and_the_result_out() {
        let base = crate::config::Config::default();
        let (_t, d) = design(&base);
        let (ins, outs) = sample_ports(&d);
        assert_eq!(ins, ["gx_i", "gy_i", "gz_i"]);
        assert_eq!(outs, ["zero_o", "i_o"]);
        for cfg in [
            crate::config::Config {
                axis: true,
                axis_user: 4,
                handshake: true,
                ..base.clone()
            },
            crate::config::Config {
                lanes: 2,
                handshake: true,
                ..base.clone()
            },
            crate::config::Config {
                lanes: 2,
                ..base.clone()
            },
        ] {
            let (_t, d) = design(&cfg);
            let (ins, outs) = sample_ports(&d);
            let side = cfg.side_bits() > 0;
            assert_eq!(ins.contains(&"side_i".to_string()), side, "{ins:?}");
            assert_eq!(outs.contains(&"side_o".to_string()), side, "{outs:?}");
            assert_eq!(ins[..3], ["gx_i", "gy_i", "gz_i"], "{}", cfg.summary());
        }
    }

    /// Yosys's JSON is read as JSON; a file that is missing or not JSON is an error naming it.
    #[test]
    fn a_netlist_is_read_as_json_or_refused_naming_the_file() {
        let tmp = tempfile::tempdir().unwrap();
        let good = tmp.path().join("n.json");
        std::fs::write(&good, r#"{"modules": {"top": {"ports": {}}}}"#).unwrap();
        assert_eq!(
            read(&good).unwrap(),
            serde_json::json!({"modules": {"top": {"ports": {}}}})
        );
        let bad = tmp.path().join("bad.json");
        std::fs::write(&bad, "{ not json").unwrap();
        let e = format!("{:#}", read(&bad).unwrap_err());
        assert!(e.contains("bad.json is not JSON"), "{e}");
        let e = format!("{:#}", read(&tmp.path().join("gone.json")).unwrap_err());
        assert!(e.contains("cannot read") && e.contains("gone.json"), "{e}");
    }

    fn reg(kind: &str, d: u64, q: u64) -> Cell {
        Cell {
            name: format!("r{q}"),
            kind: kind.to_string(),
            inputs: vec![("D".into(), vec![Some(d)])],
            outputs: vec![("Q".into(), vec![Some(q)])],
            params: HashMap::new(),
            undefined: Vec::new(),
            src: "top.v:1.1-1.2|s.v:7.3-7.9".into(),
        }
    }

    /// A `$dff` holding its own value is never loaded; one with a reset that loads it
    /// (`$adff`) is defined, and a register loaded from elsewhere is not flagged. The report
    /// names the register by its `_q` net, before a shorter net that is exactly its output
    /// and before Yosys's `$` names.
    #[test]
    fn only_registers_without_a_reset_that_hold_themselves_are_never_loaded() {
        let m = Module {
            ports: HashMap::new(),
            netnames: HashMap::from([
                ("u.hold_q".to_string(), vec![Some(5)]),
                ("u.h".to_string(), vec![Some(5)]),
                ("$auto$5".to_string(), vec![Some(5)]),
            ]),
            cells: vec![reg("$dff", 5, 5), reg("$adff", 6, 6), reg("$dff", 7, 8)],
        };
        let v = never_loaded(&m);
        assert_eq!(v, vec![("u.hold_q".into(), "s.v:7".into(), "[0]".into())]);
    }

    /// A cell of `kind` with the input pins `pins` (one bit each) and a CLK_ENABLE of `sync`.
    fn cell(kind: &str, pins: &[&str], sync: Option<&str>) -> Cell {
        Cell {
            name: "c".into(),
            kind: kind.into(),
            inputs: pins
                .iter()
                .map(|p| (p.to_string(), vec![Some(1)]))
                .collect(),
            outputs: vec![("Y".into(), vec![Some(2)])],
            params: sync
                .map(|v| HashMap::from([("CLK_ENABLE".to_string(), v.to_string())]))
                .unwrap_or_default(),
            undefined: Vec::new(),
            src: String::new(),
        }
    }

    /// The netlist reader keeps what Yosys's JSON says: ports with direction and bits
    /// (constants as None), nets, and each cell's kind, inputs and outputs by the port
    /// directions, its parameters, its source and the input pins with an `x` or `z` bit.
    #[test]
    fn the_netlist_reader_keeps_ports_nets_and_cells_with_their_undefined_pins() {
        let json = serde_json::json!({"modules": {"top": {
            "ports": {"a_i": {"direction": "input", "bits": [2, 3]},
                      "y_o": {"direction": "output", "bits": ["0", 4]}},
            "netnames": {"w": {"bits": [4]}},
            "cells": {"$m": {
                "type": "$mux",
                "port_directions": {"A": "input", "B": "input", "S": "input", "Y": "output"},
                "connections": {"A": ["x"], "B": [2], "S": ["z"], "Y": [4]},
                "parameters": {"WIDTH": "00000000000000000000000000000001"},
                "attributes": {"src": "top.v:3.1-3.9"}}}}}});
        let m = module(&json, "top").unwrap();
        assert_eq!(
            m.ports["a_i"],
            ("input".to_string(), vec![Some(2), Some(3)])
        );
        assert_eq!(m.ports["y_o"], ("output".to_string(), vec![None, Some(4)]));
        assert_eq!(m.netnames["w"], vec![Some(4)]);
        let c = &m.cells[0];
        assert_eq!((c.name.as_str(), c.kind.as_str()), ("$m", "$mux"));
        let names = |l: &[(String, Vec<Bit>)]| l.iter().map(|p| p.0.clone()).collect::<Vec<_>>();
        assert_eq!(names(&c.inputs), ["A", "B", "S"]);
        assert_eq!(names(&c.outputs), ["Y"]);
        assert_eq!(c.undefined, ["A", "S"]);
        assert_eq!(c.params["WIDTH"].len(), 32);
        assert_eq!(c.src, "top.v:3.1-3.9");
        assert!(module(&json, "other").is_err());
        assert_eq!(
            bits(&serde_json::json!([1, "1", 7])),
            vec![Some(1), None, Some(7)]
        );
        assert!(bits(&serde_json::json!("x")).is_empty());
    }

    /// Which cells are registers, bitwise or memories, and how each pin passes a sample: a
    /// register's D through one register, a synchronous read's address through one and an
    /// asynchronous one's through none, everything else of a register or memory as control,
    /// any other cell's pins combinationally.
    #[test]
    fn cells_and_pins_are_classed_as_the_depth_count_needs() {
        for k in ["$dff", "$adffe", "$sdff", "$dlatch", "$sr"] {
            assert!(is_register(k) && bitwise(k), "{k}");
        }
        for k in [
            "$mux", "$pmux", "$and", "$or", "$xor", "$xnor", "$not", "$pos", "$bwmux",
        ] {
            assert!(bitwise(k) && !is_register(k), "{k}");
        }
        for k in ["$add", "$eq", "$shl", "$memrd_v2", "$reduce_or"] {
            assert!(!bitwise(k), "{k}");
        }
        assert!(is_memory("$mem_v2") && is_memory("$memrd") && !is_memory("$mux"));
        let dff = cell("$dffe", &["D", "EN", "CLK"], None);
        assert!(pin_class(&dff, "D") == Pin::Data(1));
        assert!(pin_class(&dff, "EN") == Pin::Control && pin_class(&dff, "CLK") == Pin::Control);
        let sync = cell("$memrd_v2", &["ADDR", "EN", "CLK"], Some("1"));
        assert!(pin_class(&sync, "ADDR") == Pin::Data(1));
        assert!(pin_class(&sync, "EN") == Pin::Control);
        let asy = cell("$memrd_v2", &["ADDR"], Some("0"));
        assert!(pin_class(&asy, "ADDR") == Pin::Data(0));
        let wr = cell("$memwr_v2", &["ADDR", "DATA"], Some("1"));
        assert!(pin_class(&wr, "ADDR") == Pin::Control && pin_class(&wr, "DATA") == Pin::Control);
        let add = cell("$add", &["A", "B"], None);
        assert!(pin_class(&add, "A") == Pin::Data(0));
    }

    /// An undefined bit is allowed only on a multiplexer's data inputs and on the clock and
    /// enable of an asynchronous memory read.
    #[test]
    fn undefined_bits_are_allowed_only_where_no_path_reads_them() {
        for k in ["$mux", "$pmux", "$bwmux"] {
            let c = cell(k, &["A", "B", "S"], None);
            assert!(
                may_be_undefined(&c, "A") && may_be_undefined(&c, "B"),
                "{k}"
            );
            assert!(!may_be_undefined(&c, "S"), "{k}");
        }
        let asy = cell("$memrd_v2", &["ADDR", "EN", "CLK"], Some("0"));
        assert!(may_be_undefined(&asy, "CLK") && may_be_undefined(&asy, "EN"));
        assert!(!may_be_undefined(&asy, "ADDR"));
        let sync = cell("$memrd_v2", &["ADDR", "EN", "CLK"], Some("1"));
        assert!(!may_be_undefined(&sync, "CLK") && !may_be_undefined(&sync, "EN"));
        let no_param = cell("$memrd", &["CLK"], None);
        assert!(may_be_undefined(&no_param, "CLK"));
        for k in ["$and", "$dff", "$memwr_v2"] {
            assert!(!may_be_undefined(&cell(k, &["A"], None), "A"), "{k}");
        }
    }
}
