"""What changed between two atlases of the same points: per engine and step, how many
rows changed cause and from what to what, and the CPU of the engine jobs.

``python -m trilith_xval.compare.report.atlas_diff OLD.json NEW.json [ENGINE ...]`` prints a
Markdown table (docs/atlas.md quotes it with this command).
"""
from __future__ import annotations

import math
import sys
from collections import Counter

__all__ = ["cause_changes", "markdown"]


def _rows(doc: dict, engine: str) -> dict:
    out = {}
    for pt in doc["points"]:
        for row in pt["engines"].get(engine, ()):
            out[(pt["scene"], pt["case"], pt["pulse"], pt["omega"], round(row["dt"], 12))] = row
    return out


def cause_changes(old: dict, new: dict, engines=None) -> list[dict]:
    """Per engine and step (in either atlas): rows in each, rows in both whose
    cause changed, the changes counted by ``old -> new``, and the engine jobs' CPU
    seconds of each atlas at that step (its cost table)."""
    engines = list(engines or [e for e in new["steps"] if e in old["steps"]])
    cost = {(c["engine"], round(c["dt"], 12), which): c.get("cpu_s")
            for which, doc in (("old", old), ("new", new)) for c in doc.get("cost", [])}
    out = []
    for e in engines:
        a, b = _rows(old, e), _rows(new, e)
        for dt in sorted({k[-1] for k in (*a, *b)}):
            both = [k for k in a if k[-1] == dt and k in b]
            moves = Counter(f"{a[k].get('cause')} -> {b[k].get('cause')}" for k in both
                            if a[k].get("cause") != b[k].get("cause"))
            out.append({"engine": e, "dt": dt,
                        "old_rows": sum(k[-1] == dt for k in a),
                        "new_rows": sum(k[-1] == dt for k in b),
                        "changed": sum(moves.values()), "moves": dict(moves.most_common()),
                        "old_cpu_s": cost.get((e, dt, "old")),
                        "new_cpu_s": cost.get((e, dt, "new"))})
    return out


def markdown(rows: list[dict]) -> str:
    def cpu(x):
        return "-" if x is None or not math.isfinite(x) else f"{x:.0f}"
    lines = ["| engine | dt [s] | rows before / after | causes changed | how | CPU s before / after |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        how = "; ".join(f"{k} ({n})" for k, n in r["moves"].items()) or "-"
        lines.append(f"| {r['engine']} | {r['dt']:g} | {r['old_rows']} / {r['new_rows']} | "
                     f"{r['changed']} | {how} | {cpu(r['old_cpu_s'])} / {cpu(r['new_cpu_s'])} |")
    return "\n".join(lines)


if __name__ == "__main__":
    from trilith_xval.scenes.safe_read import read_json
    old_doc, new_doc = (read_json(p, p) for p in sys.argv[1:3])
    print(markdown(cause_changes(old_doc, new_doc, sys.argv[3:] or None)))
