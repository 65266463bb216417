"""The OpenSees peer beside the model (issue 36, item 3): writes
``docs/validation/peer_opensees.json``.

    nice -n 10 python -m benchmarks.peer_opensees [--out PATH] [--quick]

1. Free rocking from rest at ``theta0 = alpha/2`` (scene ``single_block`` and two
   other slenderness values): the restitution at every impact measured from the
   peaks (``compare.peers.opensees_block.rocking_cycles``) against Housner's
   ``1 - 1.5 sin^2(alpha)``, and the impact times against the project's model
   (``analytic.simulate`` with ``Still()`` and ``theta0``).
2. How the measured restitution moves with the contact damping ratio, the
   contact stiffness (static penetration) and the time step (``single_block``).
3. One-sine overturning thresholds at 8 (scene, Omega) points: the model's
   (``analytic.spectrum.overturning_spectrum``) and the peer's (bisection inside
   +-7 % of the model's), and at one point with the contact damping doubled.

Records the command, the openseespy version, the CPU seconds of each part
(``time.process_time``) and the load average.  About 6.5 CPU minutes (388 s measured).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

SCHEMA = "trilith-xval/peer-opensees/1"
ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "validation" / "peer_opensees.json"

# (scene overrides of single_block, Omega [rad/s]); b = 0.6 m full width throughout
THRESHOLD_POINTS = [({}, 3.0), ({}, 5.0), ({}, 8.0), ({}, 12.0), ({}, 16.0),
                    ({"lam": 4.0}, 6.0), ({"lam": 4.0}, 10.0), ({"lam": 8.0}, 5.0)]
FREE_SCENES = [({}, 4.0), ({"lam": 4.0}, 3.0), ({"lam": 8.0}, 5.0)]  # (overrides, t_end)
BRACKET = 0.07  # the peer's bisection bracket: the model's threshold +- 7 %
RTOL = 2e-3     # the peer's bisection resolution (relative)


def _half(scene):
    """The peer's half-width and half-height [m] of a project Scene (full b, h)."""
    return 0.5 * scene.b, 0.5 * scene.h


def _free(ob, scene, t_end, cs, analytic_impacts=None) -> dict:
    b, h = _half(scene)
    c0 = time.process_time()
    t, th = ob.free_rocking(b, h, 0.5 * scene.alpha, t_end, cs)
    cyc = ob.rocking_cycles(t, th, scene.alpha)
    out = {"contact": cs.describe(), "t_end": t_end,
           "restitution": cyc["restitution"],
           "housner": ob.housner_restitution(b, h),
           "impacts": cyc["impacts"],
           "peaks_over_alpha": [p / scene.alpha for _, p in cyc["peaks"]],
           "cpu_s": time.process_time() - c0}
    r = cyc["restitution"][:4]
    out["restitution_mean_first4"] = sum(r) / len(r) if r else math.nan
    out["restitution_error_first4"] = out["restitution_mean_first4"] / out["housner"] - 1.0
    if analytic_impacts is not None:
        n = min(len(analytic_impacts), len(cyc["impacts"]), 5)
        out["model_impacts"] = analytic_impacts[:n]
        out["impact_time_error_s"] = [cyc["impacts"][i] - analytic_impacts[i] for i in range(n)]
        ha = [analytic_impacts[i + 1] - analytic_impacts[i] for i in range(n - 1)]
        hp = [cyc["impacts"][i + 1] - cyc["impacts"][i] for i in range(n - 1)]
        out["half_cycle_rel_error"] = [p / a - 1.0 for p, a in zip(hp, ha)]
    return out


def _model_impacts(scene, t_end: float) -> list[float]:
    from trilith_xval.analytic.excitation import Still
    from trilith_xval.analytic.simulate import Settings, simulate
    tr = simulate(scene, Still(), Settings(theta0=0.5 * scene.alpha, t_max=t_end))
    return [float(e.t) for e in tr.events if e.kind == "impact"]


def _model_threshold(scene, omega: float) -> dict:
    from trilith_xval.analytic.spectrum import overturning_spectrum
    sp = overturning_spectrum(scene, [omega])
    return {"a_over": float(sp.a_no_pendulum[0]), "a_safe": float(sp.a_no_pendulum_safe[0]),
            "mode": sp.mode_no_pendulum[0]}


