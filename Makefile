# Entry points. `make demo` and `make test` work on a fresh Debian 12 machine: both install what is
# missing (scripts/install-deps.sh), configure and build first.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
SEGMESH := $(BUILD_DIR)/apps/cli/segmesh
DEMO_DIR ?= out/demo

.PHONY: all deps configure build python test demo bench clean sanitize fuzz

all: build

deps:
	@bash scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The Python package alone (docs/PYTHON.md): $(BUILD_DIR)/python/segmesh, imported with
# PYTHONPATH=$(BUILD_DIR)/python; `make test` builds it with everything else and runs its tests.
python: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target segmesh_python

# After the normal suite, the same suite under AddressSanitizer + UndefinedBehaviorSanitizer
# (`make sanitize`): measured at about 19 minutes for both builds and both runs from a clean clone on
# 2 cores (docs/ROBUSTNESS.md). SANITIZE=0 skips it.
SANITIZE ?= 1
test: build
	@ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS)
ifneq ($(SANITIZE),0)
	@$(MAKE) --no-print-directory sanitize
endif

# The main job on the built-in phantom: a fractured tibia and fibula with a plate and screws.
demo: build
	@mkdir -p $(DEMO_DIR)
	$(SEGMESH) phantom -o $(DEMO_DIR)/phantom.nii.gz
	$(SEGMESH) mesh $(DEMO_DIR)/phantom.nii.gz -o $(DEMO_DIR)/phantom.glb --report $(DEMO_DIR)/report.json
	$(SEGMESH) mesh $(DEMO_DIR)/phantom.nii.gz -o $(DEMO_DIR)/parts/ --format stl --quiet
	@echo
	@echo "demo: the phantom volume      $(DEMO_DIR)/phantom.nii.gz"
	@echo "demo: all parts in one scene  $(DEMO_DIR)/phantom.glb"
	@echo "demo: one STL file per part   $(DEMO_DIR)/parts/"
	@echo "demo: the JSON report         $(DEMO_DIR)/report.json"

clean:
	rm -rf $(BUILD_DIR) out

# AddressSanitizer + UndefinedBehaviorSanitizer over the whole test suite (docs/ROBUSTNESS.md):
# its own build folder, RelWithDebInfo with -O1 -g1 (line tables: what the reports need; half the
# compile time of -O2 -g, and the sanitizer build is most of make test), without the measurement
# programs of bench/ (no test runs them), and
# -fsanitize=address,undefined -fno-sanitize-recover=undefined. Leaks are reported except inside
# the third-party libraries listed (with the reason) in fuzz/lsan.supp (Mesa's OpenGL drivers,
# ITK's NRRD reader).
# SANITIZE_CTEST_ARGS passes extra ctest arguments (e.g. -E to leave tests out).
ASAN_BUILD_DIR ?= build-asan
SANITIZE_CTEST_ARGS ?=
ASAN_CHECKS := strict_string_checks=1:detect_stack_use_after_return=1
SANITIZER_ENV := ASAN_OPTIONS=detect_leaks=1:$(ASAN_CHECKS) \
	LSAN_OPTIONS=suppressions=$(CURDIR)/fuzz/lsan.supp:print_suppressions=0 \
	UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

# A failing test is run up to twice more (--repeat until-pass:3; earlier attempts' output stays in
# the log): LeakSanitizer's own stop-the-world tracer now and then crashes at process exit ("Tracer
# caught signal 11 ... LeakSanitizer has encountered a fatal error", google/sanitizers#1353) after
# the test itself has passed, seen in the renderer's tests while Mesa's threads shut down. A real
# failure fails both times.
# The viewer's smoke tests run without leak detection: Mesa's GLX/DRI drivers, unloaded before
# LeakSanitizer looks, leave allocations whose stacks are "<unknown module>" and cannot be named in
# a suppression (docs/ROBUSTNESS.md); every other sanitizer check stays on for them.
VIEWER_SMOKE := ViewerSmoke
SANITIZER_CTEST = ctest --test-dir $(ASAN_BUILD_DIR) --output-on-failure -j $(JOBS) --repeat until-pass:3
sanitize: deps
	@cmake -S . -B $(ASAN_BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
		-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
		-DSEGMESH_SANITIZE=ON -DSEGMESH_BUILD_BENCH=OFF >/dev/null
	@cmake --build $(ASAN_BUILD_DIR) -j $(JOBS)
	@$(SANITIZER_ENV) $(SANITIZER_CTEST) -E '$(VIEWER_SMOKE)' $(SANITIZE_CTEST_ARGS)
	@$(SANITIZER_ENV) ASAN_OPTIONS=detect_leaks=0:$(ASAN_CHECKS) $(SANITIZER_CTEST) -R '$(VIEWER_SMOKE)' \
		--no-tests=ignore

# libFuzzer targets for every reader, FUZZ_SECONDS each (scripts/fuzz.sh; needs clang:
# scripts/install-deps.sh --with-fuzz). Not part of `make test`.
FUZZ_SECONDS ?= 60
fuzz:
	@bash scripts/install-deps.sh --with-fuzz
	@bash scripts/fuzz.sh $(FUZZ_SECONDS)
