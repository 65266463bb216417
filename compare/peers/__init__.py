"""Peer codes beside the analytic model: independent simulators of the same
physics, built from their own elements (not engines the project calibrates),
and measurements of the real thing.

:mod:`.opensees_block` models the single rocking block in OpenSees (the optional
extra ``pip install -e '.[peers]'``); see ``docs/peers.md``.
:mod:`.impact_data`, :mod:`.impact_replay` and :mod:`.impact_measure` read a
user's copy of measured square-block drops, keep the rocking-like impacts and
set them against Housner's ratio and engines replaying each; see
``docs/measured-impacts.md``.
"""
