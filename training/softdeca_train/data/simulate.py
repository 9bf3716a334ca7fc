"""One shard, simulated: the worker's job. Pure function of (ShardSpec, GenerateConfig): the
identity comes from its seed, everything else from the spec, and each simulator runs on a
fixed number of threads, so a shard is bit-identical wherever and whenever it is made."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import softdeca_native as native

from softdeca_train.data.blend import SkinBlend
from softdeca_train.data.config import GenerateConfig
from softdeca_train.data.personalise import add_noise, personalise
from softdeca_train.data.plan import GroupSpec, ShardSpec
from softdeca_train.landmarks import SurfaceLandmarks, template_landmarks
from softdeca_train.lhm import LhmConfig
from softdeca_train.parameters import load_parameters
from softdeca_train.sim import HeadSimulation, build_head_simulation
from softdeca_train.sim.measures import SoftVolume
from softdeca_train.sim.sanity import REASONS, VolumeField, check_frame
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.regions import REGIONS, element_regions, region_labels

F16_MAX = 65504.0


@dataclass
class WorkerContext:
    """What every shard of a worker needs, loaded once per process."""

    template: Template
    landmarks: SurfaceLandmarks
    blend: SkinBlend


_CONTEXTS: dict[str | None, WorkerContext] = {}


def context(ict: str | None) -> WorkerContext:
    if ict not in _CONTEXTS:
        t = Template.load(ict)
        _CONTEXTS[ict] = WorkerContext(t, template_landmarks(t), SkinBlend.of(t))
    return _CONTEXTS[ict]


def without_collisions(m: native.SimulationMesh) -> native.SimulationMesh:
    """The same mesh without its lip/teeth collision sets."""
    has_lm = m.landmark_count > 0
    return native.SimulationMesh(
        rest=m.rest,
        soft_tets=m.soft_tets,
        muscle_tets=m.muscle_tets,
        connecting_tets=m.connecting_tets,
        skull_triangles=m.skull_triangles,
        cranium_vertices=list(m.cranium_vertices),
        jaw_vertices=list(m.jaw_vertices),
        skin_vertices=m.skin_vertices,
        skin_weights=m.skin_weights,
        skin_triangles=m.skin_triangles,
        landmark_points=m.landmark_points if has_lm else None,
        landmark_weights=m.landmark_weights if has_lm else None,
    )


def quantise(skin: np.ndarray, targets: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """float16 offsets T - S_t, their rounding errors (m) and largest magnitude (m)."""
    off = np.asarray(skin, np.float64) - targets
    if not np.isfinite(off).all() or np.abs(off).max() >= F16_MAX:
        raise FloatingPointError("simulated skin is not finite or out of float16 range")
    q = off.astype(np.float16)
    return q, q.astype(np.float64) - off, float(np.abs(off).max())


class _Shard:
    """Accumulates one shard's per-instance arrays."""

    def __init__(self) -> None:
        self.cols: dict[str, list[np.ndarray]] = {}
        self.quant_error = 0.0
        self.quant_sq_sum = 0.0
        self.quant_values = 0
        self.max_offset = 0.0
        self.frames = 0
        self.failures = dict.fromkeys((*REASONS, "failed_frames"), 0)

    def add(self, **arrays: np.ndarray) -> None:
        for k, v in arrays.items():
            self.cols.setdefault(k, []).append(np.asarray(v))

    def offsets(self, skin: np.ndarray, targets: np.ndarray) -> np.ndarray:
        q, err, mag = quantise(skin, targets)
        self.quant_error = max(self.quant_error, float(np.abs(err).max()))
        self.quant_sq_sum += float((err**2).sum())
        self.quant_values += err.size
        self.max_offset = max(self.max_offset, mag)
        return q

    def judge(
        self,
        hs: HeadSimulation,
        volume: SoftVolume,
        targets: np.ndarray,
        solved: list[tuple[np.ndarray, np.ndarray, dict]],
        target_volume: float | VolumeField,
    ) -> np.ndarray:
        """Per frame the sanity bounds' failures as a bit mask (bit i: REASONS[i]), counted."""
        masks = np.zeros(len(solved), np.uint8)
        for f, (vertices, skin, st) in enumerate(solved):
            failed = check_frame(
                hs, volume, targets[f], skin, vertices, st, target_volume
            ).failures()
            for r in failed:
                masks[f] |= 1 << REASONS.index(r)
                self.failures[r] += 1
            self.failures["failed_frames"] += bool(failed)
        return masks

    def arrays(self) -> dict[str, np.ndarray]:
        return {k: np.concatenate(v) for k, v in self.cols.items()}


