"""A training run: a folder with run.json (the dataset it trains on, network sizes, seed) and
one checkpoint per trained model (registry.py names), plus the identity encoder. Every stage
resumes from its checkpoint, so `train-bundle` can be killed and rerun at any point."""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field, fields, replace
from functools import cached_property
from pathlib import Path

import numpy as np
import torch

from softdeca_train.data.config import GenerateConfig
from softdeca_train.models.networks import FULL_SIZES, TEST_SIZES, IdentityEncoder, NetworkSizes
from softdeca_train.models.topology import TemplateDefinition, from_template
from softdeca_train.parameters import ParameterSpec
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN
from softdeca_train.train.batches import Dataset
from softdeca_train.train.identity import IdentityConfig, train_identity_encoder
from softdeca_train.train.loop import LoopConfig, train
from softdeca_train.train.registry import MODELS, dataset_specs
from softdeca_train.train.trainable import Trainable

# "test": the tiny networks of the tests, with the template's identity size (the data's h)
# and an encoder wide enough for its exact least-squares start (train/identity.py).
SIZES = {
    "full": FULL_SIZES,
    "test": replace(
        TEST_SIZES, identity=FULL_SIZES.identity, encoder_hidden=(FULL_SIZES.identity,)
    ),
}


@dataclass(frozen=True)
class RunConfig:
    dataset: str
    sizes: str = "full"  # full: docs/bundle.md's networks; test: tiny ones for the tests
    seed: int = 0
    extra: dict = field(default_factory=dict)
    # a dataset generated with --contrasts whose static train frames and their pairs also
    # fit SoftDECA's residual stage (docs/training.md); None: the dataset alone
    contrasts: str | None = None
    # datasets generated like `dataset` (its range profile and level, another seed) whose
    # static train frames join SoftDECA's closed-form start and residual stage
    more_static: tuple[str, ...] = ()
    # SoftDECA exact at rest (NetworkSizes.rest_gate): 0 (new runs), its correction g(w) - g(0)
    # with no part independent of w; tau > 0, that part gated by |w|^2 / (|w|^2 + tau^2);
    # None, the form of the runs before (a constant part, not exact at rest)
    rest_gate: float | None = 0.0
    # members of SoftDECA's residual stage (ResidualSizes), None: the sizes' own. Each member
    # reads its own weights every frame (1.74 MB of float weights for five at full size): fewer
    # members cost the frame less
    residual_members: int | None = None
    # SoftDECA learns the correction on top of the rest physics: its frames' S_t + Pd, Pd the
    # physics' rest change under the group's parameters (train/rest_changes.py), which the
    # runtime adds whole at prepare (the bundle's `rest_changes`); False: on S_t
    rest_changes: bool = False

    def __post_init__(self) -> None:  # run.json holds a list (and a caller may give paths)
        object.__setattr__(self, "more_static", tuple(str(d) for d in self.more_static))


def _key(c: RunConfig) -> tuple:
    """What a run's checkpoints depend on (every setting but `extra`): a run folder keeps one."""
    return tuple(getattr(c, f.name) for f in fields(c) if f.name != "extra")


def _read_config(path: Path) -> RunConfig:
    """A run's run.json; one written before the rest gate existed trained without one."""
    return RunConfig(**{"rest_gate": None, **json.loads(path.read_text())})


