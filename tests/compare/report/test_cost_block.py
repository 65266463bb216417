"""The README's command-cost block is generated from the stored measurements
(``compare/report/cost_block.py``), never typed; the Makefile has the targets
the block and the README name."""
from __future__ import annotations

import re

from tests.support.paths import ROOT
from trilith_xval.compare.report.cost_block import (COSTS_BEGIN, COSTS_END, load_costs,
                                                    render_costs)


def test_readme_block_is_the_generators_output():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert text.count(COSTS_BEGIN) == 1 and text.count(COSTS_END) == 1
    block = text.split(COSTS_BEGIN, 1)[1].split(COSTS_END, 1)[0].strip("\n")
    assert block == render_costs(load_costs(ROOT / "docs" / "validation")), (
        "README.md cost block is stale; run: make costs")


def test_block_names_the_report_commands_with_their_cpu():
    rows = {r["command"]: r for r in load_costs(ROOT / "docs" / "validation")}
    assert {"make report", "make report-full"} <= set(rows)
    assert all(r["cpu_s"] > 0 for r in rows.values())


def test_makefile_targets():
    make = (ROOT / "Makefile").read_text()
    recipes = dict(re.findall(r"^([\w-]+):[^\n]*\n\t([^\n]+)", make, flags=re.M))
    assert "trilith report --out report" in recipes["report"]
    assert "--full" not in recipes["report"]
    assert "trilith report --full" in recipes["report-full"]
    assert "cost_block docs/validation README.md" in recipes["costs"]
    assert "benchmarks.run" in recipes["bench"]
