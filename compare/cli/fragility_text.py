"""The printed summary of ``trilith fragility`` (the figure is
:mod:`compare.report.fragility_plot`, the files :mod:`compare.cli.fragility`)."""
from __future__ import annotations

from trilith_xval.analytic.excitation import G_STANDARD
from trilith_xval.analytic.ida import IM_UNITS, IDASettings

__all__ = ["print_fragility"]


def _value(v: float, st: IDASettings) -> str:
    """An intensity with its unit, and in g beside it for PGA."""
    unit = IM_UNITS[st.im]
    return f"{v:.4g} {unit}".rstrip() + (f" ({v / G_STANDARD:.3g} g)" if st.im == "pga" else "")


def _fit_text(fit: dict, st: IDASettings) -> str:
    """``median M (lo-hi), beta B (lo-hi)`` with the bootstrap's level and size."""
    boot = fit.get("bootstrap") or {}
    text = f"median {_value(fit['median'], st)}"
    m_lo, m_hi = fit.get("median_ci") or (None, None)
    b_lo, b_hi = fit.get("beta_ci") or (None, None)
    if m_lo is not None and m_hi is not None:
        text += f" [{m_lo:.4g}, {m_hi:.4g}]"
    text += f", beta {fit['beta']:.3f}"
    if b_lo is not None and b_hi is not None:
        text += f" [{b_lo:.3f}, {b_hi:.3f}]"
    if boot and m_lo is not None:
        text += (f" ({100 * boot['level']:g} % bootstrap, {boot['fitted']} of "
                 f"{boot['resamples']} resamples fitted, seed {boot['seed']})")
    return text


def print_fragility(doc: dict, st: IDASettings) -> None:
    """The summary of a ``trilith fragility`` result ``doc``: per backend the IDA
    fit with its bootstrap intervals, the MSA fit beside it (with ``--stripes``),
    and what the fit leaves out (islands, isolated overturns, records without a
    robust bracket, long runs) and each engine's agreement with the model."""
    unit = IM_UNITS[st.im]
    # Another kind: a failure is an overturn or a collapse (engines.structure_monitor).
    what = "failure" if doc.get("engine_against_engine") else "overturn"
    for b, body in doc["backends"].items():
        fit = body["fit"] or {"median": None, "n": 0, "n_censored": 0}
        med = fit["median"]
        shown = f"no fit (fewer than 2 {what}s)" if med is None else _fit_text(fit, st)
        print(f"{b}: IDA, {fit['n']} records, {fit['n_censored']} never "
              f"{'failed' if what == 'failure' else 'overturned'} up to "
              f"{st.im_hi:g} {unit}; {shown}")
        msa = body.get("msa")
        if msa:
            print(f"  MSA, {len(msa['stripes'])} stripes of {msa['n'][0]} runs, overturned "
                  f"{'/'.join(str(z) for z in msa['overturned'])}; "
                  + ("no fit (the counts do not bound beta)" if msa["median"] is None
                     else _fit_text(msa, st)))
        islands = sum(len(r["islands"]) for r in body["records"])
        if islands:
            print(f"  {islands} survival islands above a first overturn (see fragility.csv)")
        isolated = sum(len(r.get("isolated", ())) for r in body["records"])
        loose = [r["label"] for r in body["records"] if not r.get("bracketed", True)]
        if isolated:
            print(f"  {isolated} isolated overturns (not reproduced by their perturbed "
                  "neighbours; in fragility.json, never a threshold)")
        if loose:
            print(f"  no robust bracket (left out of the fit): {', '.join(loose)}")
        for r in body["records"]:
            if r.get("collapsed"):
                print(f"  {r['label']}: the frame collapsed (not an overturn) at "
                      f"{', '.join(f'{a:.4g}' for a in r['collapsed'])} {unit}")
            if r.get("bracket") and r["censored"]:
                print(f"  {r['label']}: overturns above the range, between "
                      f"{r['bracket'][0]:.4g} and {r['bracket'][1]:.4g} {unit}")
        for r in body["records"]:
            lr = r.get("long_run")
            if lr:
                print(f"  {r['label']} at {lr['im_value']:.4g} {unit} ({lr['t_end']:.3g} s "
                      f"{lr['status']}): pivot slid {lr['pivot_sliding_max']:.3g} m, lintel "
                      f"turned {lr['lintel_rotation_max']:.3g} rad, residual tilt "
                      f"{lr['residual_tilt']:.3g} rad (model {lr['model_residual_tilt']:.3g})")
        ag = body.get("agreement")
        if ag:
            ratio = "n/a" if ag["median_ratio"] is None else f"{ag['median_ratio']:.3f}"
            print(f"  vs model: median ratio {ratio}, largest distance fitted "
                  f"{ag['max_distance_fit'] if ag['max_distance_fit'] is not None else 'n/a'}"
                  f", empirical {ag['max_distance_empirical']:.3f}")
