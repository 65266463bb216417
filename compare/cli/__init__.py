"""Subcommands of the ``trilith`` CLI: one module each, exposing ``add_parser`` and ``run``.

``COMMANDS`` lists them in help order.
"""
COMMANDS = ("simulate", "restitution", "restitution_map", "spectrum", "figures", "report", "bench", "view",
            "record", "map", "scenes", "campaign", "calibrate", "atlas", "fragility", "trust", "cache")
