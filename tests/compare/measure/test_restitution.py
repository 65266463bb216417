"""The backend-agnostic free-rocking restitution experiment and its CLI command.

Engine accuracy is tested per engine (tests/engines/test_pymunk_engine.py); here: the
analytic run length, the plumbing (settings handed to the backend, per-impact
prediction, errors), validation before any simulation, and ``trilith restitution``.
"""
from __future__ import annotations

import dataclasses
import json
import math
import sys
import types

import numpy as np
import pytest
from scipy.integrate import quad

from trilith_xval.analytic import equations as eq
from trilith_xval.analytic.parameters import Scene
from trilith_xval.analytic.trajectory import Event, OverturnCriterion, Trajectory, Verdict
from trilith_xval.compare.cli.main import main
from trilith_xval.engines import BACKENDS
from trilith_xval.compare.measure.restitution import analytic_impact_times, measure_restitution


# ------------------------------------------------------ analytic run length
def _quarter_time(p2: float, alpha: float, amplitude: float) -> float:
    """Time to fall from rest at ``amplitude`` to theta = 0 under
    theta_ddot = -p2 sin(alpha - theta) (the trilith without pendulum, Eq. 8 with
    gamma = 0 written with 2R = sqrt(b^2+h^2)), by quadrature of the energy
    integral with theta = amplitude - s^2 (removes the 1/sqrt end singularity)."""
    def integrand(s):
        theta = amplitude - s * s
        return 2.0 * s / math.sqrt(2.0 * p2 * (math.cos(alpha - amplitude) - math.cos(alpha - theta)))

    value, _ = quad(integrand, 0.0, math.sqrt(amplitude), epsabs=1e-13, epsrel=1e-12)
    return value


def test_analytic_impact_times_match_energy_quadrature():
    scene = Scene(lam=4.0, mu=1.5, gamma=0.0)
    b, h, mu, gamma, j, l, g = scene.model_args()
    p2 = g * eq.total_mass(mu, gamma) * math.hypot(b, h) / eq.rocking_inertia(b, h, mu, gamma, j)
    alpha, theta0 = scene.alpha, 0.6 * scene.alpha
    t1 = _quarter_time(p2, alpha, theta0)
    # Speed at theta = 0 from energy, ratio Eq. 20, then the amplitude it climbs to.
    speed = math.sqrt(2.0 * p2 * (math.cos(alpha - theta0) - math.cos(alpha)))
    e = eq.restitution_ratio(0.0, -1.0, b, h, mu, gamma, j)
    v = e * speed
    amp2 = alpha - math.acos(math.cos(alpha) + v * v / (2.0 * p2))
    t2 = t1 + 2.0 * _quarter_time(p2, alpha, amp2)
    times = analytic_impact_times(scene, theta0, 0.0, 2)
    # 1e-8 s: both are converged to ~1e-10 relative (DOP853 rtol 1e-10, quad 1e-12).
    assert times == pytest.approx([t1, t2], abs=1e-8)


# ---------------------------------------------------------- fake backend
def _fake_backend(monkeypatch, impacts, tilt=True):
    """Register a backend 'fake' (what the registry reads: name, capabilities, a
    RunOptions Settings, simulate, version) that records the settings it receives and returns
    ``impacts`` (a list of Events) as its measured impacts."""
    from trilith_xval.analytic.options import RunOptions
    settings_cls = dataclasses.make_dataclass("Settings", [], bases=(RunOptions,), frozen=True)
    module = types.ModuleType("fake_backend")
    module.NAME = "fake"
    module.CAPABILITIES = frozenset({"trajectory"} | ({"initial_tilt"} if tilt else set()))
    module.Settings = settings_cls
    module.calls = []

    def version():
        return "fake 1.0"

    def simulate(scene, excitation, settings=None):
        module.calls.append((scene, excitation, settings))
        z = np.zeros(3)
        return Trajectory("fake", np.arange(3.0), z, z, z, z, tuple(impacts),
                          Verdict("survived"), OverturnCriterion(), settings.t_max,
                          settings={"t_max": settings.t_max})

    module.Fake = type("Fake", (), dict(
        name="fake", capabilities=module.CAPABILITIES, Settings=settings_cls,
        version=staticmethod(version), simulate=staticmethod(simulate)))
    monkeypatch.setitem(sys.modules, "fake_backend", module)
    monkeypatch.setitem(BACKENDS, "fake", "fake_backend:Fake")
    return module


