"""The README's engine findings are not typed by hand: the block between the
findings markers is exactly what ``compare.report.findings.render`` makes of the stored
full-campaign summary (``docs/validation/summary.json``), and that summary's
trust table is what ``compare.report.trust`` computes from its own measurements."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from trilith_xval.compare.campaign.summary import SCHEMA_VERSION
from trilith_xval.compare.report.findings import BEGIN, END, TRUST_BEGIN, TRUST_END, render, render_trust
from trilith_xval.compare.report.trust import trust_table
from trilith_xval.compare.campaign.verdicts import VERDICT_IDS

from tests.support.paths import ROOT
README = ROOT / "README.md"
TRUST_DOC = ROOT / "docs" / "engine-trust.md"
SUMMARY = ROOT / "docs" / "validation" / "summary.json"


@pytest.fixture(scope="module")
def doc() -> dict:
    return json.loads(SUMMARY.read_text(encoding="utf-8"))


def test_readme_block_is_generated_from_the_summary(doc):
    text = README.read_text(encoding="utf-8")
    assert text.count(BEGIN) == 1 and text.count(END) == 1
    block = text.split(BEGIN, 1)[1].split(END, 1)[0].strip("\n")
    assert block == render(doc), ("README findings differ from docs/validation/summary.json; "
                                  "run: python -m trilith_xval.compare.report.findings docs/validation/summary.json "
                                  "README.md")


def test_trust_doc_table_is_generated_from_the_same_summary(doc):
    text = TRUST_DOC.read_text(encoding="utf-8")
    assert text.count(TRUST_BEGIN) == 1 and text.count(TRUST_END) == 1
    block = text.split(TRUST_BEGIN, 1)[1].split(TRUST_END, 1)[0].strip("\n")
    assert block == render_trust(doc), (
        "docs/engine-trust.md differs from docs/validation/summary.json; run: python -m "
        "compare.report.findings docs/validation/summary.json README.md docs/engine-trust.md")


def test_stored_summary_is_a_full_campaign_with_a_consistent_trust_table(doc):
    assert doc["schema_version"] == SCHEMA_VERSION and doc["quick"] is False
    assert "--quick" not in doc["provenance"]["command"]
    assert {v["id"] for v in doc["verdicts"]} == set(VERDICT_IDS)
    # The stored trust table is what compare.report.trust computes from the stored
    # measurements (the conclusion's wording may have been improved since).
    recomputed = trust_table(doc)
    strip = lambda t: {e: {k: v for k, v in row.items() if k != "conclusion"}  # noqa: E731
                       for e, row in t.items()}
    assert strip(recomputed) == strip(doc["trust"])


def test_no_stale_hand_typed_threshold_claim():
    # Once: "within 0.4 % up to about 53 m/s^2" contradicted the report.
    assert "0.4 % of the model up to about 53" not in README.read_text(encoding="utf-8")
