# Two commands for a fresh clone: `make demo` and `make test`. Both install what they need.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: deps build demo test bench bench-quick clean

deps:
	@bash scripts/install-deps.sh

build: deps
	cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)
	cmake --build $(BUILD_DIR) -j $(JOBS)

# Exact distances on the built-in bumpy torus from vertex 0, with a summary.
demo: build
	$(BUILD_DIR)/cli/exactgeo distance @torus --source 0

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)
	python3 -m pip install -q -r bench/requirements-test.txt
	python3 -m pytest -q bench

# Timings against the other solvers, written to bench/results/ (see bench/README.md).
bench: build
	python3 -m pip install -q -r bench/requirements.txt
	python3 bench/run.py --build-dir $(BUILD_DIR)
	python3 bench/many_sources.py --build-dir $(BUILD_DIR)

bench-quick: build
	python3 -m pip install -q -r bench/requirements.txt
	python3 bench/run.py --quick --build-dir $(BUILD_DIR)

clean:
	rm -rf $(BUILD_DIR)
