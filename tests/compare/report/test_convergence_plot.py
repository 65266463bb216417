"""The convergence plot keeps the step study and the doubled-iteration runs apart."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from trilith_xval.compare.report import plots  # noqa: E402

ROWS = [{"kind": "dt", "dt": 1e-4, "iterations": 50, "rel_error": 0.03},
        {"kind": "dt", "dt": 5e-5, "iterations": 50, "rel_error": 0.01},
        {"kind": "dt", "dt": 2.5e-5, "iterations": 50, "rel_error": 0.002},
        {"kind": "iterations", "dt": 1e-4, "iterations": 100, "rel_error": -0.02}]


def _doc(rows):
    point = {"omega": 12.0, "convergence": rows}
    return {"config": {"tolerances": {"threshold": 0.02}},
            "spectra": {"no_pendulum": {"engines": {"pymunk": [point]}}}}


def test_rows_split_by_kind():
    dt, err, more = plots._convergence({"convergence": ROWS})
    assert list(dt) == [1e-4, 5e-5, 2.5e-5] and list(err) == [0.03, 0.01, 0.002]
    assert more == [(1e-4, -0.02, 100)]


def test_iteration_runs_are_separate_labelled_markers_off_the_dt_line():
    series = [("pymunk", "no_pendulum", {"omega": 12.0}, plots._convergence({"convergence": ROWS}))]
    fig, ax = plt.subplots()
    plots.convergence_axes(ax, series, 2.0)
    lines = {ln.get_label(): ln for ln in ax.get_lines() if not ln.get_label().startswith("_")}
    step = [ln for name, ln in lines.items() if name.endswith("dt, dt/2, dt/4")]
    more = [ln for name, ln in lines.items() if "doubled solver iterations (100)" in name]
    assert len(step) == 1 and len(more) == 1
    # The step line holds the three 'dt' rows only; -2 % is not on it.
    assert sorted(step[0].get_xdata()) == [2.5e-5, 5e-5, 1e-4]
    assert -2.0 not in list(np.asarray(step[0].get_ydata()))
    assert list(more[0].get_xdata()) == [1e-4] and list(more[0].get_ydata()) == [-2.0]
    assert more[0].get_linestyle() == "None"
    plt.close(fig)


def test_figure_with_both_kinds_and_old_tuple_rows():
    assert plots.convergence_figure(_doc(ROWS))
    assert plots.convergence_figure(_doc([(1e-4, 8.6, 0.03), (5e-5, 8.7, 0.01)]))
    assert plots.convergence_figure(_doc([])) is None
