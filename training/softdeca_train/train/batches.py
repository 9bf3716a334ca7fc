"""Batches for training and evaluation, read shard by shard from a generated dataset
(data/generate.py). A static or sparse batch is frames of one (identity, p) group: the
hypernetwork's per-element pass (the expensive part) then runs once per batch, as at run time
once per avatar. A dynamic batch is one sequence. Each batch carries its identity's neutral
skin and deformation-transfer system (cached per identity: K depends only on the neutral)."""

from __future__ import annotations

import json
import math
from collections import OrderedDict
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from softdeca_train.data.blend import SkinBlend
from softdeca_train.data.config import TEST, TRAIN
from softdeca_train.models.dt import DtSystem, dt_system
from softdeca_train.parameters import load_parameters
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.regions import region_labels

# max_error that keeps every frame: evaluation judges a model on the whole test split.
EVERY_FRAME = math.inf


def training_mask(arrays: dict[str, np.ndarray], limit: float) -> tuple[np.ndarray, np.ndarray]:
    """Per instance of one shard: (solver error within `limit`, passes the sanity bounds).
    A sequence counts as failing if any of its frames does. With `limit` EVERY_FRAME both are
    all true: the evaluation judges every frame, failed ones included."""
    n = len(arrays["instance_id"])
    if limit == EVERY_FRAME:
        ones = np.ones(n, bool)
        return ones, ones
    solved = (arrays["estimated_error"].reshape(n, -1) <= limit).all(axis=1)
    failures = arrays.get("failures")  # datasets made before the sanity bounds lack it
    sane = np.ones(n, bool) if failures is None else (failures.reshape(n, -1) == 0).all(axis=1)
    return solved, sane


def index_ranges(indices: list[int]) -> str:
    """Sorted distinct integers as ranges: [0, 1, 2, 4, 7, 8] -> "0-2,4,7-8"."""
    runs: list[str] = []
    start = prev = None
    for i in [*indices, None]:
        if start is not None and (i is None or i != prev + 1):
            runs.append(str(start) if start == prev else f"{start}-{prev}")
            start = None
        if i is not None and start is None:
            start = i
        prev = i
    return ",".join(runs)


SOURCES = ("source_take", "source_index")  # where an instance's expression came from

# The rest physics' change of each group (train/rest_changes.py), one file per shard of the
# kinds a SoftDECA run trains on, beside the shards.
REST_CHANGES = "rest-changes"
RESTED_KINDS = ("static", "dynamic")


def rest_changes_path(folder: Path, shard: str) -> Path:
    return folder / REST_CHANGES / shard