def test_plumbing_with_fake_backend(monkeypatch, fig5):
    b, h, mu, gamma, j, l, g = fig5.model_args()
    psis = (0.2, -0.1, 0.05)
    impacts = [Event("impact", 0.5 + k, side, theta_dot_before=-side * 0.3,
                     theta_dot_after=-side * 0.3 * 0.9, psi=psi)
               for k, (side, psi) in enumerate(zip((-1, 1, -1), psis))]
    fake = _fake_backend(monkeypatch, impacts)
    theta0 = 0.4 * fig5.alpha
    res = measure_restitution("fake", fig5, theta0, n_impacts=2, psi0=0.1)
    ((scene, excitation, settings),) = fake.calls
    assert settings.theta0 == theta0 and settings.psi0 == 0.1
    assert settings.early_stop is False  # free rocking must run through impacts
    times = analytic_impact_times(fig5, theta0, 0.1, 3)
    assert times[1] < settings.t_max < times[2]  # stops between impacts 2 and 3
    assert excitation.end_time == 0.0 and excitation.acceleration(0.3) == 0.0
    # Only the requested impacts; Eq. 19 at each impact's own psi and side.
    assert res.n_impacts == 2 and res.complete
    assert [i.measured for i in res.impacts] == pytest.approx([0.9, 0.9])
    expected = [eq.restitution_ratio(p, s, b, h, mu, gamma, j) for p, s in zip(psis, (-1, 1))]
    assert [i.predicted for i in res.impacts] == pytest.approx(expected, rel=1e-14)
    assert [i.rel_error for i in res.impacts] == pytest.approx([0.9 / x - 1 for x in expected])
    assert res.max_rel_error == pytest.approx(max(abs(0.9 / x - 1) for x in expected))
    assert res.engine == "fake" and res.version == "fake 1.0"


def test_no_pendulum_uses_eq20_whatever_psi_the_backend_reports(monkeypatch, fig5_bare):
    impacts = [Event("impact", 0.5, -1, theta_dot_before=0.3, theta_dot_after=0.27, psi=0.7)]
    _fake_backend(monkeypatch, impacts)
    res = measure_restitution("fake", fig5_bare, 0.1, n_impacts=1)
    assert res.impacts[0].predicted == eq.restitution_ratio(0.0, -1, *fig5_bare.model_args()[:5])


def test_incomplete_and_empty_results(monkeypatch, fig5):
    _fake_backend(monkeypatch, [])
    res = measure_restitution("fake", fig5, 0.1, n_impacts=3)
    assert not res.complete and res.n_impacts == 0
    assert math.isnan(res.max_rel_error)
    d = res.to_dict()
    assert d["n_impacts"] == 0 and d["impacts"] == [] and d["complete"] is False


def test_backend_without_initial_tilt_is_refused(monkeypatch, fig5):
    fake = _fake_backend(monkeypatch, [], tilt=False)
    with pytest.raises(ValueError, match="initial_tilt"):
        measure_restitution("fake", fig5, 0.1)
    assert fake.calls == []


@pytest.mark.parametrize("theta0, kwargs, match", [
    (0.0, {}, "theta0"), (0.3, {}, "theta0"), (-0.3, {}, "theta0"), (math.nan, {}, "theta0"),
    ("tilt", {}, "theta0"), (0.1, {"n_impacts": 0}, "n_impacts"),
    (0.1, {"n_impacts": 51}, "n_impacts"), (0.1, {"n_impacts": 2.0}, "n_impacts"),
    (0.1, {"n_impacts": True}, "n_impacts"), (0.1, {"psi0": 4.0}, "psi0"),
])
def test_bad_input_raises_before_simulating(monkeypatch, fig5, theta0, kwargs, match):
    fake = _fake_backend(monkeypatch, [])
    with pytest.raises((ValueError, TypeError), match=match):
        measure_restitution("fake", fig5, theta0, **kwargs)
    assert fake.calls == []


def test_unknown_engine(fig5):
    with pytest.raises(ValueError, match="unknown engine"):
        measure_restitution("bullet-time", fig5, 0.1)


# ------------------------------------------------ real backends, end to end
def test_analytic_backend_reproduces_eq19(fig5):
    # The accurate analytic path applies Eq. 19/21 itself: ratio errors are at
    # the level of its event location (impact at theta = 0 to ~1e-12).
    res = measure_restitution("analytic", fig5, 0.5 * fig5.alpha, n_impacts=4)
    assert res.n_impacts == 4 and [i.side for i in res.impacts] == [-1, 1, -1, 1]
    assert res.max_rel_error < 1e-9
    assert [i.t for i in res.impacts] == pytest.approx(analytic_impact_times(fig5, 0.5 * fig5.alpha, 0.0, 4),
                                      abs=1e-6)


def test_cli_json(capsys):
    code = main(["restitution", "--engine", "pymunk", "--no-pendulum", "--set", "lam=4",
                 "--n-impacts", "1", "--json"])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("impacts", "equation", "max_rel_error", "engine", "engine_version", "settings"):
        assert key in out
    assert out["engine"] == "pymunk" and len(out["impacts"]) == 1
    assert out["settings"]["theta0"] == pytest.approx(0.5 * math.atan(1 / 4))
    # the engine contract's 0.5 % (see tests/engines/test_pymunk_engine.py)
    assert out["max_rel_error"] < 5e-3


def test_cli_text_and_errors(capsys):
    assert main(["restitution", "--engine", "analytic", "--n-impacts", "2"]) == 0
    out = capsys.readouterr().out
    assert "Eq. 19" in out and "max |rel. error|" in out
    assert main(["restitution", "--theta0", "1.0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and "theta0" in err[0]
    assert main(["restitution", "--engine", "nope"]) == 2
    assert "unknown engine" in capsys.readouterr().err
