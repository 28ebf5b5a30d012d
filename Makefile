# caplab — top-level commands. See README.md.
#   make reproduce            whole catalogue at fidelity "quick", then the report
#   make reproduce-chapterN   one chapter (default fidelity "standard"; FIDELITY=thesis to change)
#   make reproduce-extra      the external validations that are not thesis cases (catalogue/extra)
#   make test                 unit + verification + short validation (what CI runs)
#   make bench | stress | report | clean

SHELL := /bin/bash
BUILD ?= build
JOBS ?= 2
PYTHON := /usr/bin/python3
CAPLAB := $(BUILD)/solver/app/caplab
RESULTS ?= results

.PHONY: all deps build test reproduce report bench stress clean \
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

reproduce-chapter%: build
	@scripts/reproduce --caplab $(CAPLAB) --fidelity $(or $(FIDELITY),standard) --results $(RESULTS) catalogue/ch$*

reproduce-extra: build
	@scripts/reproduce --caplab $(CAPLAB) --fidelity $(or $(FIDELITY),standard) --results $(RESULTS) catalogue/extra

report:
	@scripts/report --results $(RESULTS)

bench: build
	@$(CAPLAB) bench --out reports/out/bench

stress:
	@echo "make stress: not yet (issue 'Numerical stability and robustness')"; exit 1

clean:
	rm -rf $(BUILD) $(RESULTS) reports/out
