"""A run is a value: :class:`RunSpec` (backend, scene, excitation, settings), resolved once.

Settings come in layers, each over the one before, in one place
(:meth:`RunSpec.resolve`):

1. the backend's defaults (its ``Settings``);
2. its calibration, for threshold searches, where the scene lies in the
   calibration's domain (:func:`engines.calibration.threshold_choice`);
3. a ``--settings`` file's table;
4. command-line overrides (``--dt``, ``--t-max``, ...);
5. the friction rule, on the excitation (for a threshold search: the largest
   pulse it may try, so every run of the search has the same friction).  A
   friction the defaults or the calibration fixed is raised to
   :data:`engines.base.FRICTION_MARGIN` times the no-sliding bound
   (:func:`analytic.bounds.required_friction`); a friction the user gave (a
   settings file, the command line) is kept as given, and refused when it is
   below the bound itself (the pivots would slide: not the paper's mechanism).

The result is validated once, by the backend's ``Settings``; an error names the
field and the layer it came from.  :meth:`RunSpec.key` is what a stored result
is keyed by.  A spec remembers its layers, so the same run on another scene or
excitation (:meth:`RunSpec.at`) or with one more layer (:meth:`RunSpec.with_options`,
e.g. the step rule's finer step) resolves by the same rules.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["RunSpec", "LAYERS"]

LAYERS = ("defaults", "calibration", "settings file", "command line", "friction rule")


def _frozen(options: dict | None) -> tuple:
    return tuple(sorted((options or {}).items()))


@dataclass(frozen=True)
class RunSpec:
    """One run, resolved (module docstring).

    ``origin``: ``((field, layer), ...)`` for every field a layer set; ``note``:
    one line when the calibration does not hold on the scene (the reference
    settings run), else empty; ``layers``: the layers over the calibration,
    ``((where, ((field, value), ...)), ...)``; ``calibrated``: whether the
    calibration layer applies (threshold searches).
    """

    backend: str
    scene: object
    excitation: object
    settings: object
    origin: tuple = ()
    note: str = ""
    layers: tuple = ()
    calibrated: bool = False

    @classmethod
    def resolve(cls, backend: str, scene, excitation=None, *, calibrated: bool = False,
                file_options: dict | None = None, file_name: str = "",
                overrides: dict | None = None,
                overrides_from: str = "the command line") -> "RunSpec":
        """Resolve the layers for ``backend`` on ``scene`` under ``excitation``.

        Parameters
        ----------
        backend : str
            A registered backend name.
        scene, excitation
            The run's scene and ground motion (for a threshold search, the
            largest pulse it may try, which the friction rule needs); default
            :class:`~analytic.excitation.Still` (a template whose points
            :meth:`at` resolves at their own pulses).
        calibrated : bool
            Apply the engine's calibrated threshold settings where ``scene`` lies
            in their domain (default False: the backend's defaults).
        file_options, file_name : dict, str
            A ``--settings`` file's table for ``backend`` and the file's name.
        overrides, overrides_from : dict, str
            The last layer and where it came from (default: the command line).

        Raises
        ------
        TypeError, ValueError
            A value the backend's ``Settings`` refuses, naming the field and the
            layer it came from (e.g. ``dt ... (from --settings FILE)``); a
            friction given below the no-sliding bound.
        """
        if excitation is None:
            from trilith_xval.analytic.excitation import Still
            excitation = Still()
        layers = []
        if file_options:
            layers.append((f"--settings {file_name}".strip(), _frozen(file_options)))
        if overrides:
            layers.append((overrides_from, _frozen(overrides)))
        return cls._resolved(backend, scene, excitation, calibrated, tuple(layers))

    @classmethod
    def _resolved(cls, backend, scene, excitation, calibrated: bool, user_layers: tuple):
        from trilith_xval import engines
        layers, note = [], ""
        if calibrated and backend in engines.engine_names():
            from trilith_xval.engines.calibration import threshold_choice
            choice = threshold_choice(backend, scene)
            layers.append((f"the calibration of {backend}", _frozen(choice.options)))
            note = choice.note
        values, origin = {}, {}
        for where, options in (*layers, *user_layers):
            for name, value in options:
                values[name], origin[name] = value, where
        try:
            settings = engines.configure(backend, **values)
        except (TypeError, ValueError) as exc:
            named = {origin[n] for n in values if re.search(rf"\b{re.escape(n)}\b", str(exc))}
            where = sorted(named) or sorted(set(origin.values()))
            raise type(exc)(f"{exc} (from {', '.join(where)})" if where else str(exc)) from None
        settings, origin = _friction_rule(backend, scene, excitation, settings, origin)
        return cls(backend, scene, excitation, settings, tuple(sorted(origin.items())), note,
                   user_layers, calibrated)

    def at(self, scene=None, excitation=None) -> "RunSpec":
        """The same layers on another ``scene`` and/or ``excitation`` (the
        calibration's domain and the friction rule evaluated for them)."""
        return self._resolved(self.backend, self.scene if scene is None else scene,
                              self.excitation if excitation is None else excitation,
                              self.calibrated, self.layers)

    def with_options(self, where: str, **values) -> "RunSpec":
        """This run with one more layer over the others (``where`` names it in
        errors and in ``origin``), e.g. a finer step of the step rule."""
        return self._resolved(self.backend, self.scene, self.excitation, self.calibrated,
                              (*self.layers, (where, _frozen(values))))

    def key(self) -> dict:
        """What the run's result depends on: its store key."""
        from trilith_xval.compare.run.keys import (backend_version, excitation_dict, scene_dict,
                                                   settings_dict)
        return {"backend": self.backend, "version": backend_version(self.backend),
                "scene": scene_dict(self.scene), "excitation": excitation_dict(self.excitation),
                "settings": settings_dict(self.settings)}


def _friction_rule(backend, scene, excitation, settings, origin: dict):
    """Layer 5 (module docstring): ``(settings, origin)`` after it."""
    from trilith_xval import engines
    from trilith_xval.analytic.bounds import required_friction
    from trilith_xval.engines.base import FRICTION_MARGIN
    friction = getattr(settings, "friction", None)
    if friction is None:  # the engine's own default, which follows the same rule per run
        return settings, origin
    if getattr(scene, "kind", "trilith") != "trilith":
        # Another kind (analytic.kinds): no model, so no no-sliding bound; a body moving
        # with the ground needs PGA/g, as engines.base checks.
        need = excitation.acceleration_bound() / scene.g
    else:
        need = required_friction(scene, excitation)
    where = origin.get("friction", "")
    if not where.startswith("the calibration of"):  # the user's own value: kept, checked
        if friction < need:
            raise ValueError(f"friction must be >= {need:.4g}, the no-sliding bound of scene "
                             f"{getattr(scene, 'name', '')!s} under a peak ground acceleration "
                             f"of {excitation.acceleration_bound():.4g} m/s^2 (analytic.bounds."
                             f"required_friction), got {friction!r} (from {where})")
        return settings, origin
    if friction < FRICTION_MARGIN * need:
        settings = engines.configure(backend, settings, friction=FRICTION_MARGIN * need)
        origin = {**origin, "friction": "the friction rule"}
    return settings, origin