def _peer_threshold(ob, scene, omega, a_model, cs) -> dict:
    b, h = _half(scene)
    c0 = time.process_time()
    try:
        res = ob.threshold(b, h, omega, cs, lo=(1 - BRACKET) * a_model,
                           hi=(1 + BRACKET) * a_model, rtol=RTOL)
        res["error"] = None
    except ValueError as exc:  # the peer's threshold is outside the bracket
        res = {"a_over": math.nan, "a_safe": math.nan, "runs": 2, "error": str(exc)}
    res["cpu_s"] = time.process_time() - c0
    res["contact"] = cs.describe()
    return res


def _name(ov: dict) -> str:
    return "single_block" + "".join(f", {k} {v:g}" for k, v in ov.items())


def tables(doc: dict) -> str:
    """The Markdown tables of docs/peers.md, from a stored result."""
    lines = ["| scene | alpha [rad] | Housner r | peer r (impacts 1-4) | error | "
             "impact times - model's [ms] | half-cycles vs model's |",
             "|---|---|---|---|---|---|---|"]
    for r in doc["free_rocking"]:
        dt = ", ".join(f"{1e3 * e:+.1f}" for e in r.get("impact_time_error_s", []))
        hc = ", ".join(f"{100 * e:+.2f} %" for e in r.get("half_cycle_rel_error", []))
        lines.append(f"| {_name(r['overrides'])} | {r['alpha']:.4f} | {r['housner']:.5f} | "
                     + ", ".join(f"{x:.5f}" for x in r["restitution"][:4])
                     + f" | {100 * r['restitution_error_first4']:+.2f} % | {dt} | {hc} |")
    lines += ["", "| single_block, changed from the default | peer r (impacts 1-4) | "
              "error vs Housner | CPU s |", "|---|---|---|---|"]
    for r in doc["restitution_sweep"]:
        lines.append(f"| {r['label']} | " + ", ".join(f"{x:.5f}" for x in r["restitution"][:4])
                     + f" | {100 * r['restitution_error_first4']:+.2f} % | {r['cpu_s']:.1f} |")
    lines += ["", "| scene | Omega [rad/s] | Omega/p | model: safe, overturns [m/s^2] (mode) | "
              "peer: safe, overturns [m/s^2] | peer - model (overturning) | peer runs, CPU s |", "|---|---|---|---|---|---|---|"]
    for p in doc["thresholds"] + [dict(q, overrides={"zeta": q["peer"]["contact"]["zeta"]})
                                  for q in doc.get("threshold_sensitivity", [])]:
        lines.append(f"| {_name(p['overrides'])} | {p['omega']:g} | "
                     f"{p['omega'] / p['p']:.2f} | " if "p" in p else
                     f"| single_block, contact zeta {p['overrides']['zeta']:g} | {p['omega']:g} | "
                     f"| ")
        m, q = p["model"], p["peer"]
        lines[-1] += (f"{m['a_safe']:.4f}, {m['a_over']:.4f} ({m['mode']}) | "
                      f"{q['a_safe']:.4f}, {q['a_over']:.4f} | "
                      f"{100 * p['rel_error']:+.2f} % | {q['runs']}, {q['cpu_s']:.0f} |")
    lines += ["", f"openseespy {doc['openseespy']}, {doc['cpu_s']:.0f} CPU s in all, load average "
              f"{doc['load_average_start'][0]:.2f} at the start, {doc['load_average_end'][0]:.2f} "
              f"at the end; {doc['newton_substeps']} steps retried in sub-steps."]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument("--quick", action="store_true", help="two threshold points, no sweep")
    ap.add_argument("--table", action="store_true",
                    help="print the tables of docs/peers.md from --out and stop")
    args = ap.parse_args(argv)
    if args.table:
        print(tables(json.loads(args.out.read_text())))
        return 0
    from trilith_xval.compare.peers import opensees_block as ob
    from trilith_xval.scenes import load_scene

    load0, cpu0 = os.getloadavg(), time.process_time()
    cs = ob.ContactSettings()
    doc = {"schema": SCHEMA,
           "command": "nice -n 10 python -m benchmarks.peer_opensees " + " ".join(
               argv if argv is not None else sys.argv[1:]),
           "openseespy": ob.version(), "python": platform.python_version(),
           "machine": platform.machine(), "contact": cs.describe(),
           "units": "SI: m, s, rad, m/s^2; scene b is the full width (the peer's "
                    "half-width is b/2), h = lam b", "load_average_start": list(load0)}

    # 1. free rocking against Housner and the model
    free = []
    for ov, t_end in (FREE_SCENES[:1] if args.quick else FREE_SCENES):
        scene = load_scene("single_block", **ov)
        row = _free(ob, scene, t_end, cs, _model_impacts(scene, t_end))
        row.update(scene="single_block", overrides=ov, alpha=scene.alpha)
        free.append(row)
        print(f"free {ov or 'single_block'}: r {row['restitution_mean_first4']:.5f} vs "
              f"Housner {row['housner']:.5f} ({row['restitution_error_first4']:+.3%}); "
              f"impact times {['%+.4f' % e for e in row.get('impact_time_error_s', [])]} s; "
              f"{row['cpu_s']:.1f} CPU s", flush=True)
    doc["free_rocking"] = free

    # 2. what moves the restitution (single_block)
    sweep = []
    if not args.quick:
        base = load_scene("single_block")
        for label, c in (("zeta 0 (elastic contact)", replace(cs, zeta=0.0)),
                         ("zeta 0.1", replace(cs, zeta=0.1)),
                         ("zeta 0.25", replace(cs, zeta=0.25)),
                         ("zeta 1", replace(cs, zeta=1.0)),
                         ("zeta 2", replace(cs, zeta=2.0)),
                         ("20 steps per contact period", replace(cs, steps_per_contact=20.0)),
                         ("150 steps per contact period", replace(cs, steps_per_contact=150.0)),
                         ("penetration 1e-6 b (k_n x10)", replace(cs, penetration=1e-6)),
                         ("penetration 1e-4 b (k_n /10)", replace(cs, penetration=1e-4)),
                         ("friction 1", replace(cs, friction=1.0)),
                         ("Newmark (no numerical damping)", replace(cs, hht_alpha=1.0)),
                         ("Newmark, 150 steps per contact period",
                          replace(cs, hht_alpha=1.0, steps_per_contact=150.0)),
                         ("Newmark, penetration 1e-6 b",
                          replace(cs, hht_alpha=1.0, penetration=1e-6))):
            try:
                row = _free(ob, base, 3.0, c)
            except RuntimeError as exc:  # OpenSees gave up on a step
                row = {"contact": c.describe(), "restitution": [], "error": str(exc),
                       "restitution_mean_first4": math.nan,
                       "restitution_error_first4": math.nan, "cpu_s": math.nan}
            row["label"] = label
            sweep.append(row)
            print(f"sweep {label}: r {row['restitution_mean_first4']:.5f} "
                  f"({row['restitution_error_first4']:+.3%}); {row['cpu_s']:.1f} CPU s", flush=True)
    doc["restitution_sweep"] = sweep

    # 3. one-sine thresholds
    points = []
    for ov, omega in (THRESHOLD_POINTS[1:3] if args.quick else THRESHOLD_POINTS):
        scene = load_scene("single_block", **ov)
        c0 = time.process_time()
        model = _model_threshold(scene, omega)
        model["cpu_s"] = time.process_time() - c0
        peer = _peer_threshold(ob, scene, omega, model["a_over"], cs)
        row = {"scene": "single_block", "overrides": ov, "omega": omega,
               "alpha": scene.alpha, "p": math.sqrt(3.0 * 9.81 / (4.0 * scene.R)),
               "model": model, "peer": peer,
               "rel_error": peer["a_over"] / model["a_over"] - 1.0}
        points.append(row)
        print(f"threshold {ov or 'single_block'} Omega {omega:g}: model {model['a_over']:.4f} "
              f"peer {peer['a_over']:.4f} ({row['rel_error']:+.2%}); {peer['cpu_s']:.1f} CPU s",
              flush=True)
    doc["thresholds"] = points

    # 4. one threshold with the contact damping doubled (zeta 1)
    sens = []
    if not args.quick:
        scene = load_scene("single_block")
        m = next(p["model"] for p in points if p["omega"] == 5.0 and not p["overrides"])
        for c in (replace(cs, zeta=1.0),):
            peer = _peer_threshold(ob, scene, 5.0, m["a_over"], c)
            sens.append({"scene": "single_block", "omega": 5.0, "model": m, "peer": peer,
                         "rel_error": peer["a_over"] / m["a_over"] - 1.0})
            print(f"threshold zeta {c.zeta}: peer {peer['a_over']:.4f} "
                  f"({sens[-1]['rel_error']:+.2%})", flush=True)
    doc["threshold_sensitivity"] = sens

    doc["newton_substeps"] = ob.SUBSTEPS["count"]
    doc["cpu_s"] = time.process_time() - cpu0
    doc["load_average_end"] = list(os.getloadavg())
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(doc, indent=1, default=float) + "\n")
    print(f"wrote {args.out} ({doc['cpu_s']:.0f} CPU s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