def _set_parameters(sim: native.Simulator, names: list[str], p: np.ndarray) -> None:
    for name, value in zip(names, p, strict=True):
        sim.set_parameter(name, float(value))


def _set_regional(
    head: _Head, g: GroupSpec, names: list[str]
) -> tuple[np.ndarray, float | VolumeField]:
    """The group's regional pattern on the simulator (fields over the parameters' element
    domains). Returns the pattern stored with the instances (p in every region without one)
    and the soft tissue's requested volume: p's target_volume, or its field with each tet's
    region where the pattern varies it (the volume bound judges each region on its own)."""
    tv = names.index("target_volume")
    if g.p_regions is None:
        return np.repeat(g.p[None], len(REGIONS), axis=0), float(g.p[tv])
    labels = region_labels(head.ctx.template)
    domains = {s.name: s.domain for s in load_parameters().specs}
    skin = head.hs.head[:N_SKIN]
    requested: float | VolumeField = float(g.p[tv])
    for k, name in enumerate(names):
        column = g.p_regions[:, k]
        if np.any(column != g.p[k]):
            regions = element_regions(labels, head.sim.mesh, skin, domains[name])
            field = np.asarray(column, np.float64)[regions]
            head.sim.set_parameter_field(name, field)
            if k == tv:
                requested = VolumeField(values=field, groups=regions)
    return g.p_regions, requested


def _stats(stats: list[dict]) -> dict[str, np.ndarray]:
    return {
        "iterations": np.array([s["iterations"] for s in stats], np.int16),
        "converged": np.array([s["converged"] for s in stats], bool),
        "estimated_error": np.array([s["estimated_error"] for s in stats], np.float32),
    }


@dataclass
class _Head:
    """One shard's head under simulation, and where its frames go."""

    ctx: WorkerContext
    hs: HeadSimulation
    sim: native.Simulator
    cfg: GenerateConfig
    out: _Shard
    volume: SoftVolume


def _static_group(head: _Head, g: GroupSpec, sparse: bool, names: list[str]) -> None:
    ctx, hs, sim, cfg, out, volume = (head.ctx, head.hs, head.sim, head.cfg, head.out, head.volume)
    _set_parameters(sim, names, g.p)
    p_regions, requested_volume = _set_regional(head, g, names)
    w = g.frames.weights
    targets = ctx.blend.targets(hs.head[:N_SKIN], w)
    jaws = hs.jaw_transforms(hs.blend(w))
    n = len(w)
    clean = None
    extra: dict[str, np.ndarray] = {}
    if sparse:
        t, lms = ctx.template, ctx.landmarks
        donor_h = t.sample_identity(g.donor_seed, cfg.identity_scale)
        donor_neutral = t.identity_neutral(donor_h)[:N_SKIN]
        donor_frames = ctx.blend.targets(donor_neutral, w)
        clean = personalise(
            lms.evaluate(donor_neutral), lms.evaluate(donor_frames), lms.evaluate(hs.head)
        )
        noisy = add_noise(clean, cfg.landmark_noise_mm * 1e-3, g.noise_seed)
        extra = {
            "landmarks": noisy.astype(np.float32),
            "landmarks_clean": clean.astype(np.float32),
            "donor_id": np.full(n, g.donor_id, np.int32),
            "donor_h": np.repeat(donor_h.astype(np.float32)[None], n, axis=0),
        }
    # The physics follows the face (the clean landmarks); the noise belongs to the tracker and
    # reaches only the network's input. Noisy targets dimple the skin around each landmark and
    # invert tets there.
    solved = [
        sim.solve_static(
            targets[f], landmark_targets=None if clean is None else clean[f], jaw=jaws[f]
        )
        for f in range(n)
    ]
    skins, stats = [s[1] for s in solved], [s[2] for s in solved]
    out.add(
        failures=out.judge(hs, volume, targets, solved, requested_volume),
        param_id=np.full(n, g.param_id, np.int32),
        p=np.repeat(g.p[None], n, axis=0),
        p_regions=np.repeat(p_regions[None], n, axis=0),
        weights=w,
        source_take=g.frames.source_take,
        source_index=g.frames.source_index,
        offsets=out.offsets(np.stack(skins), targets),
        **_stats(stats),
        **extra,
    )
    out.frames += n


