"""``trilith calibrate`` on a scene of another kind (drums, unequal columns, a block
on a block): what it refuses, what it prints and the tables its settings file gets
(:mod:`compare.campaign.calibrate_kinds` measures: the engine's step against its
own reference step, self-convergence, no model)."""
from __future__ import annotations

__all__ = ["check_kind_calibration", "print_self_reference", "kind_tables"]


def check_kind_calibration(args, scenes, rf: float) -> str:
    """The scenes' kind; on another kind than the trilith, one line refusing what has
    no target without a model (before any work)."""
    from trilith_xval.compare.campaign.calibrate_kinds import scene_kind
    kind = scene_kind(scenes)
    if kind == "trilith":
        return kind
    if args.metric != "thresholds":
        raise ValueError(f"--metric {args.metric}: there is no model of the {kind} kind (no "
                         "Eq. 19/20, no model theta); on it only --metric thresholds, the "
                         "engine against its own reference step")
    if rf != 1.0:
        raise ValueError(f"--restitution-factor: there is no model of the {kind} kind to "
                         "scale")
    return kind


def print_self_reference(cal) -> None:
    """What a kind's errors are (self-convergence), and the reference they are from."""
    ref = cal.self_reference
    print(f"{cal.kind} kind: no model; each error is the difference from {cal.engine}'s own "
          f"first failing amplitude at its reference step dt = {ref['dt_ref']:g} s "
          "(self-convergence), not agreement with a model or another engine")
    for name, rows in ref["thresholds"].items():
        cells = ", ".join(f"Omega {w}: " + (f"{r['a_fails']:.4g} m/s^2 ({r['failure']})"
                                            if r["a_fails"] is not None else "no failure")
                          for w, r in rows.items())
        print(f"  reference {name}: {cells}")


def kind_tables(cal, scenes) -> str:
    """The ``[domain]`` (the kind: the file is refused on any other) and
    ``[calibration]`` tables of a settings file calibrated on another kind."""
    rec = cal.recommended
    names = ", ".join(f'"{sc.name}"' for sc in scenes)
    return "\n".join([
        "", "# Calibrated on this kind only, against the engine's own reference step",
        "# (self-convergence, no model): --settings refuses it on any other kind.",
        "[domain]", f'kind = "{cal.kind}"', "", "[calibration]",
        'target = "self-convergence"', f"reference_dt = {cal.self_reference['dt_ref']!r}",
        f"scenes = [{names}]", f"worst_error = {rec.worst_error!r}",
        f"tolerance = {cal.tolerance!r}"]) + "\n"
