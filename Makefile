# Every target creates .venv when missing and installs the project into it.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: report test bench figures atlas clean

$(STAMP): pyproject.toml
	test -d $(VENV) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

report: $(STAMP)
	$(VENV)/bin/trilith report --out report

# Test files are shared among TEST_WORKERS processes (pytest-xdist), a file's
# tests on one of them so its module fixtures are computed once.
TEST_WORKERS ?= 2
test: $(STAMP)
	$(PY) -m pytest -n $(TEST_WORKERS) --dist loadfile

bench: $(STAMP)
	$(PY) -m benchmarks.run

# The stored atlas, remeasured whole (hours of CPU: docs/atlas.md), then the
# blocks generated from it; killed, it resumes from the run store.
ATLAS_ENGINES ?= all
ATLAS_WORKERS ?= 2
atlas: $(STAMP)
	mkdir -p report
	$(VENV)/bin/trilith atlas --engine $(ATLAS_ENGINES) --workers $(ATLAS_WORKERS) \
		--json docs/validation/atlas.json --html report/atlas.html
	$(PY) -m trilith_xval.compare.report.atlas_findings docs/validation/atlas.json README.md \
		docs/engine-trust.md docs/atlas.md

figures: $(STAMP)
	$(VENV)/bin/trilith figures --out figures

clean:
	rm -rf $(VENV) report figures .pytest_cache
