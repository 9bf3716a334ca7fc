"""Where inputs and caches live. Everything is overridable by environment or arguments."""

from __future__ import annotations

import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


def data_dir() -> Path:
    """$SOFTDECA_DATA, else .cache/data in the repository: the third-party data that
    `make setup` fetches and verifies (softdeca_train.third_party_data, THIRD_PARTY.md)."""
    env = os.environ.get("SOFTDECA_DATA")
    return Path(env) if env else REPO_ROOT / ".cache" / "data"


def default_ict_path() -> Path:
    """$SOFTDECA_ICT, else ICT-FaceKit in the data folder."""
    env = os.environ.get("SOFTDECA_ICT")
    return Path(env) if env else data_dir() / "ict-facekit"


def default_arkit_reference_path() -> Path:
    """$SOFTDECA_ARKIT_REFERENCE, else ARKit's reference shapes in the data folder."""
    env = os.environ.get("SOFTDECA_ARKIT_REFERENCE")
    return Path(env) if env else data_dir() / "arkit-reference"


def default_takes_path() -> Path:
    """$SOFTDECA_TAKES, else the Live Link Face takes in the data folder."""
    env = os.environ.get("SOFTDECA_TAKES")
    return Path(env) if env else data_dir() / "recordings" / "livelinkface-alexdjulin"


def default_recordings_path() -> Path:
    """$SOFTDECA_RECORDINGS, else the data folder's recordings: every source's takes."""
    env = os.environ.get("SOFTDECA_RECORDINGS")
    return Path(env) if env else data_dir() / "recordings"


def cache_dir() -> Path:
    """$SOFTDECA_CACHE, else .cache in the repository (ignored by git)."""
    env = os.environ.get("SOFTDECA_CACHE")
    return Path(env) if env else REPO_ROOT / ".cache"
