"""The fit against the truth: a held-out ICT identity made into a user's avatar (remeshed to
another topology, shuffled, in centimetres, Z-up) is fitted, and on the frames of recorded
takes what the fitted avatar gets is compared with what the same identity gets on the template
path, at the same surface points (the avatar's truth, sample_avatars/mesh.py):

- SoftDECA: the correction (SoftDECA - linear blend), per frame the mean distance between the
  two over the face, over the template path's mean magnitude there;
- SparseSoftDECA: its deformation (output - neutral) from the same tracked ARKit face, likewise;
- the largest distance of any avatar vertex from its own linear blend (mm);
- the fitted avatar's identity code against the identity's own.

`python -m softdeca_train avatar-fit-check` runs it on every held-out identity and every take
(every 10th frame) and writes the report; tests/python/test_fit_avatars.py holds one reduced
case."""

from __future__ import annotations

import json
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from softdeca_train.host.native import AvatarArrays, NativeAvatar, NativeFit, NativeModel
from softdeca_train.landmarks.arkit_reference import ArkitFace
from softdeca_train.paths import REPO_ROOT, default_recordings_path
from softdeca_train.sample_avatars.build import make_avatar
from softdeca_train.sample_avatars.config import HELD_OUT_IDENTITIES, AvatarConfig
from softdeca_train.sample_avatars.mesh import AvatarMesh
from softdeca_train.sim.take import read_take
from softdeca_train.streaming.takes import take_paths
from softdeca_train.template import Template
from softdeca_train.template.identities import identity_coefficients

DEFAULT_BUNDLE = REPO_ROOT / "models" / "softdeca-default"


@dataclass(frozen=True)
class FitCheckConfig:
    identities: tuple[str, ...] = HELD_OUT_IDENTITIES
    remesh: int = 8000  # vertices of the avatar's skin
    unit: str = "cm"
    up: str = "z"
    stride: int = 10  # every stride-th frame of each take
    max_frames: int | None = None  # per take (None: all)
    takes: tuple[str, ...] = ()  # take file stems (empty: every take)
    bundle: str = str(DEFAULT_BUNDLE)


@dataclass
class TakeResult:
    take: str
    frames: int
    softdeca_ratio: float  # mean over frames of mean|difference| / mean|template path| (face)
    softdeca_ratio_max: float
    sparse_ratio: float
    sparse_ratio_max: float
    max_from_linear_mm: float  # the largest distance of an avatar vertex from its own blend


@dataclass
class IdentityResult:
    identity: str
    avatar_vertices: int
    fit: dict
    # the fitted avatar's identity code against the identity's own (h is N(0, I)): the RMS
    # over the coefficients, and over each tenth of them in order
    code_error_rms: float = float("nan")
    code_error_rms_by_tenth: list[float] = field(default_factory=list)
    takes: list[TakeResult] = field(default_factory=list)


def avatar_arrays(avatar: AvatarMesh) -> AvatarArrays:
    return AvatarArrays(avatar.neutral, avatar.triangles, avatar.deltas)


def template_head(template: Template, identity: str) -> tuple[np.ndarray, np.ndarray]:
    """The identity's head in the template's topology (metres) and its 52 shapes as deltas."""
    h = identity_coefficients(template, identity)
    eye = np.eye(52)
    neutral = template.blend(np.zeros(52), h)
    deltas = np.stack([template.blend(eye[i], h) - neutral for i in range(52)])
    return neutral, deltas


def face_mask(avatar: AvatarMesh, deltas: np.ndarray) -> np.ndarray:
    """Avatar vertices on the skin the template's shapes move: the face."""
    moved = (np.abs(deltas).max(axis=(0, 2)) > 0).astype(np.float64)
    inside = avatar.truth.evaluate(moved)
    return avatar.truth.part_mask("skin") & (np.nan_to_num(inside) > 0.999)


def _ratio(fitted: np.ndarray, truth: np.ndarray, face: np.ndarray) -> float:
    magnitude = np.linalg.norm(truth[face], axis=1).mean()
    return float(np.linalg.norm(fitted[face] - truth[face], axis=1).mean() / magnitude)


