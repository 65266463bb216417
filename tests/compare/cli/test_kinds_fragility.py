"""``trilith fragility`` on a scene the model does not cover: each engine's own first
failing intensity per record, its curve, the engines' consensus; no model curve."""
from __future__ import annotations

import json
import math

import pytest

from trilith_xval.compare.cli.main import main


def _records(folder):
    """Two 1 s windowed sines (8 and 12 rad/s): short runs, two different thresholds."""
    folder.mkdir()
    for name, w in (("p8", 8.0), ("p12", 12.0)):
        rows = [f"{0.01 * i:.2f},{math.sin(w * 0.01 * i) * math.sin(math.pi * 0.01 * i) ** 2:.6f}"
                for i in range(101)]
        (folder / f"{name}.csv").write_text("# test pulse\nt,a\n" + "\n".join(rows) + "\n")
    return folder


def test_fragility_on_drums_gives_each_engines_curve_and_no_model(tmp_path, capsys):
    records = _records(tmp_path / "rec")
    # dt 5e-4 s keeps the test to seconds: the answer converges the step itself
    # (1e-3 s against 5e-4 s within 1 %, else it halves).
    settings = tmp_path / "s.toml"
    settings.write_text("[pymunk]\ndt = 0.0005\n[mujoco]\ndt = 0.0005\n")
    out = tmp_path / "out"
    assert main(["fragility", "--scene", "drums", "--records", str(records), "--engine",
                 "pymunk,mujoco", "--im-range", "1:30", "--tail", "0.5", "--settings",
                 str(settings), "--out", str(out), "--no-cache", "--workers", "1"]) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("scene drums (drums): no model")
    assert "engine against engine" in captured.out.splitlines()[0]
    assert {"fragility.csv", "fragility.json", "fragility.png"} <= {p.name for p in out.iterdir()}
    doc = json.loads((out / "fragility.json").read_text())
    assert doc["kind"] == "drums" and doc["model"] is None and doc["engine_against_engine"]
    assert list(doc["backends"]) == ["pymunk", "mujoco"]  # no model curve
    assert "analytic" not in (out / "fragility.csv").read_text()
    for body in doc["backends"].values():
        assert body["fit"]["median"] is not None and "agreement" not in body
        for r in body["records"]:
            assert r["converged"] and not r["censored"]
            # the scan starts below the static uplift and the answer lies above it
            assert r["scan"]["start"] < r["im_overturn"] <= 30.0
            assert r["im_safe"] < r["im_overturn"]
            fine, coarse = r["steps"][-1], r["steps"][-2]
            assert fine["dt"] == r["dt"] and coarse["dt"] == 2 * r["dt"]
            assert abs(fine["a_fails"] - coarse["a_fails"]) <= 0.01 * fine["a_fails"]
    for i, point in enumerate(doc["consensus"]):
        values = [doc["backends"][e]["records"][i]["im_overturn"] for e in ("pymunk", "mujoco")]
        assert point["median"] == pytest.approx(sum(values) / 2)  # two engines: the mean
        assert point["status"] in ("consensus", "disagree")
    # different pulses, different thresholds: the curve has a dispersion
    assert doc["consensus"][0]["median"] != doc["consensus"][1]["median"]


@pytest.mark.parametrize("extra, text", [
    (["--engine", "pymunk"], "--engine needs two or more engines"),
    (["--engine", "none"], "--engine needs two or more engines"),
    (["--engine", "pymunk,mujoco", "--stripes", "1,2"], "--stripes: the multiple-stripe"),
])
def test_fragility_on_a_kind_refuses_bad_input_before_work(extra, text, tmp_path, capsys,
                                                           no_work):
    code = main(["fragility", "--scene", "block_on_block", "--records", "synthetic",
                 "--out", str(tmp_path / "o"), *extra])
    err = capsys.readouterr().err
    assert code == 2, err
    assert len(err.splitlines()) == 1 and text in err
    assert not (tmp_path / "o").exists()
