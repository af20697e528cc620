# Entry points for people and CI. Everything builds into build/ with Ninja.
BUILD ?= build
JOBS ?= 2
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release

.PHONY: all deps configure build demo test test-sanitize test-cluster fuzz bench install package format format-check clean

all: build

deps:
	@bash scripts/install-deps

$(BUILD)/build.ninja: | deps
	cmake -S . -B $(BUILD) -G Ninja $(CMAKE_FLAGS)

configure: $(BUILD)/build.ninja

build: configure
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	@mkdir -p out
	bash scripts/demo

test: build format-check
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The sanitizer job (docs/testing.md): plant and the unit tests built with ASan and UBSan into
# build-asan/, the tests, the hostile inputs and the mutation fuzzer run on them (docs/testing.md).
test-sanitize: | deps
	bash scripts/test-sanitize

# A single-node Slurm (Debian's slurm-wlm and munge, installed when missing, started by hand in a
# scratch folder) runs examples/cluster/roses.sbatch as 4 array tasks; the merged manifest and the
# roses must be those of one run (docs/batch.md). Needs root; not part of make test.
test-cluster: build
	bash scripts/test-cluster

# The libFuzzer targets (docs/testing.md), built with clang into build-fuzz/, each run for
# FUZZ_SECONDS seconds; a finding fails it and is saved in build-fuzz/findings/.
FUZZ_SECONDS ?= 60
fuzz: | deps
	FUZZ_SECONDS=$(FUZZ_SECONDS) bash scripts/fuzz

# bench/run (the derivation, meshing and end-to-end figures), bench/run-batch (1,000 roses on 1
# and 2 jobs), bench/run-peers (against cpfg and lpfg; skipped when they cannot be built) and
# bench/run-glb (plant run against a hand-written GLB writer); fails when one misses a target.
bench: build
	@bash scripts/install-deps --bench
	status=0; bash bench/run || status=1; bash bench/run-batch || status=1; \
	bash bench/run-peers || status=1; bash bench/run-glb || status=1; exit $$status

# Installing and packaging (docs/install.md): plant, plant view's server module (lib/plant/),
# its standard library, docs, man page and the C++ API under PREFIX; the Debian packages plant
# and plant-dev into $(BUILD)/.
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD) --prefix $(PREFIX)

package: build
	cd $(BUILD) && cpack -G DEB

# Every tracked C++ file, formatted by .clang-format (Debian's clang-format 14, from install-deps).
FORMAT_FILES = git ls-files -z -- '*.cpp' '*.hpp' '*.h'

format:
	$(FORMAT_FILES) | xargs -0 clang-format -i

format-check: | deps
	@$(FORMAT_FILES) | xargs -0 clang-format --dry-run --Werror \
	  || { echo "format-check: run 'make format' and commit the result" >&2; exit 1; }

clean:
	rm -rf $(BUILD) build-asan build-fuzz out