def check_take(
    fitted: NativeAvatar,
    reference: NativeAvatar,
    avatar: AvatarMesh,
    face: np.ndarray,
    arkit: ArkitFace,
    weights: np.ndarray,
) -> tuple[list[float], list[float], float]:
    """Per frame: SoftDECA's and SparseSoftDECA's ratios, and the largest distance (avatar
    units) of any vertex from the avatar's own linear blend."""
    t = avatar.truth
    soft, sparse, worst = [], [], 0.0
    for w in weights:
        w = np.clip(w, 0, 1).astype(np.float32)
        out, _ = fitted.evaluate_weights(w)
        lin, _ = fitted.evaluate_linear(w)
        ref, _ = reference.evaluate_weights(w)
        ref_lin, _ = reference.evaluate_linear(w)
        truth = t.to_avatar(t.evaluate(ref - ref_lin), direction=True)
        soft.append(_ratio(out - lin, truth, face))
        worst = max(worst, float(np.linalg.norm(out - lin, axis=1).max()))
        if fitted.model.info.has_sparse:
            points = arkit.blend(w).astype(np.float32)
            out, _ = fitted.evaluate_landmarks(points)
            ref, _ = reference.evaluate_landmarks(points)
            truth = t.to_avatar(t.evaluate(ref - reference.neutral), direction=True)
            sparse.append(_ratio(out - fitted.mesh.neutral, truth, face))
    return soft, sparse, worst


def check_identity(
    model: NativeModel,
    template: Template,
    arkit: ArkitFace,
    identity: str,
    config: FitCheckConfig,
    takes: list[Path],
    progress: bool = False,
) -> IdentityResult:
    avatar = make_avatar(
        AvatarConfig(
            identity=identity, remesh=config.remesh, shuffle=True, unit=config.unit, up=config.up
        ),
        template,
    )
    arrays = avatar_arrays(avatar)
    fit = NativeFit.create(model, arrays)
    fitted = NativeAvatar.fitted(model, fit, arrays)
    neutral, deltas = template_head(template, identity)
    reference = NativeAvatar(model, neutral, template.triangles, deltas)
    reference.neutral = neutral.astype(np.float32)
    for a in (fitted, reference):
        a.prepare()
        if model.info.has_sparse:
            a.calibrate_landmarks(arkit.neutral.astype(np.float32))
    face = face_mask(avatar, deltas)
    error = fitted.identity() - identity_coefficients(template, identity)
    result = IdentityResult(
        identity,
        len(avatar.neutral),
        fit.report(),
        float(np.sqrt(np.mean(error**2))),
        [float(np.sqrt(np.mean(e**2))) for e in np.array_split(error, 10)],
    )
    mm_per_unit = 1000.0 * avatar.truth.metres_per_unit
    for path in takes:
        take = read_take(path, stride=config.stride)
        weights = take.weights[: config.max_frames] if config.max_frames else take.weights
        soft, sparse, worst = check_take(fitted, reference, avatar, face, arkit, weights)
        r = TakeResult(
            take=path.stem,
            frames=len(weights),
            softdeca_ratio=float(np.mean(soft)),
            softdeca_ratio_max=float(np.max(soft)),
            sparse_ratio=float(np.mean(sparse)) if sparse else float("nan"),
            sparse_ratio_max=float(np.max(sparse)) if sparse else float("nan"),
            max_from_linear_mm=worst * mm_per_unit,
        )
        result.takes.append(r)
        if progress:
            print(
                f"  {identity:>9} {r.take:<11} {r.frames:4d} frames  "
                f"SoftDECA {r.softdeca_ratio:.3f} (max {r.softdeca_ratio_max:.3f})  "
                f"sparse {r.sparse_ratio:.3f}  "
                f"max from linear {r.max_from_linear_mm:.1f} mm",
                file=sys.stderr,
                flush=True,
            )
    return result


def run_fit_check(config: FitCheckConfig, progress: bool = True) -> dict:
    started = time.perf_counter()
    model = NativeModel(config.bundle)
    template, arkit = Template.load(), ArkitFace.load()
    takes = take_paths(default_recordings_path())
    if config.takes:
        takes = [p for p in takes if p.stem in config.takes]
    if not takes:
        raise FileNotFoundError(f"no takes in {default_recordings_path()}")
    results = []
    for identity in config.identities:
        if progress:
            print(
                f"fitting {identity} ({config.remesh} vertices, {config.unit}, {config.up}-up)",
                file=sys.stderr,
            )
        results.append(check_identity(model, template, arkit, identity, config, takes, progress))
    return {
        "config": asdict(config),
        "seconds": time.perf_counter() - started,
        "identities": [asdict(r) for r in results],
    }


def write_report(report: dict, out: Path) -> Path:
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(report, indent=1) + "\n")
    return out
