# The two commands a newcomer needs: `make report` and `make test`.
# Both create .venv when missing and install the package with the pinned
# versions of constraints.txt (so reports are reproduced byte for byte).
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
WB     := $(VENV)/bin/workbench
STAMP  := $(VENV)/.installed
# One OpenBLAS thread: the core count must not change the rounding.
export OPENBLAS_NUM_THREADS ?= 1
# A second CPU's BLAS kernels (no FMA): the report check must hold under it too.
OTHER_KERNEL ?= Sandybridge

.PHONY: install report test test-wheel bench clean

$(STAMP): pyproject.toml constraints.txt
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	# the distribution was named "workbench" before (an unrelated project's name on the index)
	$(PY) -m pip uninstall -q -y workbench 2>/dev/null || true
	$(PY) -m pip install -q -c constraints.txt -e '.[test,fast,scale]'
	touch $(STAMP)

install: $(STAMP)

## main job: every shipped design -> reports/<design>.md, figures, index
report: install
	$(WB) report --all

## tests, every claim (designs and proofs) and report freshness, on two CPUs' BLAS
## kernels. Three processes share the two cores: pytest; `workbench check`
## (`workbench verify` + `workbench report --all --check` in one process, each
## study computed once; its output ends with the time each design's study took);
## and the report check again under another CPU's kernels (OTHER_KERNEL). Their
## outputs are shown after pytest's, then the golden report runs under OTHER_KERNEL.
test: install
	@t0=$$(date +%s); log=$$(mktemp); other=$$(mktemp); \
	$(WB) check > $$log 2>&1 & check=$$!; \
	OPENBLAS_CORETYPE=$(OTHER_KERNEL) $(WB) report --all --check > $$other 2>&1 & second=$$!; \
	$(PY) -m pytest --durations=15; tests=$$?; \
	echo "== pytest done after $$(( $$(date +%s) - t0 )) s"; \
	wait $$check; checked=$$?; wait $$second; seconded=$$?; \
	echo; echo "== workbench check (verify + report --all --check)"; cat $$log; \
	echo; echo "== report --all --check under OPENBLAS_CORETYPE=$(OTHER_KERNEL)"; cat $$other; \
	rm -f $$log $$other; \
	echo "== golden report under OPENBLAS_CORETYPE=$(OTHER_KERNEL)"; \
	OPENBLAS_CORETYPE=$(OTHER_KERNEL) $(PY) -m pytest -q -p no:cacheprovider \
	  tests/test_cli_and_reports.py::test_golden_report; golden=$$?; \
	echo "pytest exit $$tests, workbench check exit $$checked," \
	     "$(OTHER_KERNEL) report check exit $$seconded, golden exit $$golden;" \
	     "$$(( $$(date +%s) - t0 )) s"; \
	test $$tests -eq 0 && test $$checked -eq 0 && test $$seconded -eq 0 && test $$golden -eq 0

## the wheel in a fresh venv outside the checkout: init, verify --junit-xml,
## pytest --workbench (needs PyPI for the dependencies; run by .ci/run)
test-wheel: install
	$(PY) -m pytest -m wheel tests/test_wheel.py

bench: install
	for b in benchmarks/*.py; do $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) .pytest_cache
