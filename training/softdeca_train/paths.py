"""Where inputs and caches live. Everything is overridable by environment or arguments."""

from __future__ import annotations

import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


def default_ict_path() -> Path:
    """$SOFTDECA_ICT, else ../shared/ict-facekit beside the repository."""
    env = os.environ.get("SOFTDECA_ICT")
    return Path(env) if env else REPO_ROOT.parent / "shared" / "ict-facekit"


def default_arkit_reference_path() -> Path:
    env = os.environ.get("SOFTDECA_ARKIT_REFERENCE")
    return Path(env) if env else REPO_ROOT.parent / "shared" / "arkit-reference"


def cache_dir() -> Path:
    """$SOFTDECA_CACHE, else .cache in the repository (ignored by git)."""
    env = os.environ.get("SOFTDECA_CACHE")
    return Path(env) if env else REPO_ROOT / ".cache"
