"""A scene without a pendulum prints no pendulum output: no A_yp/mode_yp/Delta
columns (text, JSON, CSV), no gain panel or "with pendulum" curve in the plots,
no "(pendulum)" mode jumps and no warning about the bob.  Each check is run on
the same grid with the pendulum too, where the output must be there."""
from __future__ import annotations

import csv
import json
from types import SimpleNamespace as NS

import matplotlib
import pytest

from trilith_xval.compare.cli.main import main

matplotlib.use("Agg")
# Fig. 5 without the pendulum: a mode jump between 15 and 18 rad/s and the model
# invalid (a contact would pull) at 24 rad/s, on both curves.
GRID = ["--omega", "15,18,24"]


@pytest.fixture(params=[False, True], ids=["pendulum", "no-pendulum"])
def no_pendulum(request):
    return request.param


def _flags(no_pendulum: bool) -> list[str]:
    return ["--no-pendulum"] if no_pendulum else []


def test_table_columns_jumps_and_warnings_follow_the_scene(no_pendulum, capsys):
    assert main(["spectrum", *GRID, *_flags(no_pendulum)]) == 0
    out = capsys.readouterr().out
    header = next(line for line in out.splitlines() if line.lstrip().startswith("Omega"))
    assert "A_np" in header and "mode jump" in out and "model is invalid" in out
    # Words of the pendulum curve, the gain, the curve a jump is on and the bob.
    for word in ("A_yp", "mode_yp", "Delta", "(no pendulum)", "bob"):
        assert (word in out) is (not no_pendulum), word
    if no_pendulum:
        assert "(pendulum)" not in out
        assert "mode jump: after-impact at Omega = 15" in out
        rows = [line.split() for line in out.splitlines() if line.strip()[:2] in ("15", "18")]
        assert all(len(r) == 4 for r in rows), rows  # Omega, A_np, mode_np, valid


def test_json_and_csv_keys_follow_the_scene(no_pendulum, capsys, tmp_path):
    path = tmp_path / "s.csv"
    assert main(["spectrum", *GRID, *_flags(no_pendulum), "--json", "--csv", str(path)]) == 0
    doc = json.loads(capsys.readouterr().out)
    pendulum_keys = {"a_pendulum", "a_pendulum_safe", "gain_percent", "mode_pendulum"}
    assert (pendulum_keys & set(doc)) == (set() if no_pendulum else pendulum_keys)
    assert set(doc["model_validity"]) == ({"no_pendulum"} if no_pendulum
                                          else {"no_pendulum", "pendulum"})
    assert {j["curve"] for j in doc["mode_jumps"]} == {"no_pendulum"}
    assert len(doc["mode_jumps"]) == 1  # one jump, not one per (identical) curve
    with open(path) as fh:
        head = next(csv.reader(fh))
    columns = {"a_pendulum", "gain_percent", "mode_pendulum", "model_valid_pendulum"}
    assert (columns & set(head)) == (set() if no_pendulum else columns)
    assert {"omega", "a_no_pendulum", "mode_no_pendulum", "model_valid_no_pendulum"} <= set(head)


def _captured(monkeypatch, module, name="savefig"):
    """The figure a plotting function saves, kept open for inspection."""
    figures = []
    monkeypatch.setattr(module, name, lambda fig, *a, **k: figures.append(fig))
    return figures


def _labels(fig) -> list[str]:
    out = []
    for ax in fig.axes:
        out += [ax.get_ylabel(), ax.get_title()] + ax.get_legend_handles_labels()[1]
    return out


def test_spectrum_plot_has_no_gain_panel_without_pendulum(no_pendulum, monkeypatch, tmp_path):
    import trilith_xval.compare.run.atomic as atomic
    figures = _captured(monkeypatch, atomic)
    assert main(["spectrum", *GRID, *_flags(no_pendulum), "--plot",
                 str(tmp_path / "s.png")]) == 0
    (fig,) = figures
    labels = " ".join(_labels(fig))
    assert len(fig.axes) == (1 if no_pendulum else 2)
    assert ("gain" in labels) is (not no_pendulum)
    assert ("with pendulum" in labels) is (not no_pendulum)
    assert "mode jump" in labels


def test_engine_spectrum_plot_draws_one_model_curve_without_pendulum(no_pendulum, monkeypatch,
                                                                     tmp_path):
    from matplotlib.figure import Figure

    from trilith_xval.compare.measure import engine_spectrum_files as files
    figures = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: figures.append(fig))
    point = NS(omega=10.0, a_engine=5.6, a_reference=5.5, rel_error=0.018, cause="agrees")
    curves = {"no_pendulum": [point]} | ({} if no_pendulum else {"pendulum": [point]})
    reference = NS(omega=[10.0], a_pendulum=[5.5], a_no_pendulum=[5.5],
                   mode_jumps=lambda: [], settings=NS(pulse="sine"),
                   scene=NS(lam=5.0, b=0.6, gamma=0.0 if no_pendulum else 0.3, mu=1.0))
    files.plot(reference, [NS(engine="toy", curves=curves)], tmp_path / "e.png")
    labels = _labels(figures[0])
    assert ("model, pendulum" in labels) is (not no_pendulum)
    assert "model, no pendulum" in labels


def test_validity_of_a_spectrum_has_its_curves_only(no_pendulum):
    from trilith_xval.analytic import Scene
    from trilith_xval.analytic.spectrum import overturning_spectrum
    from trilith_xval.analytic.threshold_validity import spectrum_validity
    scene = Scene(gamma=0.0 if no_pendulum else 0.3)
    spec = overturning_spectrum(scene, [24.0])
    validity = spectrum_validity(spec)
    assert tuple(validity) == spec.curves == (("no_pendulum",) if no_pendulum
                                              else ("no_pendulum", "pendulum"))
    assert validity["no_pendulum"][0]["model_valid"] is False  # a contact would pull
