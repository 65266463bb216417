"""What a new engine costs: a throwaway engine (tests/support/toy_engine/, Pymunk's world
under a new name) written through engines.base.Engine, registered by one line,
passes the public contract checks and reproduces Pymunk bit for bit."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from trilith_xval import engines
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.engines.testing import check_backend
from tests.support.paths import ROOT
from tests.support.toy_engine import ToyEngine

TOY = ROOT / "tests" / "support" / "toy_engine"


@pytest.fixture
def registered(monkeypatch):
    # The one line a built-in engine adds to engines.ENGINE_CLASSES (ENGINES and
    # BACKENDS follow from it at import; here they are patched alike).
    monkeypatch.setitem(engines.ENGINE_CLASSES, "toy", "tests.support.toy_engine:ToyEngine")
    monkeypatch.setitem(engines.BACKENDS, "toy", "tests.support.toy_engine:ToyEngine")
    monkeypatch.setattr(engines, "ENGINES", tuple(engines.ENGINE_CLASSES))


def test_the_toy_engine_is_one_small_folder():
    lines = sum(len(p.read_text().splitlines()) for p in TOY.rglob("*.py"))
    assert lines <= 300, lines


def test_registered_by_one_line_it_is_everywhere(registered):
    assert engines.get_backend("toy") is ToyEngine
    assert "toy" in engines.engine_names() and "toy" in engines.engine_list("all")
    from trilith_xval.compare.report.plots import color, marker
    from trilith_xval.compare.report.trust import label
    assert (label("toy"), color("toy"), marker("toy")) == ("Toy (Pymunk)", "tab:gray", "D")


def test_the_toy_engine_meets_the_contract(registered):
    check_backend("toy", slow=False)


def test_the_toy_engine_is_pymunk_bit_for_bit(fig5):
    # Same world, same d'Alembert load, same loop: the template adds nothing of its own.
    pulse = Pulse(19.0, 15.0)
    toy = engines.simulate(ToyEngine, fig5, pulse, t_max=1.0)
    ref = engines.simulate("pymunk", fig5, pulse, t_max=1.0)
    for field in ("t", "theta", "theta_dot", "psi", "psi_dot"):
        assert np.array_equal(getattr(toy, field), getattr(ref, field)), field
    assert toy.verdict == ref.verdict and toy.diagnostics.keys() == ref.diagnostics.keys()


def test_an_installed_package_registers_by_entry_point(monkeypatch):
    from importlib.metadata import EntryPoint
    ep = EntryPoint("toy", "tests.support.toy_engine:ToyEngine", engines.ENTRY_POINT_GROUP)
    monkeypatch.setattr("importlib.metadata.entry_points",
                        lambda group=None: [ep] if group == engines.ENTRY_POINT_GROUP else [])
    engines._installed.cache_clear()
    try:
        assert engines.engine_names()[-1] == "toy" and engines.get_backend("toy") is ToyEngine
        assert engines.engine_list("all") == engines.ENGINES + ("toy",)
    finally:
        engines._installed.cache_clear()


def test_an_installed_engine_named_as_a_built_in_is_an_error(monkeypatch):
    from importlib.metadata import EntryPoint
    ep = EntryPoint("pymunk", "tests.support.toy_engine:ToyEngine", engines.ENTRY_POINT_GROUP)
    monkeypatch.setattr("importlib.metadata.entry_points",
                        lambda group=None: [ep] if group == engines.ENTRY_POINT_GROUP else [])
    engines._installed.cache_clear()
    try:
        with pytest.raises(ValueError, match="pymunk .* clash with built-in"):
            engines.engine_names()
    finally:
        engines._installed.cache_clear()
