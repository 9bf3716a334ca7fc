"""The rest physics' change of every group of a dataset: Pd = P_rest(p) - P_rest(p0), the skin
of the group's identity simulated at rest under its parameters (and its regional pattern) less
the same under the defaults, by the bundle's physics at prepare: the runtime's own solve
(plugin/src/prepare/rest_physics.cpp through softdeca_native), as it adds Pd to every frame.

The runtime adds Pd to every frame at prepare. Most of a calm static frame's T - S_t is Pd
(measured on softdeca-l3-e1: 0.35 of 0.36 mm on a calm frame), and a model exact at rest
cannot fit it there: a run trained on S_t + Pd (`train-bundle --rest-changes`) learns only what
an expression adds on top of the rest physics, as the runtime will use it.

One file per static and dynamic shard in <dataset>/rest-changes/, written atomically: a rerun
goes on where one stopped, and workers share the shards."""

from __future__ import annotations

import json
import multiprocessing as mp
import os
import queue
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from softdeca_train.models.bundle import read_manifest, read_rest_physics_bytes
from softdeca_train.parameters import ParameterSpec
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN
from softdeca_train.train.batches import (
    EVERY_FRAME,
    REST_CHANGES,
    RESTED_KINDS,
    Batch,
    Dataset,
    rest_changes_path,
)


@dataclass(frozen=True)
class RestChangesConfig:
    dataset: Path
    bundle: Path  # whose physics at prepare (its rest_head.bin): the runtime's for that bundle
    workers: int = 1
    progress: bool = True


class GroupSolver:
    """Pd of the groups of one identity after another, by the runtime's physics at prepare
    (softdeca_native.RestPhysics: plugin/src/prepare/rest_physics.cpp), the identity's solver
    and its rest under the defaults kept while its groups come."""

    def __init__(self, bundle: Path, template: Template) -> None:
        # the manifest and the rest head: no network of the bundle is run
        manifest = read_manifest(bundle)
        found = read_rest_physics_bytes(bundle, manifest)
        if found is None:
            raise ValueError(f"{bundle} has no physics at prepare (rest_head.bin)")
        self.manifest_json, self.rest_head = json.dumps(manifest), found
        self.template = template
        self.specs = tuple(ParameterSpec.from_dict(p) for p in manifest["parameters"])
        self.defaults = np.array([s.default_value for s in self.specs], np.float64)
        self.localisable = np.array([s.localisable for s in self.specs], np.int32)
        self._identity: int | None = None

    def _start(self, b: Batch) -> None:
        import softdeca_native as native  # compiled with the plugin

        self._identity = None  # until its solver and rest exist
        neutral = self.template.identity_neutral(b.h[0].double().numpy())
        self.solver = native.RestPhysics(
            self.manifest_json,
            self.rest_head,
            np.ascontiguousarray(neutral, np.float32),
            np.ascontiguousarray(self.template.skin_triangles, np.int32),
        )
        self.rest0 = self._solve(self.defaults, None)
        self._identity = b.identity_id

    def _solve(self, globals_: np.ndarray, vertex_maps: np.ndarray | None) -> np.ndarray:
        localised = self.localisable if vertex_maps is not None else np.zeros_like(self.localisable)
        maps = vertex_maps if vertex_maps is not None else np.zeros((0, 0))
        return np.asarray(self.solver.solve(globals_, maps, localised), np.float64)

    def rest_change(self, b: Batch) -> np.ndarray:
        """(N_SKIN, 3): the group's Pd, zero under the defaults (where the runtime solves
        nothing)."""
        if b.identity_id != self._identity:
            self._start(b)
        globals_ = b.p[0].double().numpy()
        maps = None
        if b.p_vertices is not None and self.localisable.any():
            maps = np.ascontiguousarray(b.p_vertices.double().numpy())
        if maps is None and np.array_equal(globals_, self.defaults):
            return np.zeros((N_SKIN, 3))
        return self._solve(globals_, maps) - self.rest0


def shards_to_do(dataset: Dataset) -> list[tuple[str, str]]:
    """(kind, shard) of every static and dynamic shard whose file is not written yet."""
    return [
        (kind, f)
        for kind in RESTED_KINDS
        for f in dataset.shards(kind, "all")
        if not rest_changes_path(dataset.folder, f).is_file()
    ]


def write_shard(dataset: Dataset, groups: GroupSolver, kind: str, shard: str) -> None:
    with np.load(dataset.folder / shard) as z:
        ids = z["instance_id"]
    out = np.zeros((len(ids), N_SKIN, 3), np.float16)
    solved = np.ones(len(ids), bool)
    refusal = np.full(len(ids), "", dtype=object)
    for idx, b in dataset.shard_batches(kind, shard, max_frames=len(ids), limit=EVERY_FRAME):
        try:
            out[idx] = groups.rest_change(b).astype(np.float16)
        except ValueError as e:  # the physics at prepare refuses this head: so would the runtime
            solved[idx], refusal[idx] = False, str(e)
    path = rest_changes_path(dataset.folder, shard)
    tmp = path.with_name(path.name + ".tmp.npz")
    np.savez(tmp, instance_id=ids, rest_change=out, solved=solved, refusal=refusal.astype(str))
    os.replace(tmp, path)


def _worker(config: RestChangesConfig, jobs: list[tuple[str, str]], done) -> None:
    groups = GroupSolver(config.bundle, Template.load())
    dataset = Dataset(config.dataset, groups.template, [s.name for s in groups.specs])
    for kind, shard in jobs:
        write_shard(dataset, groups, kind, shard)
        done.put(shard)


def make_rest_changes(config: RestChangesConfig) -> Iterator[str]:
    """Writes every missing file; yields each shard as its file is written."""
    dataset = Dataset(config.dataset)
    (dataset.folder / REST_CHANGES).mkdir(exist_ok=True)
    todo = shards_to_do(dataset)
    if not todo:
        return
    workers = max(1, min(config.workers, len(todo)))
    ctx = mp.get_context("spawn")
    done = ctx.Queue()
    # shards of one identity stay with one worker (its solver is built once)
    procs = [
        ctx.Process(target=_worker, args=(config, todo[k::workers], done), daemon=True)
        for k in range(workers)
    ]
    for p in procs:
        p.start()
    with tqdm(
        total=len(todo), desc="rest changes", unit="shard", disable=not config.progress
    ) as bar:
        for _ in range(len(todo)):
            while True:
                try:
                    shard = done.get(timeout=5)
                    break
                except queue.Empty:  # the workers still run?
                    if not any(p.is_alive() for p in procs) and done.empty():
                        raise RuntimeError(
                            "the rest-change workers stopped; rerun to go on"
                        ) from None
            bar.update()
            yield shard
    for p in procs:
        p.join()