def _dynamic_group(head: _Head, g: GroupSpec, names: list[str]) -> None:
    ctx, hs, sim, cfg, out, volume = (head.ctx, head.hs, head.sim, head.cfg, head.out, head.volume)
    w = g.frames.weights  # lead-in + sequence
    targets = ctx.blend.targets(hs.head[:N_SKIN], w)
    jaws = hs.jaw_transforms(hs.blend(w))
    lead = cfg.lead_in
    fixed = g.p.copy()
    fixed[names.index("dyn_gamma")] = cfg.lead_in_gamma
    fixed[names.index("dyn_beta")] = cfg.lead_in_beta
    _set_parameters(sim, names, fixed)
    sim.reset_dynamics()
    solved = []
    reference = []  # each step's blended target: what its frame is judged against
    for f in range(len(w)):
        if f == lead:  # the sampled dynamics take over, with the lead-in's velocity
            _set_parameters(sim, names, g.p)
        reference.append(sim.dynamic_target(targets[f]))
        solved.append(sim.step_dynamic(targets[f], jaw=jaws[f]))
    skins, stats = [s[1] for s in solved], [s[2] for s in solved]
    offsets = out.offsets(np.stack(skins), targets)
    failures = out.judge(
        hs, volume, np.stack(reference[lead:]), solved[lead:], sim.get_parameter("target_volume")
    )
    seq = slice(lead, None)
    st = _stats(stats[lead:])
    out.add(
        param_id=np.array([g.param_id], np.int32),
        p=g.p[None],
        weights=w[None, seq],
        source_take=g.frames.source_take[None, seq],
        source_index=g.frames.source_index[None, seq],
        offsets=offsets[None, seq],
        prev_weights=w[None, lead - 2 : lead],
        prev_offsets=offsets[None, lead - 2 : lead],
        prev_source_index=g.frames.source_index[None, lead - 2 : lead],
        failures=failures[None],
        **{k: v[None] for k, v in st.items()},
    )
    out.frames += len(w)


def simulate_shard(
    spec: ShardSpec, cfg: GenerateConfig, ict: str | None = None, threads: int = 1
) -> tuple[dict[str, np.ndarray], dict]:
    """-> (the shard's arrays, one instance per row; info for the manifest)."""
    t0 = time.perf_counter()
    ctx = context(ict)
    t = ctx.template
    names = load_parameters().names
    h = t.sample_identity(spec.identity_seed, cfg.identity_scale)
    sparse = spec.kind == "sparse"
    lms = (ctx.landmarks.triangle, ctx.landmarks.bary) if sparse else None
    hs = build_head_simulation(t, h, LhmConfig(level=cfg.level), landmarks=lms)
    mesh = hs.mesh if cfg.collisions else without_collisions(hs.mesh)
    sim = native.Simulator(
        mesh, tolerance=cfg.tolerance, max_iterations=cfg.max_iterations, threads=threads
    )
    volume = SoftVolume(hs)
    t_build = time.perf_counter() - t0
    out = _Shard()
    head = _Head(ctx, hs, sim, cfg, out, volume)
    for g in spec.groups:
        if spec.kind == "dynamic":
            _dynamic_group(head, g, names)
        else:
            _static_group(head, g, sparse, names)
    arrays = out.arrays()
    n = len(arrays["param_id"])
    arrays = {
        "instance_id": spec.instance_ids,
        "split": np.full(n, spec.split, np.int8),
        "identity_id": np.full(n, spec.identity_id, np.int32),
        "h": np.repeat(h.astype(np.float32)[None], n, axis=0),
        **arrays,
    }
    info = {
        "split": spec.split,
        "identity_id": spec.identity_id,
        "frames_solved": out.frames,
        "seconds": round(time.perf_counter() - t0, 3),
        "build_seconds": round(t_build, 3),
        "tet_source": hs.tet_source,
        "max_quantisation_error_m": out.quant_error,
        "quantisation_sq_sum_m2": out.quant_sq_sum,
        "quantisation_values": out.quant_values,
        "max_offset_m": out.max_offset,
        "frames_judged": int(arrays["failures"].size),
        "failures": out.failures,
        "simulated_vertices": int(mesh.vertex_count),
        "factorizations": int(sim.factorizations),
    }
    return arrays, info
