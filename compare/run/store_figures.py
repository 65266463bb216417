"""The run store's figures and checks, read-only: entry counts, costs, code
versions (``trilith cache info``) and the proof of every entry (``trilith cache
verify``).  Mixed into :class:`compare.run.store.RunStore`, whose ``_query``,
``_connect`` and ``_legacy`` they use."""
from __future__ import annotations

from trilith_xval.compare.run import store_db
from trilith_xval.compare.run.codec import MAGIC, decode

__all__ = ["StoreFigures"]


class StoreFigures:
    """Read-only questions to a run store (see :class:`compare.run.store.RunStore`)."""

    def count(self, kind: str | None = None, since: float | None = None) -> int:
        """Entries (of ``kind``; created at or after ``since``, a ``time.time()``)."""
        sql, args = "SELECT COUNT(*) FROM runs WHERE 1", []
        if kind is not None:
            sql, args = sql + " AND kind = ?", [*args, kind]
        if since is not None:
            sql, args = sql + " AND created >= ?", [*args, since]
        rows = self._query(sql, args)
        return int(rows[0][0]) if rows else 0

    def created(self) -> dict[str, float]:
        """Key -> creation time of every entry (tests: nothing was rewritten)."""
        return dict(self._query("SELECT key, created FROM runs"))

    def mean_costs(self, kind: str = "run") -> dict[str, tuple[float, int]]:
        """Label -> (mean cost [s], count) over the stored entries of ``kind``."""
        rows = self._query("SELECT label, AVG(cost), COUNT(*) FROM runs WHERE kind = ? "
                           "GROUP BY label", (kind,))
        return {label: (float(mean), int(n)) for label, mean, n in rows}

    def by_code(self) -> list[tuple[str, int, int]]:
        """``(code version, entries, value bytes)`` per code version; entries this
        format did not write (old pickles) are grouped under ``'foreign'``."""
        if self._connect() is not None and self._legacy:  # read-only, never migrated
            rows = self._query("SELECT COUNT(*), SUM(length(value)) FROM runs")
            return [("foreign", int(n), int(size or 0)) for n, size in rows if n]
        rows = self._query(
            "SELECT CASE WHEN substr(value, 1, ?) = ? THEN code ELSE 'foreign' END AS c, "
            "COUNT(*), SUM(length(value)) FROM runs GROUP BY c ORDER BY c",
            (len(MAGIC), MAGIC))
        return [(code or "unknown", int(n), int(size or 0)) for code, n, size in rows]

    def verify(self):
        """Every entry whose digest or value does not check, without serving any.

        Returns
        -------
        checked : int
            Entries read.
        bad : list of tuple
            ``(key, kind, label, why)`` per entry that would not be served.
        """
        if self._connect() is None:
            return 0, []
        bad = []
        problems = [r[0] for r in self._query("PRAGMA quick_check") if r[0] != "ok"]
        if problems:
            bad.append(("-", "database", "-", "; ".join(problems[:3])))
        if self._legacy:
            rows = self._query("SELECT key, kind, label, value, '' FROM runs")
        else:
            rows = self._query("SELECT key, kind, label, value, digest FROM runs")
        entries = store_db.bad_entries(rows, decode)
        return len(rows), bad + entries

