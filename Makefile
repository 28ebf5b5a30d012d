# caplab — top-level commands. See README.md.
#   make reproduce            whole catalogue at fidelity "quick", then the report
#   make reproduce-chapterN   one chapter (default fidelity "standard"; FIDELITY=thesis to change)
#   make reproduce-extra      the external validations that are not thesis cases (catalogue/extra)
#   make test                 unit + verification + short validation (what CI runs)
#   make fuzz                 fuzz the case loader (opt-in clang build in build-fuzz; FUZZ_SECONDS=600)
#   make bench                bench.json + the page reports/out/bench/ (ERROR_SERIES=quick|full runs the error series first)
#   make bench-error          the full run-time-against-error series (hours), then the bench page
#   make stress | report | clean

SHELL := /bin/bash
BUILD ?= build
JOBS ?= 2
PYTHON := /usr/bin/python3
CAPLAB := $(BUILD)/solver/app/caplab
RESULTS ?= results

.PHONY: all deps build test reproduce report bench bench-error stress clean \
        reproduce-chapter2 reproduce-chapter3 reproduce-chapter4 reproduce-chapter5 reproduce-chapter6 \
        reproduce-extra

all: build

deps:
	@scripts/install-deps

$(BUILD)/CMakeCache.txt: | deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release > /dev/null

build: deps $(BUILD)/CMakeCache.txt
	@cmake --build $(BUILD) -j $(JOBS)

test: build
	@scripts/run-tests $(BUILD)

reproduce: build
	@scripts/reproduce --caplab $(CAPLAB) --fidelity $(or $(FIDELITY),quick) --results $(RESULTS) catalogue

# A static pattern rule: make skips implicit (pattern) rules for .PHONY targets, so a plain
# `reproduce-chapter%:` rule made `make reproduce-chapter2` do nothing at all.
CHAPTER_TARGETS := reproduce-chapter2 reproduce-chapter3 reproduce-chapter4 reproduce-chapter5 reproduce-chapter6
$(CHAPTER_TARGETS): reproduce-chapter%: build
	@scripts/reproduce --caplab $(CAPLAB) --fidelity $(or $(FIDELITY),standard) --results $(RESULTS) catalogue/ch$*

reproduce-extra: build
	@scripts/reproduce --caplab $(CAPLAB) --fidelity $(or $(FIDELITY),standard) --results $(RESULTS) catalogue/extra

report: build
	@scripts/report --results $(RESULTS) --caplab $(CAPLAB)

BENCH_OUT ?= reports/out/bench
ERROR_RESULTS ?= $(RESULTS)/bench-error
BENCH_ARGS ?=

# make bench: caplab bench, then the page; the error series only when asked (it takes hours at
# ERROR_SERIES=full; quick is a few minutes). A point that fails does not stop the page.
bench: build
	@$(CAPLAB) bench --out $(BENCH_OUT) $(BENCH_ARGS)
	@$(if $(filter quick,$(ERROR_SERIES)),scripts/bench-error --caplab $(CAPLAB) --results $(ERROR_RESULTS) --quick --no-report || true)
	@$(if $(filter full,$(ERROR_SERIES)),scripts/bench-error --caplab $(CAPLAB) --results $(ERROR_RESULTS) --no-report || true)
	@PYTHONPATH=reports $(PYTHON) -m caplab_report.bench --bench $(BENCH_OUT)/bench.json --out $(BENCH_OUT) --results $(RESULTS) \
	  --error-results $(ERROR_RESULTS) --error-mode $(or $(ERROR_SERIES),auto)

bench-error: build
	@scripts/bench-error --caplab $(CAPLAB) --results $(ERROR_RESULTS) --bench-out $(BENCH_OUT)

stress: build
	@scripts/stress --caplab $(CAPLAB) --out reports/out/stress

clean:
	rm -rf $(BUILD) $(RESULTS) reports/out

# make fuzz: libFuzzer on the case loader (tests/fuzz/fuzz_case.cpp; clang with ASan and UBSan, its
# own build directory), seeded with every catalogue case and tests/fuzz/seeds, for FUZZ_SECONDS in
# one process (one core). Inputs that crash, hang or leak go to tests/fuzz/crashes/ (not in git);
# replay one with `$(FUZZ_BUILD)/tests/fuzz/fuzz_case FILE`. Opt-in: not part of `make build`.
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 600
FUZZ_CORPUS ?= $(FUZZ_BUILD)/corpus

.PHONY: fuzz
fuzz:
	@CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=Debug -DCAPLAB_FUZZ=ON \
	  -DCAPLAB_BUILD_TESTS=OFF > /dev/null
	@cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_case
	@mkdir -p $(FUZZ_CORPUS) tests/fuzz/crashes
	@find catalogue -name '*.json' ! -name schema.json | while read -r f; do \
	  cp -n "$$f" "$(FUZZ_CORPUS)/seed_$$(echo "$$f" | tr / _)"; done
	@cp -n tests/fuzz/seeds/* tests/fuzz/regressions/* $(FUZZ_CORPUS)/
	@set -o pipefail; $(FUZZ_BUILD)/tests/fuzz/fuzz_case $(FUZZ_CORPUS) -dict=tests/fuzz/case.dict \
	  -max_total_time=$(FUZZ_SECONDS) -timeout=10 -rss_limit_mb=2048 -artifact_prefix=tests/fuzz/crashes/ \
	  -print_final_stats=1 2>&1 | tee $(FUZZ_BUILD)/fuzz.log | \
	  grep --line-buffered -E 'pulse|INITED|DONE|ERROR|BUG|SUMMARY|Test unit written|stat::number_of_executed_units|Done [0-9]+ runs'
