# swirl: the two commands.
#
#   make demo   install what is missing (Debian packages), build, run the default scene
#   make test   install what is missing, build, run every test with CTest, then the
#               parallel tests under ThreadSanitizer and a fuzz smoke run (60 s per target)
#
# Other targets: mpi (swirl with OpenMPI: mpirun -n 4 build/swirl ...), python (the Python module into build-python/venv; docs/python.md),
# browser-deps (the browser test's npm packages, tests/browser/),
# python-test (pytest; part of test), build, bench (the seeds' experiments -> docs/performance.md), unit-test (CTest only), asan-test (tests under
# AddressSanitizer+UBSan, long tests skipped), tsan-test (the parallel tests
# under ThreadSanitizer), fuzz (libFuzzer smoke run; FUZZ_SECONDS=600 for
# longer), debug, clean, deps.

PRESET   ?= release
JOBS     ?= $(shell nproc)
DEMO     ?= examples/dam_break.toml
DEMO_OUT ?= out/demo

# Debian 12 packages: what building the swirl tool needs (all `make demo`
# installs; FreeType, libpng and the font are for `swirl render`, which is part
# of the tool, HDF5 for its snapshots, Assimp for the mesh obstacles' STL and OBJ files, Boost.Beast for swirl view's
# server), and what only the tests, micro-benchmarks
# and bench plots need (python3-h5py: an independent HDF5 writer for the tests).
DEB_BUILD_PACKAGES := cmake ninja-build g++ make git pkg-config \
                      libtomlplusplus-dev libcli11-dev libfmt-dev \
                      libxsimd-dev libpng-dev libfreetype-dev fonts-dejavu-core libhdf5-dev \
                      libassimp-dev libboost-dev libboost-system-dev ccache
# OpenMPI for distributed runs and parallel HDF5 for their frames (make mpi;
# the tests run under mpirun). Not the demo's.
DEB_MPI_PACKAGES   := libopenmpi-dev openmpi-bin libhdf5-openmpi-dev
# python3-venv, python3-dev and python3-numpy: the Python module's venv (make python).
# chromium and nodejs: the browser test of swirl view's page (tests/browser/; its npm
# packages come from its lock file, browser-deps).
DEB_TEST_PACKAGES  := libgtest-dev libbenchmark-dev python3-matplotlib python3-venv python3-dev python3-numpy \
                      python3-h5py chromium nodejs $(DEB_MPI_PACKAGES)
DEB_PACKAGES       := $(DEB_BUILD_PACKAGES) $(DEB_TEST_PACKAGES)

SUDO := $(shell [ "$$(id -u)" -eq 0 ] || echo sudo)

# ccache (installed by deps) under every compiler CMake configures, with paths
# taken relative to this folder: build/ and build-demo/ then share their objects
# (same flags, same depth), so `make demo` after `make test` compiles nothing again.
ifneq ($(shell command -v ccache),)
export CMAKE_CXX_COMPILER_LAUNCHER ?= ccache
export CCACHE_BASEDIR ?= $(CURDIR)
endif

.PHONY: all deps deps-build deps-mpi mpi browser-deps configure build test unit-test python python-test demo bench asan-test tsan-test fuzz debug clean

all: build

