# Thin wrapper around CMake. `make test` and `make demo` work on a fresh Debian 12 machine.
BUILD   ?= build
JOBS    ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps configure build test demo ablation baselines ladder map-update bench fuzz clean format pretrained regen

all: build

deps:
	@bash cmake/install-deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

configure: $(BUILD)/CMakeCache.txt

build: deps configure
	cmake --build $(BUILD) -j $(JOBS)

# After ctest: only an optional tool may skip a test (tests/repo/check_skips.py).
test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)
	/usr/bin/python3 tests/repo/check_skips.py $(BUILD)/Testing/Temporary/LastTest.log

demo: build
	@bash scripts/demo.sh $(BUILD)

ablation: build
	@bash scripts/ablation.sh $(BUILD)

baselines: build
	@bash scripts/baselines.sh $(BUILD)

ladder: build
	@bash scripts/ladder.sh $(BUILD)

# The demo world in map-update mode and its copy-the-prior baseline (scripts/map_update.sh).
map-update: build
	@bash scripts/map_update.sh $(BUILD)

bench: build
	@bash scripts/bench.sh $(BUILD)

# Rewrites every file generated from the declarations: config schemas, samples/*.json
# defaults, docs/options.md, samples/semantic-classes.json (scripts/regen.sh; ctest
# repo/regen fails when one is stale).
regen: build
	@bash scripts/regen.sh $(BUILD)

# Retrains the LaneGraphNet shipped in samples/models/ and holds its score to the band of
# seeds its record keeps (scripts/pretrained_model.sh; --band N measures the band).
pretrained: build
	@bash scripts/pretrained_model.sh $(BUILD)

# libFuzzer targets in a clang build (scripts/fuzz.sh); FUZZ_SECONDS=10 for a CI smoke run.
FUZZ_BUILD   ?= build-fuzz
FUZZ_SECONDS ?= 60
fuzz: deps
	@FUZZ_SECONDS=$(FUZZ_SECONDS) JOBS=$(JOBS) BUILD=$(BUILD) bash scripts/fuzz.sh $(FUZZ_BUILD)

clean:
	rm -rf $(BUILD)

format:
	clang-format -i $$(git ls-files '*.cpp' '*.h')
