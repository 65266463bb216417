"""Peer codes beside the analytic model: independent simulators of the same
physics, built from their own elements (not engines the project calibrates).

:mod:`.opensees_block` models the single rocking block in OpenSees (the optional
extra ``pip install -e '.[peers]'``); see ``docs/peers.md``.
"""
