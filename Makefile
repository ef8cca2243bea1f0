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

.PHONY: all build run test tools cargo-test golden roms

all: run

build:
	$(CARGO) build --release

# The main job on defaults: the default design into rtl_out/ and the standard sphere.
run: build
	$(RMAPGEN) generate --out $(OUT)
	$(RMAPGEN) render --scene $(SCENE) --out out/sphere

# Installs iverilog, verilator, yosys, nextpnr-ice40 and icestorm with apt-get when missing
# (a fresh machine has none).
tools:
	@WITH_FPGA=1 scripts/install-tools.sh

cargo-test:
	$(CARGO) test

# Only the $$readmemh files of the default design, refreshed in place in $(OUT) (its other
# files kept; refused if $(OUT) holds anything rmapgen did not write).
roms: build
	$(RMAPGEN) roms --update $(OUT)

# Everything: cargo tests (model, golden rtl_out/, vectors, CLI errors, sampled stress), Verilator
# lint, Yosys synthesis, and every testbench in Icarus and Verilator plus the 1M-vector harness.
# Also the handshake design's top testbench under random backpressure (sim-handshake) and
# the default design placed and routed (fpga-check: block RAMs and the Fmax target, ~20 s).
test: tools cargo-test lint synth sim-all sim-handshake fpga-check
	@echo "make test: all checks passed"

# ---- Simulation (tb/run_sims.sh): every testbench of the design generated with $(GEN_FLAGS)
# into $(SIM_OUT) (not the committed rtl_out/), under Verilator (sim), Icarus (sim-icarus) or
# both (sim-all); build products in build/sim/. sim-matrix runs both simulators over the
# configuration list of tb/sim_matrix.sh (into build/matrix/).
GEN_FLAGS     ?=
SIM_OUT       ?= build/rtl_sim
SIM_STREAM    ?= 1000000
SIM_TB_STREAM ?= 100000
SIM_ENV        = IVERILOG=$(IVERILOG) VVP=$(VVP) VERILATOR=$(VERILATOR) RMAPGEN=$(abspath $(RMAPGEN))

.PHONY: sim sim-icarus sim-all sim-matrix sim-gen

sim-gen: build
	$(RMAPGEN) generate --out $(SIM_OUT) $(GEN_FLAGS)

# Verilator: every testbench, the top's on $(SIM_TB_STREAM) more vectors, and the C++ harness
# on $(SIM_STREAM) random vectors.
sim: sim-gen
	$(SIM_ENV) tb/run_sims.sh --verilator --stream $(SIM_STREAM) --tb-stream $(SIM_TB_STREAM) $(SIM_OUT)

sim-icarus: sim-gen
	$(SIM_ENV) tb/run_sims.sh --icarus --tb-stream $(SIM_TB_STREAM) $(SIM_OUT)

sim-all: sim-gen
	$(SIM_ENV) tb/run_sims.sh --icarus --verilator --stream $(SIM_STREAM) --tb-stream $(SIM_TB_STREAM) $(SIM_OUT)

sim-matrix: build
	$(SIM_ENV) STREAM=$(SIM_STREAM) tb/sim_matrix.sh

# ---- Design (src/rtl, templates/): the default design into $(OUT); Verilator lint of its
# .v files (testbenches excluded; any warning fails); Yosys synthesis of rmap_top for the
# iCE40 (any latch fails; prints cells, memory bits and SB_RAM40_4K; logs in $(SYNTH_DIR)).
SYNTH_DIR ?= build/synth

.PHONY: generate lint synth

generate: build
	$(RMAPGEN) generate --out $(OUT)

# The default design and every golden design under golden/, each regenerated in place from
# the tb/config.toml it holds (the cargo tests fail when any of them differs).
golden: generate
	for d in golden/*/; do $(RMAPGEN) generate --config $$d/tb/config.toml --out $$d || exit 1; done

lint:
	@test -f $(OUT)/rmap_top.v || { echo "lint: no $(OUT)/rmap_top.v; run 'make generate'" >&2; exit 1; }
	cd $(OUT) && $(VERILATOR) --lint-only -Wall --top-module rmap_top *.v
	@echo "lint: $(OUT) is clean (verilator -Wall, no warnings)"

synth:
	YOSYS=$(YOSYS) scripts/synth.sh $(OUT) $(SYNTH_DIR)

# ---- Flow control: the default configuration with the valid/ready handshake (--handshake)
# into $(HS_OUT); its top testbench on $(SIM_TB_STREAM) vectors under random backpressure in
# Icarus and Verilator, and the C++ harness on $(SIM_STREAM) vectors with backpressure.
HS_OUT ?= build/rtl_handshake

.PHONY: sim-handshake

sim-handshake: build
	$(RMAPGEN) generate --out $(HS_OUT) --handshake $(GEN_FLAGS)
	$(SIM_ENV) tb/run_sims.sh --icarus --verilator --only rmap_top --stream $(SIM_STREAM) --tb-stream $(SIM_TB_STREAM) $(HS_OUT)

# ---- FPGA (src/rtl/fpga.rs): Yosys synth_ice40 and nextpnr-ice40 on $(OUT): post-route Fmax,
# logic cells, block RAMs, critical path; fails if a ROM or map bank is not in block RAM (a
# missed timing target is only reported). fpga-check also fails below $(FPGA_FREQ) MHz.
# Installs yosys, nextpnr-ice40 and fpga-icestorm when missing. Logs in $(FPGA_DIR).
FPGA_DEVICE  ?= hx8k
FPGA_PACKAGE ?= ct256
FPGA_FREQ    ?= 125
FPGA_SEED    ?= 1
FPGA_DIR     ?= build/fpga
FPGA_ARGS     = --dir $(OUT) --device $(FPGA_DEVICE) --package $(FPGA_PACKAGE) --freq $(FPGA_FREQ) --seed $(FPGA_SEED) --logs $(FPGA_DIR)

.PHONY: fpga fpga-check

fpga: build
	@WITH_FPGA=1 scripts/install-tools.sh
	YOSYS=$(YOSYS) $(RMAPGEN) fpga $(FPGA_ARGS)

fpga-check: build
	@WITH_FPGA=1 scripts/install-tools.sh
	YOSYS=$(YOSYS) $(RMAPGEN) fpga $(FPGA_ARGS) --require-timing

# ---- Waves: the top testbench of $(SIM_OUT) under Icarus with +vcd=, for GTKWave.
WAVE ?= build/wave/rmap_top.vcd

.PHONY: wave

wave: sim-gen
	@mkdir -p $(dir $(WAVE)) build/wave
	$(IVERILOG) -g2005 -Wall -Wno-timescale -s rmap_top_tb -o build/wave/rmap_top_tb.vvp $(SIM_OUT)/tb/rmap_top_tb.v $(filter-out $(SIM_OUT)/tb/%,$(wildcard $(SIM_OUT)/*.v))
	cd $(SIM_OUT) && $(VVP) -N $(abspath build/wave/rmap_top_tb.vvp) +vcd=$(abspath $(WAVE)) > $(abspath build/wave/run.log)
	@tail -n 1 build/wave/run.log
	@echo "wave: $(WAVE) (gtkwave $(WAVE))"
