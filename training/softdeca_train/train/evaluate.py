"""Errors of trained models against the physics on a dataset's test split (identities,
parameter sets and expression frames none of them trained on), split by expression source
(the held-out real take against the coverage sampler), and per vertex for heat maps; and the
time per frame of each model's per-frame work (single thread, batch 1, what the runtime
repeats every frame once the per-avatar part is prepared)."""

from __future__ import annotations

import multiprocessing as mp
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import torch
from tqdm import tqdm

from softdeca_train.data.config import GenerateConfig
from softdeca_train.landmarks.arkit_reference import ArkitFace
from softdeca_train.models.dt import deformation_transfer
from softdeca_train.train.batches import EVERY_FRAME, Batch
from softdeca_train.train.run import Run
from softdeca_train.train.trainable import (
    Dynamics,
    FaceMlp,
    GlobalMlp,
    LatentDynamics,
    NoCorrection,
    SoftDeca,
    SoftDecaHybrid,
    SoftDecaVertex,
    SparseSoftDeca,
    Trainable,
    expand,
    vertex_error,
)

# SparseSoftDECA inputs for Table 2: the simulated head's own landmarks (on its S_t), another
# head's expression personalised to it (clean), the same with the augmentation's noise, and
# ARKit's reference face making the expression, personalised to it (what a phone sends).
SPARSE_INPUTS = ("same_head", "other_head", "other_head_noise", "arkit_face")


@dataclass
class ErrorSum:
    total: float = 0.0
    count: int = 0
    per_vertex: np.ndarray | None = None
    frames: int = 0
    by_source: dict[str, list[float]] = field(default_factory=dict)

    def add(self, err: torch.Tensor, sources: np.ndarray, test_takes: list[int]) -> None:
        e = err.detach().double().numpy().reshape(-1, err.shape[-1])  # (frames, V) metres
        self.total += float(e.sum())
        self.count += e.size
        self.frames += len(e)
        pv = e.sum(0)
        self.per_vertex = pv if self.per_vertex is None else self.per_vertex + pv
        src = np.asarray(sources).reshape(-1)
        for f in range(len(e)):
            key = "real_take" if src[f] in test_takes else "coverage"
            self.by_source.setdefault(key, []).append(float(e[f].mean()))

    def summary(self) -> dict:
        if self.frames == 0:
            return {"mean_mm": None, "frames": 0}
        out = {"mean_mm": 1e3 * self.total / self.count, "frames": self.frames}
        for k, v in sorted(self.by_source.items()):
            out[f"{k}_mm"] = 1e3 * float(np.mean(v))
            out[f"{k}_frames"] = len(v)
        return out

    def vertex_mm(self) -> np.ndarray | None:
        return None if self.per_vertex is None else 1e3 * self.per_vertex / self.frames


def _with_landmarks(
    batch: Batch, which: str, model: SparseSoftDeca, face: ArkitFace | None
) -> Batch:
    if which == "same_head":
        own = model.landmarks_on(batch.S)
        return replace(batch, landmarks=own, landmarks_clean=own)
    if which == "other_head":
        return replace(batch, landmarks=batch.landmarks_clean)
    if which == "arkit_face":
        assert face is not None
        phone = model.arkit_landmarks(batch, face)
        return replace(batch, landmarks=phone, landmarks_clean=phone)
    return batch


def _test_takes(run: Run) -> list[int]:
    """The indices (header.takes) of the takes held out for the test split."""
    header = run.data.manifest["header"]
    names = [t["name"] if isinstance(t, dict) else t for t in header["takes"]]
    return [names.index(t) for t in GenerateConfig.from_dict(header["config"]).test_takes]


class GroupOffsetOracle(NoCorrection):
    """A reference, not a model: S_t plus the mean of T - S_t over the frames of its
    (identity, p) group, i.e. the part of the physics' correction that does not depend on the
    expression, known exactly. What it leaves is the expression-dependent part; what it removes
    is what a model has to get from p and h alone."""

    @torch.no_grad()
    def predict(self, batch: Batch) -> torch.Tensor:
        return batch.S + (batch.T - batch.S).mean(0, keepdim=True)


@torch.no_grad()
def measure(
    run: Run, name: str, model: Trainable, which: str | None = None, split: str = "test"
) -> ErrorSum:
    acc = ErrorSum()
    take = _test_takes(run)
    # batches of up to 8 frames of one (identity, p) group (GroupOffsetOracle needs whole
    # groups: the datasets have 2 or 8 frames per group). A test split is judged on every
    # frame; a train split on the frames training saw.
    max_error = EVERY_FRAME if split == "test" else None
    face = ArkitFace.load() if which == "arkit_face" else None
    for batch in run.data.batches(model.kind, split, None, 8, max_error):
        if isinstance(model, GroupOffsetOracle) and len(batch.T) < 2:
            continue  # a group of one frame: its own T is its offset, nothing is measured
        if isinstance(model, SparseSoftDeca) and which:
            batch = _with_landmarks(batch, which, model, face)
        acc.add(vertex_error(model.predict(batch), batch.T), batch.source_take, take)
    return acc  # may hold no frame: the dataset has none of the kind


def test_errors(
    run: Run, models: dict[str, Trainable], progress: bool = True
) -> dict[str, dict | float]:
    """Mean test errors (mm) of the bundle's models and of "no correction", keyed as the
    manifest's `errors` and the benchmark figures name them."""
    out: dict[str, dict | float] = {}
    jobs: list[tuple[str, Trainable, str | None]] = [
        ("no_correction_static", no_correction("static"), None),
        ("no_correction_dynamic", no_correction("dynamic"), None),
    ]
    for name, m in models.items():
        if isinstance(m, SparseSoftDeca):
            jobs += [(f"{name}_{w}", m, w) for w in SPARSE_INPUTS]
        elif isinstance(m, (Dynamics, LatentDynamics)):
            jobs.append((name, m, None))
            if isinstance(m.static, (SoftDeca, SoftDecaHybrid)):  # the static model alone
                jobs.append((f"{name}_without", _AsDynamic(m.static), None))
        else:
            jobs.append((f"{name}_static", m, None))
    for key, m, which in tqdm(jobs, desc="test errors", disable=not progress):
        out[key] = measure(run, key, m, which).summary()
    return out


