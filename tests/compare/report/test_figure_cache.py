"""Report figures kept by the data they plot (compare/report/figure_cache.py):
drawn once per distinct data, options and drawing code, stored as PNG bytes in
the run store's data format, and a report rebuilt from the same results draws
nothing (nor reruns the model's validity checks)."""
from __future__ import annotations

import base64

import numpy as np
import pytest

from trilith_xval.compare.report import figure_cache, plots
from trilith_xval.compare.run import runs
from trilith_xval.compare.run.store import RunStore

PNG = b"\x89PNG\r\n\x1a\n fake image bytes"


class Draw:
    """A drawing function that counts its calls."""

    def __init__(self):
        self.calls = 0

    def __call__(self) -> bytes:
        self.calls += 1
        return PNG + bytes([self.calls])


@pytest.fixture
def store(tmp_path):
    store = RunStore(tmp_path / "store")
    with runs.using(store):
        yield store
    store.close()


def test_a_figure_is_drawn_once_per_distinct_data(store):
    draw = Draw()
    data = {"omega": np.linspace(3.0, 30.0, 7), "label": "PyBullet"}
    first = figure_cache.png_base64("demo", data, {"dpi": 200}, draw)
    again = figure_cache.png_base64("demo", {**data, "omega": data["omega"].copy()},
                                    {"dpi": 200}, draw)
    assert draw.calls == 1 and again == first
    assert base64.b64decode(first) == PNG + b"\x01"
    moved = data["omega"].copy()
    moved[3] = np.nextafter(moved[3], np.inf)  # one bit of one point
    for changed in ({**data, "omega": moved}, {**data, "label": "Pymunk"}):
        figure_cache.png_base64("demo", changed, {"dpi": 200}, draw)
    figure_cache.png_base64("demo", data, {"dpi": 100}, draw)  # another option
    figure_cache.png_base64("other", data, {"dpi": 200}, draw)  # another figure
    assert draw.calls == 5


def test_the_png_is_stored_as_data(store):
    figure_cache.png_base64("demo", {"x": [1.0]}, {}, Draw())
    key = figure_cache.figure_key("demo", {"x": [1.0]}, {})
    value = store.get(key)
    assert value["png"].dtype == np.uint8 and value["png"].tobytes() == PNG + b"\x01"
    assert store.count(figure_cache.KIND) == 1


def test_without_a_store_every_figure_is_drawn():
    draw = Draw()
    with runs.using(None):
        for _ in range(2):
            figure_cache.png_base64("demo", {"x": [1.0]}, {}, draw)
    assert draw.calls == 2


def test_a_rebuilt_report_draws_no_figure(store, tmp_path, monkeypatch):
    from tests.support.synthetic_report import synthetic_result

    from trilith_xval.compare.report.html import write_report

    from trilith_xval.analytic import threshold_validity

    drawn, checked = [], []
    real_png, real_check = plots._png, threshold_validity.curve_validity
    monkeypatch.setattr(plots, "_png", lambda fig: drawn.append(1) or real_png(fig))
    monkeypatch.setattr(threshold_validity, "curve_validity",
                        lambda *a, **k: checked.append(1) or real_check(*a, **k))
    result = synthetic_result()
    write_report(result, tmp_path / "cold", {})
    cold, cold_checks = len(drawn), len(checked)
    assert cold >= 5 and cold_checks  # spectra, convergence, histories, restitution
    write_report(result, tmp_path / "warm", {})
    assert len(drawn) == cold, "a figure of unchanged data was drawn again"
    assert len(checked) == cold_checks, "the model's validity was checked again"
    assert ((tmp_path / "warm" / "index.html").read_text()
            == (tmp_path / "cold" / "index.html").read_text())
