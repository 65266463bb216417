"""The backend contract, checked alike for every registered backend: the checks
are public in :mod:`engines.testing` (gated by each backend's capabilities, its
known failures strict xfails).  Engine-specific behaviour stays in
test_<engine>_engine.py."""
from __future__ import annotations

import pytest

from trilith_xval import engines
from trilith_xval.engines.testing import backend_checks, makris_vassiliou
from tests.support.closed_forms import makris_vassiliou as derived_here


@backend_checks()
def test_backend_meets_the_contract(backend, check):
    check.run(backend)


def test_the_checks_closed_form_is_the_suites():
    # engines.testing carries its own copy of Makris-Vassiliou (it is public);
    # it must be the one derived in test_closed_forms.
    for alpha, g in ((0.1, 0.0), (0.2, 0.25), (0.3, 1.0)):
        assert makris_vassiliou(alpha, g) == derived_here(alpha, g)


def test_configure_names_the_options_a_backend_has():
    with pytest.raises(ValueError, match="analytic has no option 'dt'; its options: .*theta0"):
        engines.configure("analytic", dt=1e-4)
    with pytest.raises(ValueError, match="unknown engine 'bullet'"):
        engines.configure("bullet")
    s = engines.configure("pymunk", criterion="alpha")
    assert s.criterion.kind == "alpha" and s.criterion.topple_angle == 1.5


def test_every_engine_has_its_own_colour():
    # The report draws every engine on shared axes (spectra, restitution per
    # impact, time histories) and tells them apart by colour first.
    colours = {name: engines.get_backend(name).color for name in engines.ENGINES}
    assert len(set(colours.values())) == len(colours), colours
