"""The gallery's solved physics kept on disk. The physics is the slow half of `make controls`
(hours at the gallery's tolerance) and does not change when only the bundle does, so a new
bundle's gallery reuses it. An entry is keyed by everything the solve reads (identity,
expressions, setting, defaults, tolerance, iterations, level, tet mesh) and by the physics'
own source: the git trees of the folders it is built from. With uncommitted changes there (or
outside a git checkout) nothing is read or written: a cached answer of other physics would be
a wrong figure, not a slow one."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softdeca_train.paths import REPO_ROOT, cache_dir

if TYPE_CHECKING:
    from softdeca_train.controls.cases import PhysicsCase
    from softdeca_train.controls.definitions import Setting

# What the physics of a gallery case is built from (native solver, parameters, head model).
# The parameter file counts without its control ranges (PARAMETERS: physics_parameters): which
# parameters a bundle offers as controls, and over what, changes no solve.
PARAMETERS = "plugin/data/parameters.json"
PHYSICS_SOURCES = (
    "plugin/src/sim",
    "plugin/src/geometry",
    "plugin/data",
    "training/softdeca_train/sim",
    "training/softdeca_train/lhm",
    "training/softdeca_train/template",
    "training/softdeca_train/parameters.py",
    "training/softdeca_train/contact_rules.py",
    "training/softdeca_train/controls/cases.py",
)


def physics_version(root: Path = REPO_ROOT) -> str | None:
    """A digest of the physics sources' committed trees, or None where they are not all
    committed (or this is no git checkout)."""

    def git(*args: str) -> str:
        return subprocess.run(
            ["git", *args], cwd=root, capture_output=True, text=True, check=True
        ).stdout

    try:
        if git("status", "--porcelain", "--", *PHYSICS_SOURCES).strip():
            return None
        others = git("ls-tree", "-r", "HEAD", "--", "plugin/data").splitlines()
        trees = [
            git("rev-parse", f"HEAD:{p}").strip() for p in PHYSICS_SOURCES if p != "plugin/data"
        ]
        trees += [line for line in others if not line.endswith("\t" + PARAMETERS)]
        trees.append(physics_parameters(git("show", f"HEAD:{PARAMETERS}")))
    except (OSError, subprocess.CalledProcessError):
        return None
    return hashlib.sha256("\n".join(trees).encode()).hexdigest()


def physics_parameters(text: str) -> str:
    """The parameter file as the physics reads it: every entry without its control range."""
    data = json.loads(text)
    for p in data.get("parameters", []):
        p.pop("control", None)
    return json.dumps(data, sort_keys=True)


@dataclass(frozen=True)
class PhysicsCache:
    folder: Path
    version: str | None  # physics_version(); None: the cache is off

    @property
    def enabled(self) -> bool:
        return self.version is not None

    def key(self, arrays: tuple[np.ndarray, ...], settings: dict) -> str:
        h = hashlib.sha256(str(self.version).encode())
        h.update(json.dumps(settings, sort_keys=True, default=str).encode())
        for a in arrays:
            a = np.ascontiguousarray(a)
            h.update(f"{a.dtype}{a.shape}".encode())
            h.update(a.tobytes())
        return h.hexdigest()

    def get(self, key: str) -> np.ndarray | None:
        if not self.enabled:
            return None
        path = self.folder / f"{key}.npy"
        try:
            return np.load(path, allow_pickle=False)
        except (OSError, ValueError):  # absent, or damaged: solve again
            return None

    def put(self, key: str, value: np.ndarray) -> None:
        if not self.enabled:
            return
        self.folder.mkdir(parents=True, exist_ok=True)
        tmp = self.folder / f"{key}.{os.getpid()}.tmp.npy"
        np.save(tmp, np.asarray(value), allow_pickle=False)
        tmp.replace(self.folder / f"{key}.npy")  # atomic: a killed run leaves no half entry


def default_folder() -> Path:
    """Where the gallery and the real takes keep their solves unless told otherwise."""
    return cache_dir() / "controls-physics"


def open_cache(folder: Path | None) -> PhysicsCache:
    """The cache in `folder` for the physics of this checkout (off where folder is None)."""
    return PhysicsCache(folder or Path(), physics_version() if folder is not None else None)


def solve_cached(
    cache: PhysicsCache,
    case: PhysicsCase,
    setting: Setting,
    defaults: dict[str, float],
    domains: dict[str, str],
) -> np.ndarray:
    """`case.solve(setting, ...)`, read from the cache where it was solved before."""
    settings = {
        "setting": asdict(setting),
        "defaults": defaults,
        "case": [case.level, case.tolerance, case.max_iterations, case.tet_mesh],
    }
    key = cache.key((case.identity, case.weights), settings)
    got = cache.get(key)
    if got is None or got.shape != case.targets.shape:
        got = case.solve(setting, defaults, domains)
        cache.put(key, got)
    return got
