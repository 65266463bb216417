"""Comparison layer: metrics between backends, the validation campaign, reports, CLI."""
