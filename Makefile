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

roms: build
	$(RMAPGEN) roms --out $(OUT)/roms

test: tools cargo-test
