# The two commands a newcomer needs: `make report` and `make test`.
# Both create .venv when missing and install the package with the pinned
# versions of constraints.txt (so reports are reproduced byte for byte).
SHELL  := /bin/bash
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
WB     := $(VENV)/bin/workbench
STAMP  := $(VENV)/.installed
# One OpenBLAS thread: the core count must not change the rounding.
export OPENBLAS_NUM_THREADS ?= 1
# A second CPU's BLAS kernels (no FMA): the report check must hold under it too.
OTHER_KERNEL ?= Sandybridge

.PHONY: install report test test-full test-wheel bench clean

$(STAMP): pyproject.toml constraints.txt
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	# the distribution was named "workbench" before (an unrelated project's name on the index)
	$(PY) -m pip uninstall -q -y workbench 2>/dev/null || true
	$(PY) -m pip install -q -c constraints.txt -e '.[test,fast,scale]'
	touch $(STAMP)

# The compiled kernels compile once per machine and source (issue 36): here, not
# in the timed check (a few seconds when the disk cache is already warm). So does
# the bytecode of the package and the tests: written here, it is read by every
# process of the check and of the test session, even where PYTHONDONTWRITEBYTECODE
# is set (then each process would compile every module it imports, about 3.5 CPU s
# per test worker); compileall skips a module whose bytecode is current.
install: $(STAMP)
	@$(PY) -m compileall -q workbench tests
	@$(PY) -m workbench.papers.p003.antiskid_warm

## main job: every shipped design -> reports/<design>.md, figures, index
report: install
	$(WB) report --all --jobs $(JOBS)

## The five-minute check: every claim of every design and proof, the report
## freshness check (Markdown and figures) and the unit tests, on every core.
## `workbench check --jobs $(JOBS)` runs each study once (a pool of processes)
## and leaves the results in a run folder; the test session (pytest-xdist,
## $(JOBS) workers, tests marked `slow` deselected: `make test-full`) reads
## them instead of computing them again. The test session starts with the
## check: its workers import and collect the tests meanwhile (on the core the
## check's last tasks leave idle) and the first test runs once the check is
## done (WORKBENCH_TESTS_AFTER names the file that says so, tests/conftest.py;
## the check creates it as soon as every study result is in the run folder,
## WORKBENCH_STUDIES_DONE, and it is created when the check ends in any case;
## an interrupted `make test` ends the waiting session: it ignores Ctrl-C).
## Ends with the wall time and the five slowest studies and tests.
# the lines of a check's output shown: problems, summaries and the claims not ok
NOT_OK := awk '!/^\| / || /✗/'
JOBS ?= $(shell $(PYTHON) -c "import os; print(max(1, len(os.sched_getaffinity(0))))")
test: install
	@t0=$$(date +%s); run=$$(mktemp -d); times=$$(mktemp); log=$$(mktemp); \
	WORKBENCH_STUDY_CACHE=$$run WORKBENCH_TESTS_AFTER=$$log.done $(PY) -m pytest -n $(JOBS) \
	  -m "not slow and not wheel" --durations=5 -p no:cacheprovider > $$log 2>&1 & pid=$$!; \
	trap 'kill $$pid 2>/dev/null' EXIT; trap 'exit 130' INT TERM; \
	echo "== workbench check --jobs $(JOBS) (every claim, report freshness)"; \
	WORKBENCH_STUDY_CACHE=$$run WORKBENCH_STUDIES_DONE=$$log.done $(WB) check --jobs $(JOBS) \
	  2> $$times | $(NOT_OK); \
	  checked=$${PIPESTATUS[0]}; touch $$log.done; \
	echo "== check done after $$(( $$(date +%s) - t0 )) s"; \
	echo "== pytest -n $(JOBS) (not slow; collected while the check ran)"; \
	tail -n +1 -f --pid=$$pid $$log; wait $$pid; tests=$$?; trap - EXIT; \
	rm -rf $$run $$log $$log.done; \
	echo; echo "== five slowest studies (workbench check; the whole table: workbench check --jobs $(JOBS))"; \
	grep -A 6 -- '| task | kind | wall s | cpu s |' $$times | sed 's/.*\(| task | kind\)/\1/'; \
	grep -v '^|\|^$$\|per-task time' $$times; rm -f $$times; \
	echo "workbench check exit $$checked, pytest exit $$tests; make test: $$(( $$(date +%s) - t0 )) s wall"; \
	test $$checked -eq 0 && test $$tests -eq 0

