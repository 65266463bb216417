"""The walk of ``dt`` and ``friction`` from the command line to the engine: the
settings file is read and checked once as a whole, the run is resolved once
(:meth:`RunSpec.resolve`), and the engine runs the very settings the RunSpec made;
no module in between configures the engine again."""
from __future__ import annotations

import traceback

import pytest

from trilith_xval import engines
from trilith_xval.compare.cli.main import main
from trilith_xval.engines.base import Engine


@pytest.fixture
def walk(monkeypatch):
    """Who calls ``engines.configure`` and which settings the engine is built with."""
    calls, built = [], []
    real = engines.configure

    def spy(*args, **kwargs):
        caller = traceback.extract_stack(limit=2)[0]
        calls.append(f"{caller.filename.rsplit('/', 2)[-2]}/{caller.filename.rsplit('/', 1)[-1]}"
                     f":{caller.name}")
        return real(*args, **kwargs)
    monkeypatch.setattr(engines, "configure", spy)
    init = Engine.__init__

    def record(self, scene, excitation, settings=None):
        init(self, scene, excitation, settings)
        built.append(self.settings)
    monkeypatch.setattr(Engine, "__init__", record)
    return calls, built


def test_dt_and_friction_reach_the_engine_through_one_resolve(walk, tmp_path, monkeypatch):
    calls, built = walk
    spec_made = []
    from trilith_xval.compare.run import spec as spec_module
    real_resolved = spec_module.RunSpec._resolved.__func__

    def keep(cls, *args):
        out = real_resolved(cls, *args)
        spec_made.append(out)
        return out
    monkeypatch.setattr(spec_module.RunSpec, "_resolved", classmethod(keep))
    path = tmp_path / "s.toml"
    path.write_text("[pymunk]\ndt = 0.000371\nfriction = 3.71\n")
    assert main(["simulate", "--engine", "pymunk", "--settings", str(path), "-A", "5", "-w",
                 "8", "--t-max", "0.05"]) == 0
    # Two checks, each in one place: the file as a whole at the door, the run's layers
    # once in RunSpec.resolve (a given friction is above the bound: no rule applied).
    assert calls == ["campaign/settings_file.py:_checked_tables", "run/spec.py:_resolved"]
    (engine_settings,) = built
    assert engine_settings.dt == 0.000371 and engine_settings.friction == 3.71
    assert any(s.settings is engine_settings for s in spec_made)
