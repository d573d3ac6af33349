# Thin wrapper: deps -> configure -> build -> run / test / bench.
BUILD  ?= build
CONFIG ?= configs/recuperative_drive/table1_sweep.yaml
OUT    ?= results
JOBS   ?= $(shell nproc)
MAKEFLAGS += --no-print-directory
# ccache (when present) shares objects between clones and worktrees.
export CCACHE_BASEDIR := $(CURDIR)
# What `make run` needs (the mechopt binary and its libraries; GoogleTest and
# Google Benchmark come with the machine, and the one configure finds them so
# `make test` never reconfigures), and what only the tests, the benchmarks
# and the peers add (`make test`, `make bench`).
RUN_PACKAGES = cmake g++ make pkg-config ccache libeigen3-dev libnlopt-cxx-dev \
  coinor-libipopt-dev libsundials-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev \
  libsqlite3-dev librandom123-dev libopenmpi-dev openmpi-bin libgtest-dev libbenchmark-dev
TEST_PACKAGES = python3-numpy python3-scipy python3-mpmath python3-yaml librsvg2-bin \
  python3-dev pybind11-dev python3-pytest python3-pandas python3-matplotlib libpagmo-dev

.PHONY: deps deps-test configure mechopt build run test install bench bench-smoke clean sanitize fuzz fuzz-linkage

deps:
	@bash tools/install_deps.sh $(RUN_PACKAGES)
deps-test:
	@bash tools/install_deps.sh $(RUN_PACKAGES) $(TEST_PACKAGES)

SUNDIALS_PREFIX = $(abspath $(BUILD))/sundials
# Extra cmake arguments for a new build directory, e.g. a package for any
# x86-64: make install BUILD=build-portable CMAKE_ARGS=-DMECHOPT_AVX2=OFF
CMAKE_ARGS ?=
IPOPT_HEADERS = $(abspath $(BUILD))/ipopt-internal/include
# Configured once: a build directory that has its CMakeCache.txt is left to
# cmake's own checks (it re-runs itself when a CMakeLists.txt changes), so
# `make test` after `make run` neither reconfigures nor rebuilds.
configure: deps $(BUILD)/CMakeCache.txt
$(BUILD)/CMakeCache.txt:
	@bash tools/build_sundials.sh $(SUNDIALS_PREFIX)
	@bash tools/ipopt_headers.sh $(IPOPT_HEADERS)
	@mkdir -p $(BUILD)
	@echo "configure: cmake (log: $(BUILD)/configure.log)"
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release \
	  $$(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache) \
	  $$(test -f $(SUNDIALS_PREFIX)/lib/cmake/sundials/SUNDIALSConfig.cmake && \
	     echo -DSUNDIALS_DIR=$(SUNDIALS_PREFIX)/lib/cmake/sundials) \
	  -DIPOPT_INTERNAL_INCLUDE=$(IPOPT_HEADERS) $(CMAKE_ARGS) \
	  > $(BUILD)/configure.log 2>&1 || (tail -n 30 $(BUILD)/configure.log; rm -f $@; exit 1)

# `mechopt` builds the command line and its libraries only; `build` the rest
# (tests, benchmarks) on top, into the same build directory.
mechopt: configure
	@echo "build: the mechopt target, $(JOBS) jobs (log: $(BUILD)/build.log)"
	@cmake --build $(BUILD) -j $(JOBS) --target mechopt > $(BUILD)/build.log 2>&1 || \
	  (grep -E -A5 "error|Error" $(BUILD)/build.log | head -n 60; exit 1)

# The Python module's and pagmo's packages come with deps-test: a build
# directory configured before them (`make run` first) looks for them again.
LOOK_AGAIN = if grep -qsE '^MECHOPT_(PYTHON|PAGMO)_MISSING:INTERNAL=1' $(BUILD)/CMakeCache.txt; then \
	  echo "configure: cmake again, for the Python module and pagmo (log: $(BUILD)/configure.log)"; \
	  cmake $(BUILD) >> $(BUILD)/configure.log 2>&1 || (tail -n 30 $(BUILD)/configure.log; exit 1); fi
build: configure deps-test
	@$(LOOK_AGAIN)
	@echo "build: everything, $(JOBS) jobs (log: $(BUILD)/build.log)"
	@cmake --build $(BUILD) -j $(JOBS) > $(BUILD)/build.log 2>&1 || \
	  (grep -E -A5 "error|Error" $(BUILD)/build.log | head -n 60; exit 1)

