"""The atlas block of the README and docs/engine-trust.md is generated from the
stored atlas, never typed: both files hold exactly what ``render_atlas`` makes of
``docs/validation/atlas.json``; and the block counts what the atlas holds."""
from __future__ import annotations

import json

import pytest

from trilith_xval.compare.report.atlas_findings import ATLAS_BEGIN, ATLAS_END, render_atlas

from tests.support.paths import ROOT
ATLAS = ROOT / "docs" / "validation" / "atlas.json"


@pytest.fixture(scope="module")
def doc() -> dict:
    return json.loads(ATLAS.read_text(encoding="utf-8"))


@pytest.mark.parametrize("name", ["README.md", "docs/engine-trust.md", "docs/atlas.md"])
def test_block_is_generated_from_the_stored_atlas(doc, name):
    text = (ROOT / name).read_text(encoding="utf-8")
    assert text.count(ATLAS_BEGIN) == 1 and text.count(ATLAS_END) == 1
    block = text.split(ATLAS_BEGIN, 1)[1].split(ATLAS_END, 1)[0].strip("\n")
    assert block == render_atlas(doc), (
        f"{name} differs from docs/validation/atlas.json; run: python -m "
        "compare.report.atlas_findings docs/validation/atlas.json README.md "
        "docs/engine-trust.md docs/atlas.md")


def test_block_counts_what_the_atlas_holds(doc):
    text = render_atlas(doc)
    rows = [line for line in text.splitlines() if line.startswith("| ") and "engine" not in line]
    assert len(rows) == sum(len(steps) for steps in doc["steps"].values())
    valid = sum(pt["a_reference"] is not None and pt["valid"] is not False
                for pt in doc["points"])
    for row, (engine, dt) in zip(rows, [(e, dt) for e, s in doc["steps"].items() for dt in s]):
        level = doc["steps"][engine].index(dt)
        agree = sum(1 for pt in doc["points"] if pt["a_reference"] is not None
                    and pt["valid"] is not False and len(pt["engines"][engine]) > level
                    and pt["engines"][engine][level].get("cause") == "agrees")
        # The points this step could be judged on: the budget's leftovers at this
        # step or a finer one are not counted.
        left = sum(doc.get("not_run", {}).get(engine, {}).get(repr(d), 0)
                   for d in doc["steps"][engine][:level + 1])
        measured = sum(1 for pt in doc["points"] if pt["a_reference"] is not None
                       and pt["valid"] is not False and len(pt["engines"][engine]) > level)
        if left and not measured:
            assert row.split(" | ")[2] == "-"
        else:
            cell = f"{agree} / {valid - left}" + (f" (of {valid})" if left else "")
            assert f"| {cell} |" in row
