"""Where the tests find the checkout: the repository root (README, docs, scenes)."""
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
