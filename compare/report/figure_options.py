"""Output options of ``trilith figures`` (light: the CLI's parser reads them without
importing the spectra and their compiled kernels)."""
from __future__ import annotations

__all__ = ["FORMATS", "DEFAULT_DPI", "check_output_options"]

FORMATS = ("png", "pdf", "svg")
DEFAULT_DPI = 300  # print resolution of journals


def check_output_options(dpi: int, fmt: str) -> None:
    """ValueError naming ``--dpi``/``--format`` when out of range."""
    if isinstance(dpi, bool) or not isinstance(dpi, int) or not 50 <= dpi <= 1200:
        raise ValueError(f"--dpi must be an integer in [50, 1200], got {dpi!r}")
    if fmt not in FORMATS:
        raise ValueError(f"--format must be one of {', '.join(FORMATS)}, got {fmt!r}")
