"""The training loop shared by every model: Adam with a learning-rate schedule, a budget in
steps and/or minutes, periodic checkpoints that a rerun resumes from (model, optimiser, step,
elapsed time, data order), a progress bar, and a JSON-lines log."""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from softdeca_train.train.batches import Batch, Dataset
from softdeca_train.train.trainable import Trainable


@dataclass(frozen=True)
class LoopConfig:
    """How long and how fast one model trains. The run stops at whichever budget ends first."""

    steps: int = 2000
    minutes: float | None = None
    lr: float = 1e-3
    lr_end: float = 1e-4  # cosine decay from lr to lr_end over the budget (paper: 1e-4 -> 5e-5)
    frames: int = 8  # frames per batch (static/sparse: one (identity, p) group)
    groups: int = 1  # batches per step: a step's gradient over several (identity, p) groups
    seed: int = 0
    checkpoint_minutes: float = 2.0
    grad_clip: float = 1.0
    hyper_lr: float | None = None  # the hypernetworks' learning-rate factor (None: the model's)


def _lr(cfg: LoopConfig, progress: float) -> float:
    c = 0.5 * (1 + math.cos(math.pi * min(1.0, progress)))
    return cfg.lr_end + (cfg.lr - cfg.lr_end) * c


def endless(data: Dataset, kind: str, cfg: LoopConfig, epoch0: int) -> Iterator[Batch]:
    """Training batches forever, reshuffled each pass (epoch-seeded: resumable)."""
    epoch = epoch0
    while True:
        n = 0
        data.refresh()  # shards finished since the last pass join (training while generating)
        for b in data.batches(kind, "train", np.random.default_rng([cfg.seed, epoch]), cfg.frames):
            n += 1
            yield b
        if n == 0:
            raise ValueError(f"the dataset {data.folder} has no usable {kind} training frames")
        epoch += 1


def train(
    model: Trainable,
    data: Dataset,
    cfg: LoopConfig,
    folder: Path,
    name: str,
    progress: bool = True,
    on_checkpoint: Callable[[], None] | None = None,
) -> dict:
    """Train `model` in place; checkpoint to folder/<name>.pt, log to folder/<name>.log.jsonl.
    Returns the run summary (steps, minutes, last losses)."""
    if cfg.groups < 1:
        raise ValueError(f"groups per step must be at least 1, not {cfg.groups}")
    folder.mkdir(parents=True, exist_ok=True)
    ckpt, log_path = folder / f"{name}.pt", folder / f"{name}.log.jsonl"
    torch.manual_seed(cfg.seed)
    params = [q for q in model.parameters() if q.requires_grad]
    scales = model.lr_scales(cfg.hyper_lr)
    by_factor: dict[float, list[torch.nn.Parameter]] = {}
    for pname, q in model.named_parameters():
        if q.requires_grad:
            f = next((v for k, v in scales.items() if pname.startswith(k)), 1.0)
            by_factor.setdefault(f, []).append(q)
    opt = torch.optim.Adam([{"params": g, "scale": f} for f, g in by_factor.items()], lr=cfg.lr)
    step, elapsed, resumes = 0, 0.0, 0
    if ckpt.is_file():
        state = torch.load(ckpt, weights_only=False)
        if state.get("config") != asdict(cfg):
            raise ValueError(
                f"{ckpt} was written with another configuration; delete it to start over"
            )
        model.load_state_dict(state["model"])
        opt.load_state_dict(state["optimiser"])
        step, elapsed, resumes = state["step"], state["elapsed"], state["resumes"] + 1
        if progress:
            print(f"{name}: resuming at step {step} ({elapsed / 60:.1f} min done)")
    budget_s = cfg.minutes * 60 if cfg.minutes else math.inf

    def save() -> None:
        tmp = ckpt.with_suffix(".tmp")
        torch.save(
            {
                "config": asdict(cfg),
                "model": model.state_dict(),
                "optimiser": opt.state_dict(),
                "step": step,
                "elapsed": elapsed,
                "resumes": resumes,
                "done": done(),
            },
            tmp,
        )
        tmp.replace(ckpt)  # atomic: a kill never leaves a half-written checkpoint
        if on_checkpoint:
            on_checkpoint()

    def done() -> bool:
        return step >= cfg.steps or elapsed >= budget_s

    # A resumed run draws a fresh data order (its own epoch seeds), not the interrupted one's.
    batches = endless(data, model.kind, cfg, 1000 * resumes)
    # The bar follows whichever budget is binding: seconds when minutes are given.
    timed = cfg.minutes is not None
    bar = tqdm(
        total=round(budget_s) if timed else cfg.steps,
        initial=round(elapsed) if timed else step,
        desc=name,
        disable=not progress,
        unit="s" if timed else "step",
    )
    last_save, recent, recent_nc = time.monotonic(), [], []
    model.train()
    with log_path.open("a") as log:
        while not done():
            t0 = time.monotonic()
            frac = max(step / cfg.steps, elapsed / budget_s)
            for g in opt.param_groups:
                g["lr"] = _lr(cfg, frac) * g["scale"]
            opt.zero_grad(set_to_none=True)
            parts = []
            for _ in range(cfg.groups):  # gradients accumulate over the groups of one step
                loss, m = model.loss(next(batches))
                (loss / cfg.groups).backward()
                parts.append(m)
            metrics = {k: float(np.mean([m[k] for m in parts])) for k in parts[0]}
            torch.nn.utils.clip_grad_norm_(params, cfg.grad_clip)
            opt.step()
            step += 1
            elapsed += time.monotonic() - t0
            recent = [*recent[-49:], metrics["error_mm"]]
            recent_nc = [*recent_nc[-49:], metrics.get("no_correction_mm", np.nan)]
            log.write(json.dumps({"step": step, "s": round(elapsed, 2), **metrics}) + "\n")
            bar.update(round(elapsed) - bar.n if timed else 1)
            # error relative to "no correction" (S_t) on the same batches: < 1 is progress
            rel = np.mean(recent) / np.mean(recent_nc)
            bar.set_postfix(step=step, mm=f"{np.mean(recent):.3f}", rel=f"{rel:.3f}")
            if time.monotonic() - last_save > 60 * cfg.checkpoint_minutes:
                save()
                log.flush()
                last_save = time.monotonic()
    bar.close()
    save()
    model.eval()
    return {
        "steps": step,
        "minutes": round(elapsed / 60, 2),
        "lr_factors": scales,  # the effective per-prefix factors (cfg.hyper_lr may be None)
        "train_error_mm_last50": float(np.mean(recent)) if recent else None,
        "train_no_correction_mm_last50": float(np.mean(recent_nc)) if recent_nc else None,
    }
