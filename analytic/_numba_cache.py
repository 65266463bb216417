"""Keep numba's on-disk cache of the fast path honest.

numba re-compiles a cached function when *its own* source file changes, but not
when a function it calls lives in another file that changed (numba's caching
notes).  The fast path compiles :mod:`analytic.equations` into
:mod:`analytic._fast_kernels`, so an edit of the equations would leave stale
machine code behind.  On import this module hashes the files the kernels are
built from and, when the hash differs from the one recorded next to the cache,
deletes the cached kernels so numba compiles them again.  The hash includes the
package's import name (cached kernels name the modules they were compiled in).
"""
from __future__ import annotations

import hashlib
from pathlib import Path

_HERE = Path(__file__).resolve().parent
SOURCES = ("equations.py", "_fast_numerics.py", "_fast_steps.py", "_fast_run.py",
           "_fast_kernels.py")
PREFIXES = tuple(Path(name).stem + "." for name in SOURCES)


def sources_digest() -> str:
    # The import name too: numba's cached machine code names the modules it was
    # compiled in, so the same files imported under another package name (a
    # checkout renamed or installed elsewhere) must not load it.
    h = hashlib.sha256(__name__.encode())
    for name in SOURCES:
        h.update((_HERE / name).read_bytes())
    return h.hexdigest()


def invalidate_if_stale(cache_dir: Path = _HERE / "__pycache__") -> bool:
    """Delete stale numba cache files; returns True when it did.  A read-only or
    missing cache directory is left alone (numba then compiles in memory)."""
    stamp = cache_dir / "_fast_sources.sha256"
    try:
        digest = sources_digest()
        if stamp.is_file() and stamp.read_text().strip() == digest:
            return False
        if cache_dir.is_dir():
            for path in cache_dir.iterdir():
                if path.name.startswith(PREFIXES) and path.suffix in (".nbi", ".nbc"):
                    path.unlink(missing_ok=True)
            stamp.write_text(digest + "\n")
        return True
    except OSError:
        return False


invalidate_if_stale()
