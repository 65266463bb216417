"""The excitation contract: every shipped excitation keeps it, a user's own
subclass runs through the model and an engine without touching project code,
anything else is refused with one TypeError everywhere, bad values with a
ValueError naming the field, and the run keys of stored runs are unchanged."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from trilith_xval import engines
from trilith_xval.analytic import fast
from trilith_xval.analytic.excitation import (Excitation, Pulse, SampledRecord, Still,
                                              check_excitation, check_excitation_contract)
from trilith_xval.analytic.pulses import PULSE_FAMILY, MavroeidisPapageorgiou, Ricker, pulse_of
from trilith_xval.analytic.simulate import simulate
from trilith_xval.compare.run.keys import digest, excitation_dict
from trilith_xval.scenes import load_scene
from trilith_xval.scenes.ground_motion import load_suite

SHIPPED = [Pulse(25.0, 11.0), Pulse(-3.5, 7.25, "cosine"), Ricker(2.0, 0.5),
           Ricker(-3.0, 0.7, "antisymmetric"), MavroeidisPapageorgiou(0.4, 1.5, 2.5, 0.3),
           SampledRecord((0.0, 0.5, 1.0), (0.0, 2.5, -1.0), "r"),
           SampledRecord((0.2, 0.3, 0.9), (1.0, -2.0, 0.5)), Still()]
SHIPPED += [pulse_of(kind, 5.0, 9.0) for kind in PULSE_FAMILY]


@dataclass(frozen=True)
class UserSine(Excitation):
    """A user's own one-sine pulse: only the required members, no compiled form."""

    amplitude: float
    omega: float

    @property
    def end_time(self) -> float:
        return 2.0 * math.pi / self.omega

    def acceleration_array(self, t):
        t = np.asarray(t, dtype=float)
        return np.where((t >= 0.0) & (t <= self.end_time),
                        self.amplitude * np.sin(self.omega * t), 0.0)

    def velocity(self, t: float) -> float:
        tc = min(max(t, 0.0), self.end_time)
        return self.amplitude / self.omega * (1.0 - math.cos(self.omega * tc))

    def displacement(self, t: float) -> float:
        tc = min(max(t, 0.0), self.end_time)
        return self.amplitude / self.omega * (tc - math.sin(self.omega * tc) / self.omega)

    def scaled(self, factor: float) -> "UserSine":
        if not (math.isfinite(factor) and factor > 0.0):
            raise ValueError(f"factor must be finite and > 0, got {factor!r}")
        return UserSine(factor * self.amplitude, self.omega)


@pytest.mark.parametrize("excitation", SHIPPED, ids=lambda e: type(e).__name__)
def test_every_shipped_excitation_keeps_the_contract(excitation):
    check_excitation_contract(excitation)
    check_excitation_contract(type(excitation))


def test_the_shipped_sample_record_keeps_the_contract():
    check_excitation_contract(load_suite("sample")[0])


def test_a_user_excitation_keeps_the_contract():
    check_excitation_contract(UserSine(25.0, 11.0))
    assert UserSine(25.0, 11.0).describe() == {"type": "usersine", "amplitude": 25.0,
                                               "omega": 11.0}


def test_the_checker_names_a_broken_rule():
    @dataclass(frozen=True)
    class NotScaling(UserSine):
        def scaled(self, factor):
            return self

    with pytest.raises(AssertionError, match="scaled"):
        check_excitation_contract(NotScaling(25.0, 11.0))

    class Partial(Excitation):
        @property
        def end_time(self):
            return 1.0

    with pytest.raises(AssertionError, match="abstract"):
        check_excitation_contract(Partial)
    with pytest.raises(TypeError):
        Partial()
    with pytest.raises(AssertionError, match="not a subclass"):
        check_excitation_contract(dict)


def test_a_user_excitation_runs_through_the_model_and_an_engine():
    """The same motion as the shipped one-sine pulse gives the same runs, in the
    accurate model, in the compiled path (handed to the accurate one) and in an
    engine."""
    pytest.importorskip("pymunk")
    scene = load_scene("fig5")
    mine, ref = UserSine(25.0, 11.0), Pulse(25.0, 11.0)
    a, b = simulate(scene, mine), simulate(scene, ref)
    assert a.verdict.status == b.verdict.status
    assert a.verdict.n_impacts == b.verdict.n_impacts
    assert np.max(np.abs(a.theta)) == pytest.approx(np.max(np.abs(b.theta)), rel=1e-6)
    f = fast.simulate(scene, mine)
    assert "fast_path_fallback" in f.diagnostics and f.verdict.status == b.verdict.status
    e, r = (engines.simulate("pymunk", scene, x, t_max=2.0) for x in (mine, ref))
    assert e.verdict.status == r.verdict.status
    assert e.theta == pytest.approx(r.theta, abs=1e-9)


