"""The scan that starts a search without a model (compare.measure.kind_scan.scan):
the pulse spectra and the record fragility of another kind share it."""
from __future__ import annotations

import math

from trilith_xval.compare.measure.kind_scan import SCAN_FACTOR, SCAN_STEPS, scan


def test_the_guess_is_the_geometric_mean_of_the_last_survival_and_the_first_failure():
    probed = []

    def fails(a):
        probed.append(a)
        return a >= 3.0
    guess, runs = scan(fails, 1.0)
    # 1, 1.5, 2.25 survive; 3.375 fails
    assert probed == [1.0, 1.5, 2.25, 3.375] and runs == 4
    assert guess == math.sqrt(2.25 * 3.375)


def test_a_failure_at_the_start_stands_below_it_and_the_top_censors():
    assert scan(lambda a: True, 2.0) == (math.sqrt(2.0 / SCAN_FACTOR * 2.0), 1)
    probed = []
    guess, runs = scan(lambda a: probed.append(a) or False, 1.0, top=3.0)
    assert guess is None and probed[-1] == 3.0 and runs == len(probed) == 4
    # no top: the pulse spectra's scan ends after its fixed number of probes
    assert scan(lambda a: False, 1.0) == (None, SCAN_STEPS)