class Run:
    def __init__(self, folder: str | Path, config: RunConfig | None = None) -> None:
        self.folder = Path(folder)
        path = self.folder / "run.json"
        if config is None:
            if not path.is_file():
                raise FileNotFoundError(f"{self.folder} is not a training run (no run.json)")
            config = _read_config(path)
        elif path.is_file():
            old = _read_config(path)
            if _key(old) != _key(config):
                raise ValueError(
                    f"{self.folder} trains on {old.dataset} ({old.sizes}, seed {old.seed}, "
                    f"contrasts {old.contrasts}, more static data {list(old.more_static)}, "
                    f"rest gate {old.rest_gate}, residual members {old.residual_members}, "
                    f"rest changes {old.rest_changes}); use another folder for another dataset, "
                    "sizes, seed, contrasts, more data, rest gate, residual members or rest "
                    "changes"
                )
        else:
            self.folder.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(asdict(config), indent=1) + "\n")
        if config.sizes not in SIZES:
            raise ValueError(f"sizes must be one of {sorted(SIZES)}")
        if config.residual_members is not None and config.residual_members < 1:
            raise ValueError("the residual stage needs at least one member")
        self.config = config

    @cached_property
    def template(self) -> Template:
        return Template.load()

    @cached_property
    def data(self) -> Dataset:
        return self._dataset(self.config.dataset)

    @cached_property
    def blend_data(self) -> Dataset:
        """The dataset with S_t the linear blend, what a bundle's frames read (with
        rest_changes the run's own `data` carry S_t + Pd; the bundle adds Pd at prepare)."""
        if not self.config.rest_changes:
            return self.data
        return Dataset(self.config.dataset, self.template, [s.name for s in self.specs])

    def _dataset(self, folder: str) -> Dataset:
        names = [s.name for s in self.specs]
        return Dataset(folder, self.template, names, rest_changes=self.config.rest_changes)

    @cached_property
    def contrasts(self) -> Dataset | None:
        if self.config.contrasts is None:
            return None
        data = self._dataset(self.config.contrasts)
        if not data.manifest["header"]["config"].get("contrasts"):
            raise ValueError(f"{self.config.contrasts} was not generated with --contrasts")
        return data

    @cached_property
    def more_static(self) -> list[Dataset]:
        """The datasets whose static train frames join SoftDECA's start; each must be drawn
        like the run's dataset (the same range profile, level, tolerance and collisions: else
        its frames teach another physics or other ranges) from a seed of its own."""
        out = []
        main = GenerateConfig.from_dict(self.data.manifest["header"]["config"])
        seeds = {main.seed}
        for folder in self.config.more_static:
            data = self._dataset(folder)
            cfg = GenerateConfig.from_dict(data.manifest["header"]["config"])
            if cfg.seed in seeds:  # identities come from the seed: the test split's among them
                raise ValueError(
                    f"{folder}: seed {cfg.seed} again; its identities would repeat those of "
                    "the run's dataset (its test identities too) or of another: use another seed"
                )
            seeds.add(cfg.seed)
            for name in ("ranges", "level", "tolerance", "collisions", "contrasts"):
                if getattr(cfg, name) != getattr(main, name):
                    raise ValueError(
                        f"{folder}: {name} {getattr(cfg, name)!r}, the run's dataset has "
                        f"{getattr(main, name)!r}: more static data must be drawn like it"
                    )
            if not data.left_out("static", "train")["kept"]:
                raise ValueError(f"{folder} holds no static train frame")
            out.append(data)
        return out

    @cached_property
    def definition(self) -> TemplateDefinition:
        return from_template(self.template)

    @property
    def sizes(self) -> NetworkSizes:
        sizes = replace(
            SIZES[self.config.sizes],
            rest_gate=self.config.rest_gate,
            region_means=not self.config.rest_changes,
        )
        if self.config.residual_members is not None:
            sizes = replace(sizes, residual_members=self.config.residual_members)
        return sizes

    @cached_property
    def specs(self) -> tuple[ParameterSpec, ...]:
        # read from the manifest itself: the Dataset takes the model's columns from here
        manifest = json.loads((Path(self.config.dataset) / "manifest.json").read_text())
        cfg = GenerateConfig.from_dict(manifest["header"]["config"])
        return dataset_specs(cfg.ranges)

    def checkpoint(self, name: str) -> Path:
        return self.folder / f"{name}.pt"

    def finished(self, name: str) -> bool:
        path = self.checkpoint(name)
        return path.is_file() and bool(torch.load(path, weights_only=False).get("done"))

    def build(self, name: str) -> Trainable:
        entry = MODELS[name]
        base = self.load(entry.base) if entry.base else None
        return entry.make(self.definition, self.specs, self.sizes, base)

    def load(self, name: str) -> Trainable:
        """A trained model (its checkpoint must be finished)."""
        path = self.checkpoint(name)
        if not path.is_file():
            raise FileNotFoundError(f"{name} is not trained in {self.folder} (no {path.name})")
        model = self.build(name)
        try:
            model.load_state_dict(torch.load(path, weights_only=False)["model"])
        except RuntimeError as e:  # a checkpoint of another architecture under this name
            raise ValueError(
                f"{path} does not hold the current {name} model ({MODELS[name].description}); "
                f"it was trained with another version of it: train {name} again in a new "
                f"run folder. ({str(e).splitlines()[0]})"
            ) from e
        return model.eval()

    def train(self, name: str, cfg: LoopConfig, progress: bool = True) -> dict:
        if name not in MODELS:
            raise ValueError(f"unknown model {name!r}; known: {', '.join(MODELS)}")
        model = self.build(name)
        fresh = not self.checkpoint(name).is_file()
        if fresh:
            rng = np.random.default_rng(cfg.seed)
            model.init_from_dataset(
                self.data, rng, progress=progress, contrasts=self.contrasts, more=self.more_static
            )
        # the train frames the run could read, when it started and when it ended: a dataset
        # still being generated lists more finished shards each pass (loop.endless), and the
        # training record's dataset summary is of the dataset as it is later
        self.data.refresh()
        at_start = self.data.left_out(model.kind, "train")["kept"]
        summary = train(model, self.data, cfg, self.folder, name, progress)
        self.data.refresh()
        at_end = self.data.left_out(model.kind, "train")["kept"]
        summary["train_frames_listed"] = {
            "kind": model.kind,
            "at_start": at_start,
            "at_end": at_end,
        }
        summary["config"] = asdict(cfg)
        (self.folder / f"{name}.summary.json").write_text(json.dumps(summary, indent=1) + "\n")
        return summary

    def identity_encoder(self, cfg: IdentityConfig, progress: bool = True) -> tuple:
        """The trained identity encoder (trained now if the run has none) and its errors."""
        path, info = self.folder / "identity.pt", self.folder / "identity.json"

        if path.is_file() and info.is_file():
            enc = IdentityEncoder(N_SKIN, self.sizes, cfg.seed)
            enc.load_state_dict(torch.load(path, weights_only=False))
            return enc.eval(), json.loads(info.read_text())
        enc, errors = train_identity_encoder(self.template, self.sizes, cfg, progress)
        torch.save(enc.state_dict(), path)
        info.write_text(json.dumps({"config": asdict(cfg), "errors": errors}, indent=1) + "\n")
        return enc, json.loads(info.read_text())