def read_rest_changes(
    folder: Path, shard: str, instance_id: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Pd of each instance of the shard, (n, N_SKIN, 3) float16, checked to be its own, and
    whether the physics at prepare could simulate its head (n,) bool: an instance it refuses
    (a head whose carried tissue fill inverts a tet) has no Pd and is left out, counted."""
    path = rest_changes_path(folder, shard)
    if not path.is_file():
        raise FileNotFoundError(
            f"{path} is missing: make the dataset's rest changes first "
            f"(python -m softdeca_train rest-changes --dataset {folder})"
        )
    with np.load(path) as z:
        if not np.array_equal(z["instance_id"], instance_id):
            raise ValueError(f"{path} is not of this shard's instances: make it again")
        return z["rest_change"], z["solved"]


@dataclass
class Batch:
    """One group of frames. Shapes: B frames (static/sparse) or L sequence frames (dynamic);
    V = skin vertices, K = landmarks; metres, float32."""

    kind: str
    identity_id: int
    param_id: int
    p: torch.Tensor  # (1, P) raw parameter values, the model's columns
    h: torch.Tensor  # (1, H)
    neutral: torch.Tensor  # (V, 3) the identity's neutral skin
    weights: torch.Tensor  # (B, 52)
    S: torch.Tensor  # (B, V, 3) linear blend S_t
    T: torch.Tensor  # (B, V, 3) simulated
    dt: DtSystem
    landmarks: torch.Tensor | None = None  # sparse: (B, K, 3) sigma(L), noisy, personalised
    landmarks_clean: torch.Tensor | None = None  # sparse: the same without the noise
    prev_S: torch.Tensor | None = None  # dynamic: (2, V, 3) frames t-2, t-1 before the sequence
    prev_T: torch.Tensor | None = None
    prev_weights: torch.Tensor | None = None  # dynamic: (2, 52)
    source_take: np.ndarray | None = None  # (B,) take index or -1 (coverage)
    source_index: np.ndarray | None = None  # (B,) frame of that take, or coverage draw
    # static/sparse: (len(REGIONS), P) the group's values per region of S (template/regions.py),
    # p in every region without a regional pattern; None in datasets written without them
    p_regions: torch.Tensor | None = None
    p_faces: torch.Tensor | None = None  # (F, P) p_regions on the skin triangles
    p_vertices: torch.Tensor | None = None  # (V, P) p_regions on the skin vertices

    @property
    def frames(self) -> int:
        return len(self.weights)

    def face_parameters(self, n: int) -> torch.Tensor:
        """(n, P) parameters per skin triangle: the regional pattern, or p everywhere."""
        return self.p_faces if self.p_faces is not None else self.p.expand(n, self.p.shape[-1])

    def vertex_parameters(self, n: int) -> torch.Tensor:
        """(n, P) parameters per skin vertex: the regional pattern, or p everywhere."""
        if self.p_vertices is not None:
            return self.p_vertices
        return self.p.expand(n, self.p.shape[-1])


class IdentityCache:
    """Neutral skins and DT systems per identity, least recently used out."""

    def __init__(self, template: Template, triangles: np.ndarray, size: int = 48) -> None:
        self.template, self.triangles, self.size = template, triangles, size
        self._items: OrderedDict[int, tuple[np.ndarray, DtSystem]] = OrderedDict()

    def get(self, identity_id: int, h: np.ndarray) -> tuple[np.ndarray, DtSystem]:
        if identity_id in self._items:
            self._items.move_to_end(identity_id)
            return self._items[identity_id]
        neutral = self.template.identity_neutral(h)[:N_SKIN].astype(np.float64)
        item = (neutral, dt_system(neutral, self.triangles))
        self._items[identity_id] = item
        if len(self._items) > self.size:
            self._items.popitem(last=False)
        return item


class Dataset:
    """A generated dataset: its manifest and the shards of one kind and split."""

    def __init__(
        self,
        folder: str | Path,
        template: Template | None = None,
        parameters: list[str] | None = None,
        rest_changes: bool = False,
    ) -> None:
        """`parameters`: the columns of p a model takes, by name (default: all of them, in
        plugin/data/parameters.json order, which is the order of the stored p).
        `rest_changes`: static and dynamic batches carry S_t on the rest physics, S_t + Pd
        (train/rest_changes.py), so a model learns the correction on top of it."""
        self.folder = Path(folder)
        self.rest_changes = rest_changes
        path = self.folder / "manifest.json"
        if not path.is_file():
            raise FileNotFoundError(f"no dataset at {self.folder} (manifest.json missing)")
        self.manifest = json.loads(path.read_text())
        self._path = path
        self.template = template or Template.load()
        self.blend = SkinBlend.of(self.template)
        self.cache = IdentityCache(self.template, self.template.skin_triangles)
        self.tolerance = float(self.manifest["header"]["config"]["tolerance"])

        names = load_parameters().names
        unknown = set(parameters or ()) - set(names)
        if unknown:
            raise ValueError(f"unknown parameters {sorted(unknown)}")

        self.labels = region_labels(self.template)  # regional patterns -> triangles, vertices
        self.columns = (
            [names.index(n) for n in parameters] if parameters else list(range(len(names)))
        )

    def refresh(self) -> None:
        """Re-read the manifest: a dataset still being generated lists more finished shards."""
        self.manifest = json.loads(self._path.read_text())

    def shards(self, kind: str, split: str) -> list[str]:
        want = {"train": {TRAIN}, "test": {TEST}, "all": {TRAIN, TEST}}[split]
        return [
            s["file"]
            for s in self.manifest["shards"]
            if s["kind"] == kind and s.get("split", TRAIN) in want
        ]

    def left_out(self, kind: str, split: str, max_error: float | None = None) -> dict[str, int]:
        """Instances of one kind and split that `batches` yields (`kept`), leaves out for
        their solver error (`left_out`, same limit as `batches`) and, of the others, for a
        failed sanity bound (`failed_bounds`, sim/sanity.py): reported, never silent."""
        limit = 3 * self.tolerance if max_error is None else max_error
        kept = left = failed = unrested = 0
        for arrays, solved, sane in self._judged(kind, split, limit):
            rested = arrays.get("rest_solved", np.ones(len(solved), bool))
            kept += int((solved & sane & rested).sum())
            left += int((~solved).sum())
            failed += int((solved & ~sane).sum())
            unrested += int((solved & sane & ~rested).sum())
        out = {"kept": kept, "left_out": left, "failed_bounds": failed, "max_error": limit}
        if self.rest_changes and kind in RESTED_KINDS:  # and the physics at prepare refused
            out["no_rest_physics"] = unrested
        return out  # type: ignore[return-value]

    def take_frames(self, split: str = "train") -> dict[str, dict]:
        """Which frames of which recorded takes the kept instances of `split` came from (every
        kind; coverage draws are no take's): per take name, the instances per kind and the frame
        indices as ranges ("0-4,9"), for a training record that says what a model saw."""
        names = [t["name"] for t in self.manifest["header"].get("takes", [])]
        seen: dict[str, dict] = {}
        for kind in self.manifest["dataset"]["kinds"]:
            for arrays, solved, sane in self._judged(kind, split, 3 * self.tolerance, SOURCES):
                if "source_take" not in arrays:
                    continue
                keep = solved & sane
                # dynamic instances are sequences: one take per sequence, a frame per step
                takes = arrays["source_take"][keep].reshape(int(keep.sum()), -1)
                index = arrays["source_index"][keep].reshape(takes.shape)
                for t in np.unique(takes[takes >= 0]):
                    entry = seen.setdefault(names[int(t)], {"instances": {}, "frames": set()})
                    count = int((takes == t).any(axis=1).sum())
                    entry["instances"][kind] = entry["instances"].get(kind, 0) + count
                    entry["frames"].update(int(i) for i in index[takes == t])
        return {
            name: {"instances": e["instances"], "frames": index_ranges(sorted(e["frames"]))}
            for name, e in sorted(seen.items())
        }

    def _judged(
        self, kind: str, split: str, limit: float, more: tuple[str, ...] = ()
    ) -> Iterator[tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]]:
        """Per shard of one kind and split: its arrays (the solver and sanity columns and
        `more`) and training_mask's verdicts at `limit`."""
        for f in self.shards(kind, split):
            with np.load(self.folder / f) as z:
                keys = ("instance_id", "estimated_error", "failures", *more)
                arrays = {k: z[k] for k in keys if k in z}
            if self.rest_changes and kind in RESTED_KINDS:
                arrays["rest_solved"] = read_rest_changes(self.folder, f, arrays["instance_id"])[1]
            yield (arrays, *training_mask(arrays, limit))

    def batches(
        self,
        kind: str,
        split: str,
        rng: np.random.Generator | None = None,
        max_frames: int = 8,
        max_error: float | None = None,
    ) -> Iterator[Batch]:
        """Every batch of one pass (shuffled with `rng`, in order without). Frames whose
        solver error exceeds `max_error` (default 3x the dataset's tolerance) or that fail a
        sanity bound are left out; EVERY_FRAME keeps all (`left_out` counts them)."""
        limit = 3 * self.tolerance if max_error is None else max_error
        files = self.shards(kind, split)
        if rng is not None:
            files = [files[k] for k in rng.permutation(len(files))]
        for f in files:
            for _, batch in self.shard_batches(kind, f, rng, max_frames, limit):
                yield batch

    def shard_batches(
        self,
        kind: str,
        file: str,
        rng: np.random.Generator | None = None,
        max_frames: int = 8,
        limit: float = EVERY_FRAME,
    ) -> Iterator[tuple[np.ndarray, Batch]]:
        """The batches of one shard (as `batches` makes them), each with its instances'
        indices in the shard."""
        with np.load(self.folder / file) as z:
            a = {k: z[k] for k in z.files if k != "meta"}
        if self.rest_changes and kind in RESTED_KINDS:
            a["rest_change"], a["rest_solved"] = read_rest_changes(
                self.folder, file, a["instance_id"]
            )
        solved, sane = training_mask(a, limit)
        ok = solved & sane & a.get("rest_solved", True)  # no Pd: out, also of the evaluation
        groups = [np.flatnonzero(ok & (a["param_id"] == g)) for g in np.unique(a["param_id"])]
        if rng is not None:
            groups = [groups[k] for k in rng.permutation(len(groups))]
        for idx in groups:
            if kind == "dynamic":
                for i in idx:
                    yield np.array([i]), self._batch(kind, a, np.array([i]))
            else:
                for b in range(0, len(idx), max_frames):
                    if len(idx[b : b + max_frames]):
                        yield idx[b : b + max_frames], self._batch(kind, a, idx[b : b + max_frames])

    def _batch(self, kind: str, a: dict[str, np.ndarray], idx: np.ndarray) -> Batch:
        i0 = int(idx[0])
        neutral, system = self.cache.get(int(a["identity_id"][i0]), a["h"][i0])
        w = a["weights"][idx].reshape(-1, 52)  # dynamic: the sequence's frames
        s = self.blend.targets(neutral, w)
        t = s + a["offsets"][idx].reshape(-1, N_SKIN, 3).astype(np.float64)
        # on the rest physics: every frame of a group shares its Pd (a sequence is one group)
        rest = a["rest_change"][i0].astype(np.float64) if "rest_change" in a else None
        if rest is not None:
            s = s + rest[None]
        f32 = lambda x: torch.from_numpy(np.ascontiguousarray(x, dtype=np.float32))  # noqa: E731
        batch = Batch(
            kind=kind,
            identity_id=int(a["identity_id"][i0]),
            param_id=int(a["param_id"][i0]),
            p=f32(a["p"][i0][None][:, self.columns]),
            h=f32(a["h"][i0][None]),
            neutral=f32(neutral),
            weights=f32(w),
            S=f32(s),
            T=f32(t),
            dt=system,
            source_take=a["source_take"][idx].reshape(-1),
            source_index=a["source_index"][idx].reshape(-1),
        )
        if "p_regions" in a:
            pr = a["p_regions"][i0][:, self.columns]
            if np.any(pr != a["p"][i0][self.columns]):  # a regional pattern
                batch.p_regions = f32(pr)
                batch.p_vertices = f32(pr[self.labels])
                batch.p_faces = f32(pr[self.labels[self.template.skin_triangles[:, 0]]])
        if "landmarks" in a:
            batch.landmarks = f32(a["landmarks"][idx])
            batch.landmarks_clean = f32(a["landmarks_clean"][idx])
        if "prev_weights" in a:
            ps = self.blend.targets(neutral, a["prev_weights"][i0])
            batch.prev_T = f32(ps + a["prev_offsets"][i0].astype(np.float64))
            batch.prev_S = f32(ps if rest is None else ps + rest[None])
            batch.prev_weights = f32(a["prev_weights"][i0])
        return batch
