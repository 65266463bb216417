"""A run is a value: :class:`RunSpec` (backend, scene, excitation, settings), resolved once.

Settings come in layers, each over the one before, in one place
(:meth:`RunSpec.resolve`):

1. the backend's defaults (its ``Settings``);
2. its calibration, for threshold searches, where the scene lies in the
   calibration's domain (:func:`engines.calibration.threshold_choice`);
3. a ``--settings`` file's table;
4. command-line overrides (``--dt``, ``--t-max``, ...);
5. the friction rule: a fixed friction coefficient below
   :data:`engines.base.FRICTION_MARGIN` times the no-sliding bound of the
   excitation (:func:`analytic.bounds.required_friction`) is raised to it.

The result is validated once, by the backend's ``Settings``; an error names the
field and the layer it came from.  :meth:`RunSpec.key` is what a stored result
is keyed by.
"""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["RunSpec", "LAYERS"]

LAYERS = ("defaults", "calibration", "settings file", "command line", "friction rule")


@dataclass(frozen=True)
class RunSpec:
    """One run, resolved (module docstring).

    ``origin``: ``((field, layer), ...)`` for every field a layer set; ``note``:
    one line when the calibration does not hold on the scene (the reference
    settings run), else empty.
    """

    backend: str
    scene: object
    excitation: object
    settings: object
    origin: tuple = ()
    note: str = ""

    @classmethod
    def resolve(cls, backend: str, scene, excitation, *, calibrated: bool = False,
                file_options: dict | None = None, file_name: str = "",
                overrides: dict | None = None,
                overrides_from: str = "the command line") -> "RunSpec":
        """Resolve the layers for ``backend`` on ``scene`` under ``excitation`` (for a
        threshold search: the largest pulse it may try, which the friction rule
        needs).

        Raises
        ------
        TypeError, ValueError
            A value the backend's ``Settings`` refuses, naming the field and the
            layer it came from (e.g. ``dt ... (from --settings FILE)``).
        """
        from trilith_xval import engines
        from trilith_xval.analytic.bounds import required_friction
        from trilith_xval.engines.base import FRICTION_MARGIN
        layers, note = [], ""
        if calibrated and backend in engines.engine_names():
            from trilith_xval.engines.calibration import threshold_choice
            choice = threshold_choice(backend, scene)
            layers.append((f"the calibration of {backend}", choice.options))
            note = choice.note
        if file_options:
            layers.append((f"--settings {file_name}".strip(), file_options))
        if overrides:
            layers.append((overrides_from, overrides))
        values, origin = {}, {}
        for where, options in layers:
            for name, value in options.items():
                values[name], origin[name] = value, where
        try:
            settings = engines.configure(backend, **values)
        except (TypeError, ValueError) as exc:
            import re
            named = {origin[n] for n in values if re.search(rf"\b{re.escape(n)}\b", str(exc))}
            where = sorted(named) or sorted(set(origin.values()))
            raise type(exc)(f"{exc} (from {', '.join(where)})" if where else str(exc)) from None
        friction = getattr(settings, "friction", None)
        if friction is not None:
            need = FRICTION_MARGIN * required_friction(scene, excitation)
            if friction < need:
                settings = engines.configure(backend, settings, friction=need)
                origin["friction"] = "the friction rule"
        return cls(backend, scene, excitation, settings, tuple(sorted(origin.items())), note)

    def key(self) -> dict:
        """What the run's result depends on: its store key."""
        from trilith_xval.compare.run.keys import (backend_version, excitation_dict, scene_dict,
                                      settings_dict)
        return {"backend": self.backend, "version": backend_version(self.backend),
                "scene": scene_dict(self.scene), "excitation": excitation_dict(self.excitation),
                "settings": settings_dict(self.settings)}
