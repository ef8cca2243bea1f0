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

# Installs iverilog, verilator and yosys with apt-get when missing (a fresh machine has none).
tools:
	@scripts/install-tools.sh

cargo-test:
	$(CARGO) test

# Only the $$readmemh files of the default design, refreshed in place in $(OUT).
roms: build
	$(RMAPGEN) roms --out build/roms
	cp build/roms/*.hex $(OUT)/

# Everything: cargo tests (model, golden rtl_out/, vectors, CLI errors, sampled stress), Verilator
# lint, Yosys synthesis, and every testbench in Icarus and Verilator plus the 1M-vector harness.
test: tools cargo-test lint synth sim-all
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

lint:
	@test -f $(OUT)/rmap_top.v || { echo "lint: no $(OUT)/rmap_top.v; run 'make generate'" >&2; exit 1; }
	cd $(OUT) && $(VERILATOR) --lint-only -Wall --top-module rmap_top *.v
	@echo "lint: $(OUT) is clean (verilator -Wall, no warnings)"

synth:
	YOSYS=$(YOSYS) scripts/synth.sh $(OUT) $(SYNTH_DIR)