def no_correction(kind: str) -> NoCorrection:
    """The linear blend S_t as a model of `kind`'s frames (static, dynamic or sparse)."""
    m = NoCorrection()
    m.kind = kind
    return m


class _AsDynamic(Trainable):
    """A static model evaluated on sequence frames (what dynamics add, by difference)."""

    kind = "dynamic"

    def __init__(self, static: Trainable) -> None:
        super().__init__()
        self.static = static

    def predict(self, batch: Batch) -> torch.Tensor:
        return self.static.predict(batch)


# --- time per frame -------------------------------------------------------------------------


def frame_function(model: Trainable, batch: Batch) -> Callable[[], object]:
    """The per-frame work of `model` for one frame of `batch`, with everything per avatar
    (hypernetwork outputs, the DT factorisation) prepared beforehand, as the runtime runs it."""
    first = {
        k: v[:1]
        for k, v in batch.__dict__.items()
        if k in ("weights", "S", "T", "landmarks", "landmarks_clean") and v is not None
    }
    one = Batch(**{**batch.__dict__, **first})
    if isinstance(model, SoftDeca):
        hyper = model.f_ph(expand(batch.p, model.n_faces), batch.h)

        def softdeca() -> object:
            z = model.f_w(one.weights)
            dg = torch.einsum("bk,fkn->bfn", z, hyper).reshape(1, -1, 3, 3)
            return deformation_transfer(one.dt, one.S, dg)

        return softdeca
    if isinstance(model, SoftDecaHybrid):
        faces = model.f_ph(batch.face_parameters(model.n_faces), batch.h)
        vertices = model.f_ph_v(batch.vertex_parameters(model.n_vertices), batch.h)

        def hybrid() -> object:
            z = model.f_w(one.weights)
            dg = torch.einsum("bk,fkn->bfn", z, faces).reshape(1, -1, 3, 3)
            return deformation_transfer(one.dt, one.S, dg) + torch.einsum(
                "bk,vkn->bvn", z, vertices
            )

        return hybrid
    if isinstance(model, SoftDecaVertex):
        hyper = model.f_ph_v(expand(batch.p, model.n_vertices), batch.h)
        return lambda: one.S + torch.einsum("bk,vkn->bvn", model.f_w(one.weights), hyper)
    if isinstance(model, SparseSoftDeca):
        hyper = model.f_ph_v(expand(batch.p, model.n_vertices), batch.h)
        off = (model.inputs(one) - model.neutral_landmarks(one.neutral)).reshape(1, -1)
        return lambda: one.neutral + torch.einsum("bk,vkn->bvn", model.f_l(off), hyper)
    if isinstance(model, FaceMlp):
        p = expand(batch.p, model.n_faces)
        b = model.body
        base = b.from_parameters(b.normalise(p)) + b.from_positional(b.positional)
        base = base + b.from_identity(batch.h)

        def face_mlp() -> object:
            x = base[None] + model.from_weights(one.weights)[:, None]
            dg = b.rest(x).reshape(1, model.n_faces, 3, 3)
            return deformation_transfer(one.dt, one.S, dg)

        return face_mlp
    if isinstance(model, (GlobalMlp, NoCorrection)):
        return lambda: model.predict(one)
    raise TypeError(f"no per-frame timing for {type(model).__name__}")


TIMING_SECONDS = 600.0  # a timing child that takes longer than this is stopped and reported


@torch.no_grad()
def _median_ms(model: Trainable, batch: Batch, repeats: int) -> float:
    """One warm-up frame, then the median of `repeats`, at this process's thread count."""
    fn = frame_function(model, batch)
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def _time_in_child(model: Trainable, batch: Batch, repeats: int, send) -> None:
    try:
        torch.set_num_threads(1)
        send.send(("ms", _median_ms(model, batch, repeats)))
    except BaseException as e:  # every failure goes back to the parent
        send.send(("error", f"{type(e).__name__}: {e}"))
    finally:
        send.close()


def time_per_frame(model: Trainable, batch: Batch, repeats: int = 20) -> float:
    """Median milliseconds of the per-frame work, single thread.

    Timed in a forked child: lowering torch's thread count and raising it again in one process
    leaves later LAPACK solves in that process wrong (a closed-form fit after a report moved by
    0.2 mm), so this process's count is never changed. Where fork is not available, the frame
    is timed here at the process's own thread count."""
    if "fork" not in mp.get_all_start_methods():
        return _median_ms(model, batch, repeats)
    ctx = mp.get_context("fork")
    receive, send = ctx.Pipe(duplex=False)
    child = ctx.Process(target=_time_in_child, args=(model, batch, repeats, send), daemon=True)
    child.start()
    send.close()
    try:
        if not receive.poll(TIMING_SECONDS):
            raise RuntimeError(f"timing {type(model).__name__} took over {TIMING_SECONDS:.0f} s")
        kind, value = receive.recv()
    except EOFError:
        kind, value = "error", f"the timing child ended with code {child.exitcode}"
    finally:
        receive.close()
        child.join(5)
        if child.is_alive():
            child.kill()
            child.join()
    if kind != "ms":
        raise RuntimeError(f"timing {type(model).__name__}: {value}")
    return float(value)
