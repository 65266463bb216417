"""``trilith restitution`` on a scene the model does not cover: free rocking from a
tilt, each engine's measured velocity ratio per impact and the engines against each
other (:mod:`compare.measure.restitution_kinds`); there is no Eq. 19/20 for them."""
from __future__ import annotations

import math

from trilith_xval.compare.cli.options import (envelope, info, print_json, run_spec,
                                              settings_from_args, use_store)

__all__ = ["kind_restitution"]


def _checked(args, scene):
    """``(engines, theta0, n)`` or one line refusing, before any work, what has no
    meaning without a model or cannot be released."""
    from trilith_xval.compare.cli.options import check_structure_engines, parse_engine_list
    from trilith_xval.compare.measure.restitution import (DEFAULT_N_IMPACTS,
                                                          DEFAULT_THETA0_FRACTION, MAX_N_IMPACTS)
    from trilith_xval.engines.geometry import RELEASE_KINDS, STRUCTURE_ENGINES, release_limit
    kind = scene.kind
    if kind not in RELEASE_KINDS:
        raise ValueError(f"trilith restitution: the {kind} kind has no free-rocking release "
                         f"(its parts do not turn as one; released: {', '.join(RELEASE_KINDS)})")
    names = parse_engine_list(args.engine)
    if len(names) < 2:
        raise ValueError(f"--engine: there is no Eq. 19/20 for the {kind} kind; give two or "
                         f"more engines to check against each other "
                         f"({', '.join(STRUCTURE_ENGINES)}), got {','.join(names)}")
    check_structure_engines(names, kind, "restitution")
    if args.psi0 != 0.0:
        raise ValueError(f"--psi0: the {kind} kind is released with its bob at rest (0)")
    if getattr(args, "restitution_factor", None) not in (None, 1.0):
        raise ValueError(f"--restitution-factor: there is no model of the {kind} kind to scale")
    limit = release_limit(scene)
    theta0 = args.theta0 if args.theta0 is not None else DEFAULT_THETA0_FRACTION * limit
    if not (math.isfinite(theta0) and 0.0 < abs(theta0) < limit):
        raise ValueError(f"--theta0 must satisfy 0 < |theta0| < {limit:.4g} rad (the {kind} "
                         f"kind's release limit: its turned part's centre of mass over the "
                         f"pivot), got {theta0!r}")
    n = args.n_impacts if args.n_impacts is not None else DEFAULT_N_IMPACTS
    if not 1 <= n <= MAX_N_IMPACTS:
        raise ValueError(f"--n-impacts must be in [1, {MAX_N_IMPACTS}], got {n}")
    return names, theta0, n


def _per_impact(results: dict, n: int) -> list[dict]:
    """Per impact the engines' median ratio, deviations and status
    (:func:`compare.measure.consensus.consensus`: 'disagree' beyond 2 % for two
    engines, outliers beyond it among three or more)."""
    from trilith_xval.compare.measure.consensus import consensus
    out = []
    for k in range(n):
        owns = {}
        for e, r in results.items():
            row = r["impacts"][k] if k < len(r["impacts"]) else None
            ok = row is not None and math.isfinite(row["ratio"])
            owns[e] = {"converged": ok, "a_fails": row["ratio"] if ok else None,
                       "failure": "impact", "dt": r["dt"], "cause": None if ok else "no impact",
                       "detail": None if ok else f"no measured impact {k + 1} ({r['status']})"}
        c = consensus(owns)
        out.append({"impact": k + 1, "median": c["median"], "status": c["status"],
                    "deviations": {e: v["deviation"] for e, v in c["engines"].items()},
                    "outliers": [o["engine"] for o in c["outliers"]],
                    "no_answer": c["no_answer"]})
    return out


def kind_restitution(args, scene) -> int:
    """The command on a scene of another kind (module docstring)."""
    from trilith_xval.analytic.excitation import Still
    from trilith_xval.compare.measure.restitution_kinds import kind_free_rocking
    names, theta0, n = _checked(args, scene)
    loaded = settings_from_args(args, names)
    runs = {e: run_spec(e, scene, Still(), loaded) for e in names}  # before any work
    use_store(args)
    results = {e: kind_free_rocking(run, theta0, n) for e, run in runs.items()}
    points = _per_impact(results, n)
    if args.json:
        inputs = {"scene": scene.to_dict(), "excitation": {"type": "still"}, "engines": names,
                  "theta0": theta0, "n_impacts": n,
                  "settings_file": None if loaded is None else loaded.describe()}
        print_json(envelope("restitution", inputs, {"kind": scene.kind, "model": None,
                                                    "engines": results, "impacts": points}, {}))
        return 0
    print(f"scene {scene.name} ({scene.kind}): no model (no Eq. 19/20); free rocking from "
          f"theta0 = {theta0:.4g} rad, each engine's measured velocity ratio per impact; "
          "engine against engine")
    for e, r in results.items():
        one = ("the structure rocks as one" if r["as_one"] else
               "the bodies above do not rock with it: largest rotations "
               + ", ".join(f"{b} {v:.3g}" for b, v in r["max_rotation"].items()) + " rad")
        print(f"  {e} (dt {r['dt']:g} s, {r['status']}): the ratio is of {r['body']}; {one}")
    head = "".join(f" {e:>10}" for e in names)
    print(f"{'#':>3}{head} {'median':>9} {'status':>10}")
    for p in points:
        cells = "".join(f" {results[e]['impacts'][p['impact'] - 1]['ratio']:10.4f}"
                        if p["impact"] <= len(results[e]["impacts"]) else f" {'-':>10}"
                        for e in names)
        median = f"{p['median']:9.4f}" if p["median"] is not None else f"{'-':>9}"
        print(f"{p['impact']:>3}{cells} {median} {p['status']:>10}")
        for miss in p["no_answer"]:
            info(f"  impact {p['impact']}: {miss['engine']} has none ({miss['detail']})")
    info("engine against engine, never agreement with a model (docs/geometry.md)")
    return 0
