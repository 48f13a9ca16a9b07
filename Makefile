# Entry points. `make demo` and `make test` work on a fresh Debian 12 machine: both install what is
# missing (scripts/install-deps.sh), configure and build first.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
SEGMESH := $(BUILD_DIR)/apps/cli/segmesh
DEMO_DIR ?= out/demo

.PHONY: all deps configure build test demo bench clean

all: build

deps:
	@bash scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	@ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS)

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
