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
	$(PY) -m pip install -q -c constraints.txt -e '.[test]'
	touch $(STAMP)

install: $(STAMP)

## main job: every shipped design -> reports/<design>.md, figures, index
report: install
	$(WB) report --all

## tests, then every claim (designs and proofs), then report freshness; then
## the report check and the golden report again under another CPU's kernels
test: install
	$(PY) -m pytest
	$(WB) verify
	$(WB) report --all --check
	OPENBLAS_CORETYPE=$(OTHER_KERNEL) $(WB) report --all --check
	OPENBLAS_CORETYPE=$(OTHER_KERNEL) $(PY) -m pytest -q -p no:cacheprovider \
	  tests/test_cli_and_reports.py::test_golden_report

## the wheel in a fresh venv outside the checkout: init, verify --junit-xml,
## pytest --workbench (needs PyPI for the dependencies; run by .ci/run)
test-wheel: install
	$(PY) -m pytest -m wheel tests/test_wheel.py

bench: install
	for b in benchmarks/*.py; do $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) .pytest_cache