NOT_EXCITATIONS = [3.0, (1.0, 10.0), {"amplitude": 1.0}, "sine", None]


class DuckTyped:
    """Has what the model once duck-typed on, but is no Excitation."""

    end_time = 1.0

    def acceleration(self, t):
        return 0.0


@pytest.mark.parametrize("bad", NOT_EXCITATIONS + [DuckTyped()], ids=lambda b: type(b).__name__ if isinstance(b, DuckTyped) else repr(b))
def test_one_type_error_everywhere(bad):
    scene = load_scene("fig5")
    message = r"excitation must be an analytic\.excitation\.Excitation \(Pulse, .*Still"
    with pytest.raises(TypeError, match=message):
        check_excitation(bad)
    with pytest.raises(TypeError, match=message):
        simulate(scene, bad)
    with pytest.raises(TypeError, match=message):
        fast.simulate(scene, bad)
    with pytest.raises(TypeError, match=message):
        fast.verdict_for(scene, bad)
    with pytest.raises(TypeError, match="pymunk: " + message):
        engines.simulate("pymunk", scene, bad)
    with pytest.raises(TypeError, match=message):
        excitation_dict(bad)


def test_the_compiled_verdict_needs_a_compiled_form():
    with pytest.raises(TypeError, match="compiled_form"):
        fast.verdict_for(load_scene("fig5"), Ricker(2.0, 0.5))


@pytest.mark.parametrize("make, field", [
    (lambda: Pulse(math.nan, 10.0), "amplitude"),
    (lambda: Pulse(1.0, 0.0), "omega"),
    (lambda: Pulse(1.0, 10.0, "square"), "kind"),
    (lambda: Ricker(1.0, 100.0), "period"),
    (lambda: MavroeidisPapageorgiou(0.4, 1.5, 50.0), "gamma"),
    (lambda: SampledRecord((0.0, 1.0), (0.0, 2e4)), "accelerations"),
    (lambda: SampledRecord((1.0, 0.5), (0.0, 1.0)), "times"),
    (lambda: Pulse(1.0, 10.0).scaled(-1.0), "factor"),
    (lambda: Still().scaled(0.0), "factor"),
])
def test_bad_values_raise_value_error_naming_the_field(make, field):
    with pytest.raises(ValueError, match=field):
        make()


# The run keys of these excitations before the excitation contract existed
# (computed on the parent commit): stored runs must keep their keys.
KEYS_BEFORE = {
    "pulse": (Pulse(25.0, 11.0),
              "7c6a2d48581516b2904e3e612576be56cc4f5ea4013486c665c2e5e8c1f70987"),
    "cosine": (Pulse(-3.5, 7.25, "cosine"),
               "68bc7fc519cdb3e2cb4ef3666cae28d426a11e9561bd2baf6e18da510e3b755f"),
    "record": (SampledRecord((0.0, 0.5, 1.0), (0.0, 2.5, -1.0), "r"),
               "36a5478e47503bef7201765bcc442574e8e64a8e1a0549829ad8345adc4a5858"),
    "ricker": (Ricker(2.0, 0.5),
               "01f55c8e237be481d8b4eb7b6ace533edd076abebea64fbcc1d33e89b3979c9d"),
    "mp": (MavroeidisPapageorgiou(0.4, 1.5, 2.5, 0.3),
           "4fbbd4f836e994399a03252d03ad2d44ff76b2a4c84dfc78f30c220063e8eaf3"),
    "still": (Still(), "4048e5ad1edf8269701a1802ed045e7f94414f5db07d956f1fa8cdeca9408a34"),
}


@pytest.mark.parametrize("name", sorted(KEYS_BEFORE))
def test_run_keys_are_unchanged(name):
    excitation, key = KEYS_BEFORE[name]
    assert digest(excitation_dict(excitation)) == key


def test_the_sample_records_run_key_is_unchanged():
    # Before the excitation contract, as above.
    assert (digest(excitation_dict(load_suite("sample")[0]))
            == "773fc75a400dba61c125f8b3ed031cc32d93cbd9f306c047e5396b73b1d1fb91")
