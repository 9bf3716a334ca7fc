"""Streaming the dataset into training: a torch IterableDataset over the shards of one kind and
split. Each DataLoader worker reads its own share of the shards, one (or `buffer_shards`) at
a time, shuffles inside that buffer, and rebuilds S_t and T = S_t + offsets from (h, w), so
memory stays at a few shards whatever the dataset's size."""

from __future__ import annotations

import json
from collections import OrderedDict
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import torch
from torch.utils.data import IterableDataset, get_worker_info

from softdeca_train.data.blend import SkinBlend
from softdeca_train.data.config import KINDS, TEST, TRAIN
from softdeca_train.parameters import load_parameters
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN

PER_INSTANCE_SKIP = {"meta"}


class ShardDataset(IterableDataset):
    """Yields one dict of tensors per instance: the stored arrays (float16 offsets as
    float32), `p_norm` (p mapped to [0, 1] on each parameter's scale), and with
    `targets=True` also `S` (S_t) and `T` (the simulated skin), float32, metres. Dynamic
    instances carry whole sequences (L frames, plus `prev_S`/`prev_T` of the two lead-in
    frames). Instances whose solver's estimated error (any frame, for sequences) exceeds
    `max_error` ("auto": 3x the dataset's tolerance; None keeps all) are skipped: extreme
    parameters can stall just above the tolerance (kept) or far from it (skipped)."""

    def __init__(
        self,
        folder: str | Path,
        kind: str,
        split: str = "train",
        shuffle: bool = True,
        seed: int = 0,
        buffer_shards: int = 2,
        targets: bool = True,
        ict: str | None = None,
        max_error: float | str | None = "auto",
    ) -> None:
        if kind not in KINDS:
            raise ValueError(f"kind must be one of {KINDS}, not {kind!r}")
        if split not in ("train", "test", "all"):
            raise ValueError(f"split must be train, test or all, not {split!r}")
        self.folder = Path(folder)
        manifest = json.loads((self.folder / "manifest.json").read_text())
        want = {"train": {TRAIN}, "test": {TEST}, "all": {TRAIN, TEST}}[split]
        self.files = [
            s["file"]
            for s in manifest["shards"]
            if s["kind"] == kind and s.get("split", TRAIN) in want
        ]
        # All listed instances; with only_converged fewer are yielded (see the report).
        self.instances = sum(
            s["instances"] for s in manifest["shards"] if s["file"] in set(self.files)
        )
        self.kind, self.split, self.shuffle, self.seed = kind, split, shuffle, seed
        self.buffer_shards = max(1, buffer_shards)
        self.targets, self.ict = targets, ict
        tol = manifest["header"]["config"]["tolerance"]
        self.max_error = 3 * tol if max_error == "auto" else max_error
        self.epoch = 0
        self._blend: SkinBlend | None = None
        self._template: Template | None = None
        self._neutrals: OrderedDict[int, np.ndarray] = OrderedDict()

    def __len__(self) -> int:
        return self.instances

    def set_epoch(self, epoch: int) -> None:
        """Reshuffle differently in the next pass (call before iterating)."""
        self.epoch = epoch

    def _neutral(self, identity_id: int, h: np.ndarray) -> np.ndarray:
        if identity_id not in self._neutrals:
            if self._template is None:
                self._template = Template.load(self.ict)
                self._blend = SkinBlend.of(self._template)
            self._neutrals[identity_id] = self._template.identity_neutral(h)[:N_SKIN]
            if len(self._neutrals) > 64:
                self._neutrals.popitem(last=False)
        return self._neutrals[identity_id]

    def _load(self, file: str) -> dict[str, np.ndarray]:
        with np.load(self.folder / file) as z:
            return {k: z[k] for k in z.files if k not in PER_INSTANCE_SKIP}

    def _item(self, a: dict[str, np.ndarray], i: int) -> dict[str, torch.Tensor]:
        item = {k: torch.from_numpy(np.array(v[i])) for k, v in a.items()}  # 0-d stays 0-d
        for k in ("offsets", "prev_offsets"):
            if k in item:
                item[k] = item[k].float()
        item["p_norm"] = torch.from_numpy(
            np.asarray(load_parameters().normalise(a["p"][i]), np.float32)
        )
        if self.targets:
            neutral = self._neutral(int(a["identity_id"][i]), a["h"][i])
            assert self._blend is not None
            w = a["weights"][i]
            s = self._blend.targets(neutral, w.reshape(-1, 52)).reshape(*w.shape[:-1], N_SKIN, 3)
            item["S"] = torch.from_numpy(s.astype(np.float32))
            item["T"] = torch.from_numpy((s + a["offsets"][i]).astype(np.float32))
            if "prev_weights" in a:
                ps = self._blend.targets(neutral, a["prev_weights"][i])
                item["prev_S"] = torch.from_numpy(ps.astype(np.float32))
                item["prev_T"] = torch.from_numpy((ps + a["prev_offsets"][i]).astype(np.float32))
        return item

    def __iter__(self) -> Iterator[dict[str, torch.Tensor]]:
        info = get_worker_info()
        wid, nw = (info.id, info.num_workers) if info is not None else (0, 1)
        rng = np.random.default_rng([self.seed, self.epoch])
        files = list(self.files)
        if self.shuffle:
            files = [files[k] for k in rng.permutation(len(files))]
        mine = files[wid::nw]  # each worker its own shards: no instance twice per epoch
        for b in range(0, len(mine), self.buffer_shards):
            shards = [self._load(f) for f in mine[b : b + self.buffer_shards]]
            a = {k: np.concatenate([s[k] for s in shards]) for k in shards[0]}
            n = len(a["instance_id"])
            order = rng.permutation(n) if self.shuffle else np.arange(n)
            if self.max_error is not None:
                ok = (a["estimated_error"].reshape(n, -1) <= self.max_error).all(axis=1)
                order = order[ok[order]]
            for i in order:
                yield self._item(a, int(i))
