# The two commands of the README. Everything else is CMake.
BUILD ?= build
JOBS  ?= $(shell nproc)
OUT   ?= runs/default

.PHONY: run test test-long deps configure build bench clean

deps:
	@bash scripts/setup-deps.sh

configure: deps
	@cmake --preset release -B $(BUILD) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# Set up, build, run the built-in default scenario (again: it replaces the earlier runs/default,
# never a folder fracflow did not make).
run: build
	@$(BUILD)/apps/cli/fracflow run --out $(OUT) --overwrite

# Set up, build, run the fast test suite.
test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE long

# Long validation runs (minutes to hours).
test-long: build
	@cd $(BUILD) && ctest --output-on-failure -L long

bench: build
	@$(BUILD)/benchmarks/dem_ucs
	@$(BUILD)/benchmarks/lbm
	@$(BUILD)/benchmarks/coupled
	@$(BUILD)/benchmarks/porenet

clean:
	rm -rf $(BUILD)
