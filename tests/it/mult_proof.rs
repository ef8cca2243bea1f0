//! `rmapgen prove-mult`: the Yosys proof that every adder tree equals its product passes on
//! a generated design with every tree stage, and fails, naming the tree, for each fault
//! planted in a copy of the generated Verilog.

use crate::hdl::{generate, require};
use crate::helpers::{rmapgen, tempdir};
use std::path::Path;

/// The narrowest widths with every tree stage (normalise, interpolate, color_mul) at depth 0,
/// where most levels are unregistered and the sums are wires: 11 trees, 268 SAT cases.
const FLAGS: &[&str] = &[
    "--grad-bits",
    "8",
    "--red-bits",
    "6",
    "--recip-bits",
    "5",
    "--frac-bits",
    "4",
    "--index-bits",
    "2",
    "--interp-bits",
    "1",
    "--map-bits",
    "6",
    "--color",
    "--pipeline-depth",
    "0",
];

/// (name, file, the generated text, its faulty replacement, the tree that must fail).
const PLANTS: &[(&str, &str, &str, &str, &str)] = &[
    (
        "a partial product left out",
        "normalise.v",
        "(a_q1[3] ? {{1{1'b0}}, recip_q1} : 6'd0)",
        "6'd0",
        "normalise.pa",
    ),
    (
        "a wrong rounding constant",
        "color_mul.v",
        "assign ng_l1_0_d = {(8'd31 +",
        "assign ng_l1_0_d = {(8'd30 +",
        "color_mul.ng",
    ),
    (
        "a wrong shift of one term",
        "interpolate.v",
        "(wu_i[1] ? {{1{1'b0}}, e11_i} : 7'd0)",
        "(wu_i[1] ? {e11_i, 1'b0} : 7'd0)",
        "interpolate.a1",
    ),
    (
        "a carry dropped between levels",
        "color_mul.v",
        // Bit 8 of level 1's node is its carry out (the node reaches 441).
        "{{5{1'b0}}, nr_l1_0_d[8:3]}",
        "{{6{1'b0}}, nr_l1_0_d[7:3]}",
        "color_mul.nr",
    ),
];

fn prove(dir: &Path, logs: &Path, engine: &str) -> (bool, String, String) {
    let (code, out, err) = prove_with(dir, logs, &["--engine", engine], None);
    (code == Some(0), out, err)
}

/// `rmapgen prove-mult DIR --logs LOGS ARGS`, with `YOSYS` set to `yosys` if given: (exit
/// code, stdout, stderr).
fn prove_with(
    dir: &Path,
    logs: &Path,
    args: &[&str],
    yosys: Option<&str>,
) -> (Option<i32>, String, String) {
    let mut c = rmapgen();
    c.arg("prove-mult")
        .arg(dir)
        .arg("--logs")
        .arg(logs)
        .args(args);
    if let Some(y) = yosys {
        c.env("YOSYS", y);
    }
    let out = c.output().expect("rmapgen runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn every_tree_is_proved_and_every_planted_fault_is_caught() {
    if !require("yosys") {
        return;
    }
    let tmp = tempdir();
    let good = tmp.path().join("good");
    generate(&good, FLAGS, 0);
    // The three engines on the same design and the same faults: each must prove the design
    // and catch every fault on its own.
    for (engine, how) in [
        ("sat", "SAT case"),
        ("exhaustive", "every input: "),
        ("algebra", "as polynomials: "),
    ] {
        proves_and_catches(tmp.path(), &good, engine, how);
    }
}

fn proves_and_catches(tmp: &Path, good: &Path, engine: &str, how: &str) {
    let (ok, out, err) = prove(good, &tmp.join(format!("logs-{engine}")), engine);
    assert!(ok, "{engine}: the generated design must prove: {out}{err}");
    for tree in [
        "normalise.pa",
        "normalise.pb",
        "interpolate.a0",
        "interpolate.a1",
        "interpolate.r",
        "color_mul.nr",
        "color_mul.ng",
        "color_mul.nb",
        "color_mul.pr",
        "color_mul.pg",
        "color_mul.pb",
    ] {
        let line = out
            .lines()
            .find(|l| l.starts_with(&format!("prove-mult: {tree} = ")))
            .unwrap_or_else(|| panic!("{engine}: {tree}: {out}"));
        assert!(line.contains(how), "{engine}: {line}");
    }
    assert!(out.contains("all 11 trees proved"), "{out}");
    // The summary's SAT cases are the trees' own, summed (none under the other engines).
    let cases: usize = out
        .lines()
        .filter_map(|l| {
            l.strip_suffix(" SAT cases)")
                .or_else(|| l.strip_suffix(" SAT case)"))
        })
        .map(|l| l.rsplit('(').next().unwrap().parse::<usize>().unwrap())
        .sum();
    assert_eq!(engine == "sat", cases > 0, "{engine}: {out}");
    assert!(
        out.contains(&format!("({cases} SAT cases, ")),
        "{engine}: {cases} SAT cases: {out}"
    );

    for (k, (what, file, old, new, tree)) in PLANTS.iter().enumerate() {
        let bad = tmp.join(format!("bad-{engine}-{k}"));
        std::fs::create_dir(&bad).unwrap();
        for e in std::fs::read_dir(good).unwrap() {
            let e = e.unwrap();
            if e.file_type().unwrap().is_file() {
                std::fs::copy(e.path(), bad.join(e.file_name())).unwrap();
            }
        }
        let path = bad.join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.matches(old).count(), 1, "{what}: {old} in {file}");
        std::fs::write(&path, text.replace(old, new)).unwrap();
        let (ok, out, err) = prove(&bad, &tmp.join(format!("logs-{engine}-{k}")), engine);
        assert!(!ok, "{engine}: {what} must make the proof fail: {out}{err}");
        assert!(
            err.contains(&format!("prove-mult: {tree} = ")) && err.contains("FAILED"),
            "{what}: the failure must name {tree}: {err}"
        );
        // Only the tree with the fault fails.
        let failed: Vec<&str> = err
            .lines()
            .filter(|l| l.contains(": FAILED: the sum"))
            .collect();
        assert_eq!(failed.len(), 1, "{what}: {err}");
    }
}

