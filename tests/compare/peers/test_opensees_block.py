"""The OpenSees peer (compare/peers/opensees_block.py) beside the model.

Needs the optional extra ``pip install -e '.[peers]'`` (openseespy); skipped
with that reason when it is absent.  About 15 CPU s.

Tolerances, from the measurement in docs/peers.md (docs/validation/peer_opensees.json):

* restitution: the mean of the first three impacts within 0.5 % of Housner
  (the tolerance the validation report gives an engine against Eq. 20: 0.5 % on
  the ratio is 1 % of the energy kept per impact), each impact within 1 %.
  The default contact damping was chosen on ``single_block`` (lam = 5), so the
  test checks lam = 4, a slenderness the choice never saw: measured mean
  -0.38 %, impacts -0.22 %, -0.51 %, -0.40 % (the contact rings a little after
  each impact, which scatters single impacts by about +-0.15 % around the mean).
* threshold: 2 %, the issue's agreement level; measured -0.2 % at this point,
  within the peer's own contact modelling spread (docs/peers.md).
"""
from __future__ import annotations

import json
import math

import pytest

from tests.support.paths import ROOT

try:  # openseespy raises RuntimeError, not ImportError, when its shared library
    # cannot load (on Linux: no system libblas.so.3)
    import openseespy.opensees  # noqa: F401
except ImportError:
    pytest.skip("the OpenSees peer needs the optional extra: pip install -e '.[peers]'",
                allow_module_level=True)
except RuntimeError as exc:
    pytest.skip(f"openseespy is installed but does not load ({exc}; on Linux it needs "
                "libblas.so.3)", allow_module_level=True)

from trilith_xval.compare.peers import opensees_block as ob  # noqa: E402
from trilith_xval.scenes import load_scene  # noqa: E402

STORED = ROOT / "docs" / "validation" / "peer_opensees.json"
RESTITUTION_TOL = 0.005
IMPACT_TOL = 0.01
THRESHOLD_TOL = 0.02


def test_free_rocking_restitution_is_housners():
    scene = load_scene("single_block", lam=4.0)
    b, h = 0.5 * scene.b, 0.5 * scene.h
    t, theta = ob.free_rocking(b, h, 0.5 * scene.alpha, 2.5)
    cyc = ob.rocking_cycles(t, theta, scene.alpha)
    r = cyc["restitution"][:3]
    assert len(r) == 3, cyc
    housner = ob.housner_restitution(b, h)
    assert abs(housner - (1.0 - 1.5 * math.sin(scene.alpha) ** 2)) < 1e-12
    assert sum(r) / len(r) == pytest.approx(housner, rel=RESTITUTION_TOL), (r, housner)
    for value in r:
        assert value == pytest.approx(housner, rel=IMPACT_TOL), (r, housner)
    # the first quarter-cycle is pure pivoting: the impact time is the model's
    # (Housner, linearised: acosh(2) / p from alpha/2) within a step or two
    p = math.sqrt(3.0 * ob.G / (4.0 * math.hypot(b, h)))
    assert cyc["impacts"][0] == pytest.approx(math.acosh(2.0) / p, rel=5e-3)


def test_one_sine_threshold_agrees_with_the_model():
    """single_block, Omega = 8 rad/s: the model's threshold 3.102 m/s^2
    (stored in peer_opensees.json by the script); the peer is safe 2 % below
    it and overturns 2 % above it."""
    scene = load_scene("single_block")
    b, h = 0.5 * scene.b, 0.5 * scene.h
    stored = json.loads(STORED.read_text())
    a_model = next(p["model"]["a_over"] for p in stored["thresholds"]
                   if p["omega"] == 8.0 and not p["overrides"])
    assert not ob.one_sine_overturns(b, h, (1.0 - THRESHOLD_TOL) * a_model, 8.0)
    assert ob.one_sine_overturns(b, h, (1.0 + THRESHOLD_TOL) * a_model, 8.0)


def test_stored_results_come_from_the_script():
    from benchmarks import peer_opensees as script
    doc = json.loads(STORED.read_text())
    assert doc["schema"] == script.SCHEMA
    assert doc["command"].startswith("nice -n 10 python -m benchmarks.peer_opensees")
    for key in ("openseespy", "cpu_s", "load_average_start", "load_average_end", "contact",
                "free_rocking", "restitution_sweep", "thresholds"):
        assert key in doc, key
    assert doc["contact"] == ob.ContactSettings().describe()
    points = doc["thresholds"]
    assert len(points) >= 6
    assert len({(json.dumps(p["overrides"], sort_keys=True), p["omega"]) for p in points}) \
        == len(points)
    for p in points:
        assert math.isfinite(p["model"]["a_over"]) and math.isfinite(p["peer"]["a_over"]), p
        assert p["rel_error"] == pytest.approx(p["peer"]["a_over"] / p["model"]["a_over"] - 1.0)
    assert len(doc["free_rocking"]) >= 1 and all(r["restitution"] for r in doc["free_rocking"])