# deps-build installs what building the tool needs; deps adds the test-only packages.
deps: PACKAGES = $(DEB_PACKAGES)
deps-build: PACKAGES = $(DEB_BUILD_PACKAGES)
deps-mpi: PACKAGES = $(DEB_BUILD_PACKAGES) $(DEB_MPI_PACKAGES)
deps deps-build deps-mpi:
	@missing=""; \
	for p in $(PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "swirl: installing Debian packages:$$missing"; \
	  $(SUDO) apt-get update -q && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -q --no-install-recommends $$missing; \
	fi

configure: deps
	cmake --preset $(PRESET)

build: configure
	cmake --build --preset $(PRESET) -j $(JOBS)

test: unit-test python-test tsan-test fuzz

# swirl with MPI (OpenMPI from Debian) in build/: mpirun -n 4 build/swirl run SCENE
# (docs/design/mpi.md says what runs distributed so far).
mpi: deps-mpi
	cmake --preset $(PRESET) -DSWIRL_MPI=ON
	cmake --build --preset $(PRESET) -j $(JOBS) --target swirl_cli
	@echo "swirl with MPI: mpirun -n 2 build$(if $(filter-out release,$(PRESET)),-$(PRESET))/swirl info"

# The browser test's harness (tests/browser/: puppeteer-core, which downloads no
# browser: the test drives Debian's chromium) from its lock file, again only when
# the lock file changed. npm: NodeSource's nodejs bundles it, Debian's has it apart.
browser-deps: deps
	@command -v npm >/dev/null || { $(SUDO) apt-get update -q && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -q --no-install-recommends npm; }
	@[ tests/browser/node_modules/.package-lock.json -nt tests/browser/package-lock.json ] || \
	  (cd tests/browser && npm ci --no-audit --no-fund --ignore-scripts)

unit-test: build browser-deps
	ctest --preset $(PRESET)
	bash tools/check_simd_objects.sh build$(if $(filter-out release,$(PRESET)),-$(PRESET))

# The Python module (python/, docs/python.md), built by `pip install .` into a
# venv of Debian's Python (/usr/bin/python3 with its numpy and matplotlib; the
# python3 on PATH may be another): build-python/venv, CMake tree in
# build-python/build (position-independent libraries; the CLI's trees are untouched),
# with the release preset's -march=native, so its results are the release CLI's bit for bit.
PY_VENV := build-python/venv
python: deps
	@[ -x $(PY_VENV)/bin/python ] || /usr/bin/python3 -m venv --system-site-packages $(PY_VENV)
	$(PY_VENV)/bin/pip install -q -r python/requirements-dev.txt
	CMAKE_BUILD_PARALLEL_LEVEL=$(JOBS) $(PY_VENV)/bin/pip install -q --no-build-isolation \
	  --config-settings=build-dir=build-python/build --config-settings=cmake.define.SWIRL_NATIVE=ON $(if $(CMAKE_CXX_COMPILER_LAUNCHER),--config-settings=cmake.define.CMAKE_CXX_COMPILER_LAUNCHER=$(CMAKE_CXX_COMPILER_LAUNCHER)) .

# pytest on the installed module; the CLI of `make build` is the reference of
# the byte-identical frames test.
python-test: python build
	SWIRL_CLI=$(CURDIR)/build/swirl $(PY_VENV)/bin/python -m pytest -q python/tests

# The demo builds only the tool, in its own tree (preset demo: release, tests
# off, build-demo/), so a fresh machine neither installs nor compiles the test
# suite and micro-benchmarks it does not run.
demo: deps-build
	cmake --preset demo
	cmake --build --preset demo -j $(JOBS) --target swirl_cli
	./build-demo/swirl run $(DEMO) --out $(DEMO_OUT) --overwrite
	@echo "Open $(DEMO_OUT)/particles.pvd in ParaView."

# The seeds' experiments at their default sizes (each suite's CSV, JSON,
# markdown and plots into bench/results/<suite>/), then docs/performance.md
# regenerated from them. About 30 min on the 2-core machine, of which bh-opt
# (the paper tree built at -O0..-O3, apps/bh_opt) about 2 min to build and 5 to run.
BENCH_OUT ?= bench/results
bench: build
	./build/swirl bench sph-table --strategy hash,hash+serial,hash+serial+precomputed+after_distance,grid --out $(BENCH_OUT)/sph-table
	./build/swirl bench hash-stats --out $(BENCH_OUT)/hash-stats
	./build/swirl bench bh-table --out $(BENCH_OUT)/bh-table
	./build/swirl bench bh-lambda --out $(BENCH_OUT)/bh-lambda
	./build/swirl bench bh-phases --out $(BENCH_OUT)/bh-phases
	cmake --build build -j $(JOBS) --target swirl_bh_opt
	./build/swirl bench bh-opt --out $(BENCH_OUT)/bh-opt
	/usr/bin/python3 tools/update_performance.py --results $(BENCH_OUT)

asan-test: deps
	cmake --preset asan
	cmake --build --preset asan -j $(JOBS)
	ctest --preset asan

tsan-test: deps
	bash .ci/tsan.sh

fuzz: deps
	bash .ci/fuzz.sh

debug: deps
	cmake --preset debug
	cmake --build --preset debug -j $(JOBS)

clean:
	rm -rf build build-demo build-debug build-asan build-tsan build-fuzz build-portable build-python out
