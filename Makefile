# Thin wrapper: deps -> configure -> build -> run / test / bench.
BUILD  ?= build
CONFIG ?= configs/recuperative_drive/table1_sweep.yaml
OUT    ?= results
JOBS   ?= $(shell nproc)
MAKEFLAGS += --no-print-directory
# ccache (when present) shares objects between clones and worktrees.
export CCACHE_BASEDIR := $(CURDIR)
DEB_PACKAGES = cmake g++ make libeigen3-dev libnlopt-cxx-dev coinor-libipopt-dev \
  libsundials-dev libyaml-cpp-dev libgtest-dev libbenchmark-dev libcli11-dev \
  nlohmann-json3-dev pkg-config python3-numpy python3-scipy python3-mpmath

.PHONY: deps configure build run test bench clean

deps:
	@bash tools/install_deps.sh $(DEB_PACKAGES)

SUNDIALS_PREFIX = $(abspath $(BUILD))/sundials
configure: deps
	@bash tools/build_sundials.sh $(SUNDIALS_PREFIX)
	@mkdir -p $(BUILD)
	@echo "configure: cmake (log: $(BUILD)/configure.log)"
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release \
	  $$(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache) \
	  $$(test -f $(SUNDIALS_PREFIX)/lib/cmake/sundials/SUNDIALSConfig.cmake && \
	     echo -DSUNDIALS_DIR=$(SUNDIALS_PREFIX)/lib/cmake/sundials) \
	  > $(BUILD)/configure.log 2>&1 || (tail -n 30 $(BUILD)/configure.log; exit 1)

build: configure
	@echo "build: $(JOBS) jobs (log: $(BUILD)/build.log)"
	@cmake --build $(BUILD) -j $(JOBS) > $(BUILD)/build.log 2>&1 || \
	  (grep -E -A5 "error|Error" $(BUILD)/build.log | head -n 60; exit 1)

run: build
	$(BUILD)/bin/mechopt run $(CONFIG) --output $(OUT)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

bench: build
	/usr/bin/python3 bench/run_bench.py --build $(BUILD)

clean:
	rm -rf $(BUILD) $(OUT)
