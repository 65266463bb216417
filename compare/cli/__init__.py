"""Subcommands of the ``trilith`` CLI: one module each, exposing ``add_parser`` and ``run``.

``COMMANDS`` lists them in help order; a module that is missing is skipped, so
each subcommand can land on its own.
"""
COMMANDS = ("simulate", "restitution", "spectrum", "figures", "report", "bench", "view",
            "record", "map", "scenes", "campaign", "calibrate", "cache")
