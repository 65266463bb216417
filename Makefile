# Every target creates .venv when missing and installs the project into it.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: report report-full costs test bench figures atlas clean

$(STAMP): pyproject.toml
	test -d $(VENV) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

# The default report: cheap checks and a sample of threshold points now, the rest
# from docs/validation/ (labelled, re-verified on a sample); minutes on 2 cores.
report: $(STAMP)
	$(VENV)/bin/trilith report --out report

# Everything remeasured (~1,300 CPU s on 2 cores: the stored docs/validation/summary.json).
report-full: $(STAMP)
	$(VENV)/bin/trilith report --full --out report

# The README's command-cost block, from the stored measurements (make bench with
# BENCH_STORE=1 stores them).
costs: $(STAMP)
	$(PY) -m trilith_xval.compare.report.cost_block docs/validation README.md

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