run: mechopt
	$(BUILD)/bin/mechopt run $(CONFIG) --output $(OUT)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The package (docs/package.md): the binary, shared libraries, headers, the
# CMake and pkg-config files and the Python module under PREFIX.
PREFIX ?= /usr/local
install: configure deps-test
	@$(LOOK_AGAIN)
	@echo "build: the binary, the libraries and the Python module, $(JOBS) jobs (log: $(BUILD)/build.log)"
	@cmake --build $(BUILD) -j $(JOBS) --target mechopt mechopt_mech mechopt_opt $$(grep -qs \
	  '^MECHOPT_PYTHON_MISSING:INTERNAL=0' $(BUILD)/CMakeCache.txt && echo _core) > $(BUILD)/build.log 2>&1 || \
	  (grep -E -A5 "error|Error" $(BUILD)/build.log | head -n 60; exit 1)
	cmake --install $(BUILD) --prefix $(PREFIX)

bench: build
	/usr/bin/python3 bench/run_bench.py --build $(BUILD)

# The benchmark gate of CI (~40 s): every same-run peer comparison, reduced,
# against bench/smoke_gates.json (ratios and errors; never absolute times).
bench-smoke: build
	/usr/bin/python3 bench/smoke.py --build $(BUILD)

# ASan + UBSan build in its own directory (-O1, no debug info, no benchmarks,
# no MPI: the MPI test runs in `make test` only),
# linked with the same SUNDIALS build, then the whole test suite with every
# finding fatal: abort_on_error turns a report into SIGABRT, which the CLI
# tests see as a signal. Leak suppressions: tools/lsan.supp (docs/testing.md).
ASAN_BUILD ?= build-asan
SAN_ENV = ASAN_OPTIONS=halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1 \
  UBSAN_OPTIONS=halt_on_error=1:abort_on_error=1:print_stacktrace=1 \
  LSAN_OPTIONS=suppressions=$(CURDIR)/tools/lsan.supp:print_suppressions=0
sanitize: deps-test
	@bash tools/build_sundials.sh $(SUNDIALS_PREFIX)
	@bash tools/ipopt_headers.sh $(IPOPT_HEADERS)
	@mkdir -p $(ASAN_BUILD) && echo '*' > $(ASAN_BUILD)/.gitignore  # git ignores the whole dir
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Release -DMECHOPT_SANITIZE=ON -DMECHOPT_BENCH=OFF -DMECHOPT_MPI=OFF \
	  $$(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache) \
	  $$(test -f $(SUNDIALS_PREFIX)/lib/cmake/sundials/SUNDIALSConfig.cmake && \
	     echo -DSUNDIALS_DIR=$(SUNDIALS_PREFIX)/lib/cmake/sundials) \
	  -DIPOPT_INTERNAL_INCLUDE=$(IPOPT_HEADERS)
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	cd $(ASAN_BUILD) && $(SAN_ENV) ctest --output-on-failure -j $(JOBS) -E '^DoeMpi\.'

# Config fuzzer on the Release binary: N mutants of the configs FUZZ_CONFIGS
# matches (all of configs/ by default) from SEED (tools/fuzz_configs.py;
# failing mutants kept in FUZZ_OUT). `make fuzz-linkage`: the linkage
# descriptions alone, whose nested keys leave fewer mutants that still load
# (47-52% reach an evaluation over seeds 1-3, gate 40%; every mutant must pass).
N            ?= 300
SEED         ?= 1
FUZZ_OUT     ?= $(BUILD)/fuzz
FUZZ_CONFIGS ?= configs/**/*.yaml
FUZZ_REACHED ?= 0.5
fuzz: build
	/usr/bin/python3 tools/fuzz_configs.py --binary $(BUILD)/bin/mechopt -n $(N) --seed $(SEED) \
	  --jobs $(JOBS) --out $(FUZZ_OUT) --configs '$(FUZZ_CONFIGS)' --min-reached $(FUZZ_REACHED)
fuzz-linkage:
	@$(MAKE) fuzz FUZZ_CONFIGS='configs/linkage/*.yaml' FUZZ_REACHED=0.4 FUZZ_OUT=$(BUILD)/fuzz-linkage

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(OUT)