/// `--matrix` generates grid rows and proves each (here the narrowest row, 5 trees, ~5 s,
/// and lanes4, whose tree inputs at pipeline depth 0 are other names of a stage input port
/// (`recip_q1` of `recip_data_i`) and of a mux's output (`ux_d`): the cut must reach every
/// reader of the net); an unknown row is bad input (one line, exit 2) before anything is
/// generated.
#[test]
fn the_matrix_proves_the_rows_named_and_refuses_an_unknown_row() {
    if !require("yosys") {
        return;
    }
    let tmp = tempdir();
    let out = rmapgen()
        .arg("prove-mult")
        .arg(tmp.path().join("designs"))
        .args([
            "--matrix",
            "--row",
            "narrowest,lanes4",
            "--jobs",
            "1",
            "--logs",
        ])
        .arg(tmp.path().join("logs"))
        .output()
        .expect("rmapgen runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("==== narrowest: "), "{text}");
    assert!(text.contains("all 5 trees proved"), "{text}");
    assert!(text.contains("==== lanes4: "), "{text}");
    assert!(text.contains("all 4 trees proved"), "{text}");
    assert!(text.contains("every row proved (2 rows,"), "{text}");
    assert!(tmp.path().join("logs/narrowest/yosys.log").is_file());

    let bad = tmp.path().join("bad");
    let out = rmapgen()
        .arg("prove-mult")
        .arg(&bad)
        .args(["--matrix", "--row", "no_such_row"])
        .output()
        .expect("rmapgen runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("no_such_row"), "{err}");
    assert!(!bad.exists());

    // A tree no selected row has, and a tree too wide for --engine exhaustive: bad input,
    // refused before anything is generated.
    for (args, named) in [
        (
            &["--row", "narrowest", "--tree", "normalise.pq"][..],
            "normalise.pq",
        ),
        (
            &["--row", "widest", "--engine", "exhaustive"][..],
            "interpolate.r",
        ),
    ] {
        let out = rmapgen()
            .arg("prove-mult")
            .arg(&bad)
            .arg("--matrix")
            .args(args)
            .output()
            .expect("rmapgen runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(named), "{err}");
        assert!(!bad.exists());
    }
}

/// `--mult infer`: the Verilog holds plain `*` products and no partial product (no gated
/// term `sel ? x : 0` in a multiplying stage), the same specifications prove against the
/// inferred products and their sums, and a planted fault in one sum is caught by name.
#[test]
fn inferred_products_are_plain_and_proved_and_a_planted_fault_is_caught() {
    let tmp = tempdir();
    let good = tmp.path().join("infer");
    let flags: Vec<&str> = FLAGS.iter().copied().chain(["--mult", "infer"]).collect();
    generate(&good, &flags, 0);
    // The tree design of the same widths, where the same count finds partial products and
    // no product: the check can fail.
    let tree = tmp.path().join("tree");
    generate(&tree, FLAGS, 0);
    let count = |dir: &Path, file: &str| {
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        let assigns = || {
            text.lines()
                .filter(|l| l.trim_start().starts_with("assign"))
        };
        // A partial product is a gated term, `(sel ? x : N'd0)`.
        let gated = assigns().filter(|l| l.contains(" ? ") && l.contains("'d0)"));
        (
            assigns().filter(|l| l.contains(" * ")).count(),
            gated.count(),
        )
    };
    for (file, products) in [("normalise.v", 2), ("interpolate.v", 6), ("color_mul.v", 6)] {
        assert_eq!(
            count(&good, file),
            (products, 0),
            "{file}: plain products only"
        );
        let (muls, gated) = count(&tree, file);
        assert!(
            muls == 0 && gated > 0,
            "{file} of the tree design: {muls} {gated}"
        );
    }
    if !require("yosys") {
        return;
    }
    let (ok, out, err) = prove(&good, &tmp.path().join("logs"), "auto");
    assert!(ok, "the inferred design must prove: {out}{err}");
    assert!(out.contains("all 11 trees proved"), "{out}");
    let bad = tmp.path().join("bad");
    std::fs::create_dir(&bad).unwrap();
    for e in std::fs::read_dir(&good).unwrap() {
        let e = e.unwrap();
        if e.file_type().unwrap().is_file() {
            std::fs::copy(e.path(), bad.join(e.file_name())).unwrap();
        }
    }
    let path = bad.join("color_mul.v");
    let text = std::fs::read_to_string(&path).unwrap();
    let (old, new) = (
        "assign ng_l2_d = {ng_l1_0_d, {1{1'b0}}} + 15'd63;",
        "assign ng_l2_d = {ng_l1_0_d, {1{1'b0}}} + 15'd62;",
    );
    assert_eq!(text.matches(old).count(), 1, "{old}");
    std::fs::write(&path, text.replace(old, new)).unwrap();
    let (ok, out, err) = prove(&bad, &tmp.path().join("logs_bad"), "auto");
    assert!(!ok, "a wrong constant must make the proof fail: {out}{err}");
    let failed: Vec<&str> = err
        .lines()
        .filter(|l| l.contains(": FAILED: the sum"))
        .collect();
    assert_eq!(failed.len(), 1, "{err}");
    assert!(failed[0].contains("prove-mult: color_mul.ng = "), "{err}");
}

/// `--tree` proves the trees it names and no other, and the exhaustive engine's count is every
/// input of every tree proved. A `--tree` the design does not have is bad input beside one it
/// has too (one line naming it, exit 2, nothing written), and so is a Yosys that is not there.
#[test]
fn the_trees_named_alone_are_proved_and_their_inputs_counted() {
    if !require("yosys") {
        return;
    }
    let tmp = tempdir();
    let good = tmp.path().join("good");
    generate(&good, FLAGS, 0);
    let jobs = rmapgen::prove::mult::jobs(&crate::hdl::config_of(&good));
    let inputs = |names: &[&str]| -> u128 {
        jobs.iter()
            .filter(|j| names.contains(&j.name().as_str()))
            .map(|j| j.exhaustive_inputs())
            .sum()
    };
    let run = |trees: &str, yosys: Option<&str>, logs: &str| {
        let args = ["--engine", "exhaustive", "--tree", trees];
        prove_with(&good, &tmp.path().join(logs), &args, yosys)
    };
    for names in [
        &["normalise.pa"][..],
        &["interpolate.r", "color_mul.ng"][..],
    ] {
        let (code, out, err) = run(&names.join(","), None, &names.join("+"));
        assert_eq!(code, Some(0), "{names:?}: {out}{err}");
        let proved: Vec<&str> = out
            .lines()
            .filter_map(|l| l.strip_prefix("prove-mult: ")?.split_once(" = "))
            .map(|(tree, _)| tree)
            .collect();
        assert_eq!(proved, names, "{out}");
        let n = inputs(names);
        assert!(n > 0);
        assert!(
            out.contains(&format!("all {} trees proved", names.len()))
                && out.contains(&format!(
                    " {} inputs evaluated",
                    rmapgen::prove::mult::count(n)
                )),
            "{names:?}: {n} inputs: {out}"
        );
    }
    for (trees, yosys, named) in [
        (
            "normalise.pa,normalise.pq",
            None,
            "--tree normalise.pq: no such tree",
        ),
        (
            "normalise.pa",
            Some("/nonexistent/yosys"),
            "/nonexistent/yosys not found",
        ),
    ] {
        let (code, out, err) = run(trees, yosys, "refused");
        assert_eq!(code, Some(2), "{trees}: {out}{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(named), "{named}: {err}");
        assert!(!tmp.path().join("refused").exists());
    }
}
