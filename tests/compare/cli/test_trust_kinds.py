"""``trilith trust`` and ``trilith report`` on a scene of another kind: engine
against engine (compare.campaign.trust_kinds), never agreement with a model.

Cheap: pymunk and mujoco, one frequency, a 1e-3 s step and a fixed 5 s window
(trust_kind's own ``over_p`` and ``options`` arguments); the design itself is the
module's (OVER_P)."""
from __future__ import annotations

import functools
import json
import math

import pytest

from trilith_xval.compare.campaign import trust_kinds
from trilith_xval.compare.cli.main import main
from trilith_xval.compare.measure.consensus import OUTLIER_TOL
from trilith_xval.scenes import load_scene

# 1e-3 s and a 5 s window keep a point to seconds; at 6 p of the drums (13 rad/s,
# a 0.5 s pulse) both engines fail within 3 s of the start near the threshold.
CHEAP = {"dt": 1e-3, "t_max": 5.0, "early_stop": False}


@pytest.fixture
def cheap(monkeypatch):
    def use(*over_p):
        monkeypatch.setattr(trust_kinds, "trust_kind",
                            functools.partial(trust_kinds.trust_kind, over_p=over_p,
                                              options=CHEAP))
    return use


def test_trust_on_drums_is_engine_against_engine(tmp_path, capsys, cheap):
    cheap(6.0)
    out = tmp_path / "t"
    code = main(["trust", "--scene", "drums", "--engine", "pymunk,mujoco", "--out", str(out)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t"]  # written whole, no leftovers
    assert {"index.html", "trust.csv", "trust.json"} <= {p.name for p in out.iterdir()}
    doc = json.loads((out / "trust.json").read_text())
    assert doc["kind"] == "drums" and doc["model"] is None and doc["records"] is None
    assert all(e["record_verdict"] is None for e in doc["engines"].values())
    assert set(doc["no_model"]) == {"restitution", "model_theta"}
    (point,) = doc["points"]
    fails = {e: o["a_fails"] for e, o in point["own"].items() if o["converged"]}
    if len(fails) == 2:
        assert min(fails.values()) <= point["median"] <= max(fails.values())
    for e, entry in doc["engines"].items():
        # The verdict is what the deviations say, not a label.
        trusted = entry["threshold_verdict"]["trusted"]
        if len(fails) == 2:
            assert trusted is (abs(point["engines"][e]["deviation"]) <= OUTLIER_TOL)
        else:  # no answer: not trusted; the only answer: nothing to judge it against
            assert trusted is (None if e in fails else False)
        assert entry["cost"]["threshold_point_cpu_s"] > 0 and entry["cost"]["cpu_per_sim_s"] > 0
    if point["median"] is not None:
        h = doc["histories"]
        assert [x["factor"] for x in h] == [0.9, 1.1]
        for x in h:
            assert math.isclose(x["amplitude"], x["factor"] * point["median"])
            assert x["body"] == "column_left_0" and set(x["engines"]) == {"pymunk", "mujoco"}
            assert x["agree"] == (len({r["failed"] for r in x["engines"].values()}) == 1)
    page = (out / "index.html").read_text()
    assert "engine against engine: the model does not cover the drums kind" in page
    assert "Consensus: engine against engine" in page and "agreement with a model" in page
    for line in doc["no_model"].values():
        assert line.replace("'", "&#x27;") in page
    assert (out / "trust.csv").read_text().count("\n") == 3  # header + 2 engines x 1 point
    assert "trust: 1/2 thresholds, engine against engine" in captured.err
    assert "trust: 2/2 time histories, engine against engine" in captured.err
    assert captured.out.startswith("Pymunk: thresholds ")


@pytest.mark.parametrize("argv, word", [
    (["--engine", "drake,pymunk"], "drake runs the parametric trilith only, not the drums kind"),
    (["--engine", "pymunk,mujoco", "--record", "/nonexistent.csv"], "--record"),
    (["--engine", "nosuch"], "--engine"),
    (["--engine", "pymunk", "--set", "lam=3"], "--set lam: not a value of the drums kind"),
])
def test_bad_input_is_refused_before_any_work(tmp_path, capsys, no_work, monkeypatch, argv,
                                              word):
    # Every shipped engine builds the body list: one taken off the list stands for an
    # engine that does not.
    from trilith_xval.engines import geometry
    monkeypatch.setattr(geometry, "STRUCTURE_ENGINES", ("pymunk", "mujoco"))
    out = tmp_path / "t"
    code = main(["trust", "--scene", "drums", *argv, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.splitlines()) == 1 and word in err, err
    assert not out.exists()


def test_the_api_refuses_bad_input_before_any_work(no_work):
    drums = load_scene("drums")
    for kwargs, word in [({"scene": load_scene("fig5")}, "scene is a trilith"),
                         ({"engines": ("nosuch",)}, "engines must be one or more of"),
                         ({"over_p": (4.0, -1.0)}, "over_p must be positive")]:
        args = {"scene": drums, "engines": ("pymunk",), **kwargs}
        with pytest.raises(ValueError, match=word):
            trust_kinds.trust_kind(args.pop("scene"), args.pop("engines"), **args)


def _point(omega, devs, missing=(), outliers=()):
    return {"omega": omega, "status": "consensus", "median": 10.0,
            "engines": {e: {"deviation": d} for e, d in devs.items()},
            "no_answer": [{"engine": e, "cause": "step", "detail": "no two steps agree"}
                          for e in missing],
            "outliers": [{"engine": e, "deviation": devs[e], "cause": c} for e, c in outliers]}


def test_the_verdict_is_engine_against_engine():
    within = OUTLIER_TOL / 2
    pts = [_point(8.0, {"a": within, "b": -within}), _point(12.0, {"a": 0.0, "b": 0.0})]
    assert trust_kinds.verdict(pts, "a")["trusted"] is True
    apart = [*pts, _point(16.0, {"a": 2 * OUTLIER_TOL, "b": -2 * OUTLIER_TOL})]
    v = trust_kinds.verdict(apart, "b")
    assert v["trusted"] is False and "two engines apart" in v["why"]
    odd = [_point(8.0, {"a": 0.0, "b": 0.0, "c": 0.1}, outliers=[("c", "sliding")])]
    assert trust_kinds.verdict(odd, "a")["trusted"] is True
    v = trust_kinds.verdict(odd, "c")
    assert v["trusted"] is False and "cause sliding" in v["why"]
    v = trust_kinds.verdict([*pts, _point(16.0, {"a": 0.0}, missing=["b"])], "b")
    assert v["trusted"] is False and "no answer (step" in v["why"]
    alone = [_point(8.0, {"a": 0.0})]
    v = trust_kinds.verdict(alone, "a")
    assert v["trusted"] is None and "no consensus" in v["why"]


def test_the_design_follows_the_slowest_stack():
    # Drums: the 3 m column of three drums on its 0.6 m base rocks as one until a
    # joint opens; a block on a block: the 0.8 m lower block carrying the upper.
    p, R, body = trust_kinds.structure_p(load_scene("drums"))
    assert body == "column_left_0" and math.isclose(R, 0.5 * math.hypot(0.6, 3.0))
    assert math.isclose(p, math.sqrt(3 * 9.81 / (4 * R)))
    p, R, body = trust_kinds.structure_p(load_scene("block_on_block"))
    assert body == "lower" and math.isclose(R, 0.5 * math.hypot(0.8, 3.5))
    p, R, body = trust_kinds.structure_p(load_scene("unequal"))
    assert body == "column_right" and math.isclose(R, 0.5 * math.hypot(0.8, 3.0))
    omegas = trust_kinds.design_omegas(load_scene("drums"))
    assert len(omegas) == 6 and omegas == sorted(omegas)
    assert math.isclose(omegas[-1] / omegas[0], 6.0, rel_tol=1e-3)


def test_a_record_on_a_kind_is_engine_against_engine(tmp_path, capsys, monkeypatch):
    # The record's own window (its 10 s and the tail) runs; 1e-3 s keeps it to seconds.
    monkeypatch.setattr(trust_kinds, "trust_kind",
                        functools.partial(trust_kinds.trust_kind, over_p=(4.0,),
                                          options={"dt": 1e-3}))
    out = tmp_path / "t"
    code = main(["trust", "--scene", "block_on_block", "--engine", "pymunk,mujoco",
                 "--record", "scenes/records/sample.csv", "--out", str(out)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    doc = json.loads((out / "trust.json").read_text())
    (rec,) = doc["records"]
    assert rec["record"] == "sample.csv" and rec["im"] == "pga"
    fails = {e: o["a_fails"] for e, o in rec["own"].items() if o["converged"]}
    for e, entry in doc["engines"].items():
        trusted = entry["record_verdict"]["trusted"]
        if len(fails) == 2:
            assert min(fails.values()) <= rec["median"] <= max(fails.values())
            assert trusted is (abs(rec["engines"][e]["deviation"]) <= OUTLIER_TOL)
        else:
            assert trusted is (None if e in fails else False)
    assert "Ground motions: engine against engine" in (out / "index.html").read_text()
    assert "trust: 3/3 ground motions, engine against engine 1/1" in captured.err
    assert "MuJoCo: ground motions " in captured.out


def test_report_on_a_kind_writes_its_trust_page(tmp_path, capsys, cheap):
    cheap(4.0)
    out = tmp_path / "r"
    code = main(["report", "--scene", "block_on_block", "--engine", "pymunk,mujoco",
                 "--out", str(out)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert captured.err.startswith("report: block_on_block is of the block_on_block kind, "
                                   "which the model does not cover: writing its trust page")
    assert {"index.html", "trust.csv", "trust.json"} <= {p.name for p in out.iterdir()}
    doc = json.loads((out / "trust.json").read_text())
    assert doc["kind"] == "block_on_block" and len(doc["points"]) == 1
    assert "report written to" in captured.out
    # The campaign's options do not apply to a kind: refused in one line.
    assert main(["report", "--scene", "block_on_block", "--quick", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "--quick do not apply" in err


def test_one_engine_alone_is_refused_before_any_work(capsys, tmp_path):
    from trilith_xval.compare.cli.main import main
    for command in ("trust", "report"):
        assert main([command, "--scene", "block_on_block", "--engine", "pymunk",
                     "--out", str(tmp_path / command)]) == 2
        err = capsys.readouterr().err
        assert len(err.splitlines()) == 1 and "two or more engines" in err
        assert not (tmp_path / command).exists()