## The full tier: the slow tests; the check again under another CPU's BLAS
## kernels ($(OTHER_KERNEL)), with every physical input moved +3 ulp, and
## moved -3 ulp with numpy's widest SIMD loops switched off (the features
## tests/simd_features.py finds on this CPU); each must find every report
## byte-identical; the golden report under $(OTHER_KERNEL).
test-full: install
	@t0=$$(date +%s); \
	echo "== pytest -n $(JOBS) -m slow (the fuzz campaign next, alone)"; \
	$(PY) -m pytest -n $(JOBS) --dist load -m "slow and not wheel" --durations=10 -p no:cacheprovider \
	  --deselect tests/test_fuzz.py::test_fuzz_full; slow=$$?; \
	echo "== the seeded fuzz campaign, alone: its 120 s limit per run is wall time, which"; \
	echo "   other slow tests on the same cores would stretch (issue 32)"; \
	$(PY) -m pytest -q -p no:cacheprovider -m slow tests/test_fuzz.py::test_fuzz_full; fuzz=$$?; \
	echo "== workbench check under OPENBLAS_CORETYPE=$(OTHER_KERNEL)"; \
	OPENBLAS_CORETYPE=$(OTHER_KERNEL) $(WB) check --jobs $(JOBS) 2>/dev/null | $(NOT_OK); \
	  other=$${PIPESTATUS[0]}; \
	echo "== golden report under OPENBLAS_CORETYPE=$(OTHER_KERNEL)"; \
	OPENBLAS_CORETYPE=$(OTHER_KERNEL) $(PY) -m pytest -q -p no:cacheprovider \
	  tests/test_cli_and_reports.py::test_golden_report; golden=$$?; \
	echo "== last-bit perturbation: every physical input moved +3 ulp"; \
	WORKBENCH_PERTURB_ULPS=3 $(WB) check --jobs $(JOBS) 2>/dev/null | $(NOT_OK); up=$${PIPESTATUS[0]}; \
	simd=$$($(PY) tests/simd_features.py); \
	echo "== -3 ulp with numpy's widest SIMD loops off: NPY_DISABLE_CPU_FEATURES='$$simd'"; \
	NPY_DISABLE_CPU_FEATURES="$$simd" WORKBENCH_PERTURB_ULPS=-3 $(WB) check --jobs $(JOBS) \
	  2>/dev/null | $(NOT_OK); down=$${PIPESTATUS[0]}; \
	echo "slow tests exit $$slow, fuzz campaign exit $$fuzz, $(OTHER_KERNEL) check exit $$other, golden exit $$golden," \
	     "+3 ulp exit $$up, -3 ulp and narrower SIMD exit $$down; make test-full:" \
	     "$$(( $$(date +%s) - t0 )) s wall"; \
	test $$slow -eq 0 && test $$fuzz -eq 0 && test $$other -eq 0 && test $$golden -eq 0 && test $$up -eq 0 \
	  && test $$down -eq 0

## the wheel in a fresh venv outside the checkout: init, verify --junit-xml,
## pytest --workbench (needs PyPI for the dependencies; run by .ci/run)
test-wheel: install
	$(PY) -m pytest -m wheel tests/test_wheel.py

bench: install
	for b in benchmarks/*.py; do $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) .pytest_cache
