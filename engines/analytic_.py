"""The analytic model behind the registry's interface.

:mod:`analytic.simulate` and :mod:`analytic.fast` are modules with ``NAME``,
``CAPABILITIES``, ``Settings``, ``version()`` and ``simulate()``; the classes
here give them the interface of :class:`engines.base.Engine` (``name``,
``label``, ``capabilities``, ...), so that callers treat every backend alike.
The analytic package never imports :mod:`engines`.
"""
from __future__ import annotations

import importlib
from typing import ClassVar

__all__ = ["AnalyticBackend", "Analytic", "AnalyticFast"]


class _Module:
    """A class attribute read from the wrapped module when first asked for."""

    def __init__(self, attr: str) -> None:
        self.attr = attr

    def __get__(self, obj, owner):
        return getattr(importlib.import_module(owner.module), self.attr)


class AnalyticBackend:
    """An analytic backend module seen as a registry class."""

    module: ClassVar[str]
    name: ClassVar[str]
    label: ClassVar[str]
    color: ClassVar[str]
    marker: ClassVar[str]
    known_failures: ClassVar[dict] = {}
    capabilities = _Module("CAPABILITIES")
    Settings = _Module("Settings")

    @classmethod
    def version(cls) -> str:
        return importlib.import_module(cls.module).version()

    @classmethod
    def simulate(cls, scene, excitation, settings=None):
        return importlib.import_module(cls.module).simulate(scene, excitation, settings)


class Analytic(AnalyticBackend):
    """The accurate analytic model (:mod:`analytic.simulate`, SciPy DOP853)."""

    module = "trilith_xval.analytic.simulate"
    name = "analytic"
    label = "analytic model (scipy)"
    color = "k"
    marker = "o"


class AnalyticFast(AnalyticBackend):
    """The compiled fast path (:mod:`analytic.fast`, numba)."""

    module = "trilith_xval.analytic.fast"
    name = "analytic-fast"
    label = "analytic model (compiled)"
    color = "tab:green"
    marker = "x"
