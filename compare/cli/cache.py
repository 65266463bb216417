"""``trilith cache info|verify|prune|clear``: the run store's size and housekeeping.

``info`` prints the store's directory, its size on disk and its entries by code
version (project version + source digest; ``current`` marks the versions this
checkout writes).  ``prune`` deletes the entries of every other code version
(they can never be reused: the key holds the source digest) and old entries of
a format that is never read, and entries that fail their digest.  ``verify``
reads every entry and checks its digest and format: exit 0 when all are
proven, 1 naming every entry that would not be served.  ``clear`` deletes the store's files
(``runs.sqlite`` and its ``-wal``/``-shm``), nothing else in the directory.
None of them creates a store, and none touches a ``runs.sqlite`` that is not
this tool's (one ``error:`` line, exit 2).
"""
from __future__ import annotations

import argparse

from trilith_xval.compare.cli.options import envelope, info, print_json


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("cache", help="size of the run store; prune or clear it",
                              description=__doc__)
    p.add_argument("action", choices=("info", "verify", "prune", "clear"),
                   help="info: size and entries; verify: check every entry's digest; "
                        "prune: drop other code versions and bad entries; "
                        "clear: delete the store")
    p.add_argument("--cache", metavar="DIR", default=None,
                   help="run store directory [$TRILITH_CACHE or the default store]")
    p.add_argument("--json", action="store_true", help="print a JSON object (info)")


def _size(store) -> int:
    return sum(p.stat().st_size for p in store.files())


def _mib(n: int) -> str:
    return f"{n / 2**20:.3g} MiB"


def run(args: argparse.Namespace) -> int:
    from trilith_xval.compare.cli.options import store_location
    from trilith_xval.compare.run.store import RunStore

    directory, source = store_location(args)
    store = RunStore(directory, check_database=args.action != "clear", source=source)
    try:
        return _act(store, args)
    finally:
        store.close()  # no connection left open (a read-only mount must unmount)


def _act(store, args) -> int:
    from trilith_xval.compare.run.keys import CODE_SETS, code_version
    current = {code_version(packages) for packages in CODE_SETS}
    if args.action == "clear":
        n = store.clear()
        info(f"cleared {store.directory}" + (f": {n} entries removed" if n >= 0 else ""))
        return 0
    if args.action == "prune":
        before = _size(store)
        removed = store.prune(current)
        info(f"pruned {store.directory}: {removed} entries removed, "
             f"{_mib(before)} -> {_mib(_size(store))}")
        return 0
    if args.action == "verify":
        return _verify(store, args)
    groups = store.by_code()
    size = _size(store)
    if args.json:
        print_json(envelope("cache", {"directory": str(store.directory)},
                            {"bytes": size, "entries": sum(n for _, n, _ in groups),
                             "by_code": [{"code": c, "entries": n, "bytes": b,
                                          "current": c in current} for c, n, b in groups]},
                            {}))
        return 0
    print(f"store {store.directory}: {_mib(size)} on disk, "
          f"{sum(n for _, n, _ in groups)} entries")
    for code, n, nbytes in groups:
        mark = "  (current)" if code in current else ""
        print(f"  {code:<32} {n:>8} entries {_mib(nbytes):>12}{mark}")
    return 0


def _verify(store, args) -> int:
    checked, bad = store.verify()
    if args.json:
        print_json(envelope("cache", {"directory": str(store.directory)},
                            {"entries": checked, "bad": [
                                {"key": k, "kind": kind, "label": label, "why": why}
                                for k, kind, label, why in bad]}, {}))
    else:
        print(f"store {store.directory}: {checked} entries checked, {len(bad)} bad")
        for key, kind, label, why in bad:
            print(f"  {key[:16]:<16} {kind:<10} {label[:40]:<40} {why}")
    return 1 if bad else 0
