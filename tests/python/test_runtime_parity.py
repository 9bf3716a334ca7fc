"""Parity of the native runtime (through its C ABI, as a host calls it) with the torch reference
of the same bundle, for both models, static and dynamic, global and localised parameters.

Bounds (max over all head vertices of all test frames; the untrained networks correct S_t by
up to ~1 mm, so storage errors are relative to that):
  float hyper-tensors: 1e-4 mm  (float32 networks and output against the float64 reference)
  half  hyper-tensors: 1e-3 mm  (binary16 storage of L)
  int8  hyper-tensors: 0.02 mm  (int8 with a scale per 8 elements and latent)
With the physics at prepare (localised SoftDECA cases) a frame also carries the model at rest
under two more parameter sets, each stored the same way: three times the bound.
Measured values are printed (pytest -s) and recorded in docs/runtime.md.

Kept whole: every case shares the fixtures (the bundle, the reference runtime, the take)
built once per module."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from bounds import above, below
from gated_bundle import edited_copy, gated_bundle, reference_and_native
from softdeca_train.host.native import (
    AvatarArrays,
    NativeAvatar,
    NativeError,
    NativeFit,
    NativeModel,
)
from softdeca_train.models import (
    TEST_SIZES,
    BundleInfo,
    ReferenceAvatar,
    TorchNetworks,
    as_stored,
    build_random,
    export_bundle,
    load_parameter_specs,
    read_manifest,
)
from softdeca_train.models.synthetic import (
    TEST_PARAMETERS,
    synthetic_head,
    synthetic_rest_head,
)
from softdeca_train.models.template_head import template_head_of

BOUND_MM = {"float": 1e-4, "half": 1e-3, "int8": 0.02}
# What each model stores at SOFTDECA_PRECISION_DEFAULT (docs/runtime.md): its default output is
# held to that storage's bound.
DEFAULT_STORAGE = {"softdeca": "int8", "sparse": "half"}
REASON = {
    "float": "float32 networks (ONNX Runtime, any kernels) against the float64 reference",
    "half": "binary16 storage of L: 2^-11 of ~1 mm terms",
    "int8": "int8 with a scale per 8 elements and latent: 1/254 of ~1 mm terms",
}
# The rest physics: the runtime and the reference run the same simulator on the same carried
# mesh to the same tolerance (1e-5 of the head's size) from the same start; what differs is
# the float32 storage of the parameters and the three networks' rest outputs.
REASON_REST = (
    "one solver, same tolerance and start; float-stored parameters and networks"
)
REASON_SAME = "the reference adds the same arrays it was given: float64 rounding"


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    head = synthetic_head()
    specs = load_parameter_specs(TEST_PARAMETERS)
    # with SoftDECA's vertex and residual stages (format version 3); the template-topology
    # test below and the contract tests run bundles without them
    nets = build_random(
        head.definition,
        specs,
        TEST_SIZES,
        seed=7,
        vertex_stage=True,
        residual_stage=True,
    )
    folder = tmp_path_factory.mktemp("parity") / "bundle"
    # with the physics at prepare (format version 4): it acts on the localised cases; the skin
    # strain is rest-inert there (it moves nothing of the unloaded head at rest)
    rest = replace(synthetic_rest_head(head), inert=("w_skin_strain",))
    export_bundle(
        folder, head.definition, nets, BundleInfo(True, "parity"), rest_head=rest
    )
    return head, nets, NativeModel(folder), folder, rest


def frames(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    w = np.zeros((n, 52))
    for row in w:
        idx = rng.choice(52, 30, replace=False)
        row[idx] = rng.uniform(0, 1, 30)
    return w


def storage(model: str, precision: str) -> str:
    """The storage `precision` (a PRECISIONS name) gives `model`'s tables."""
    return DEFAULT_STORAGE[model] if precision == "default" else precision


def pair(setup, precision: str, localise: bool = False):
    """The reference and the native avatar, both models' tables at `precision`."""
    head = setup[0]
    ref, nat = reference_and_native(setup, precision)
    assert np.allclose(nat.identity(), ref.identity, atol=1e-6)
    if localise:  # a per-face map, a per-vertex map and a global change
        nf, nv = head.definition.n_faces, head.definition.skin_vertices
        faces = np.where(np.arange(nf) % 3 == 0, 60.0, 0.5)
        verts = np.linspace(0.6, 1.4, nv)
        ref.params.set_faces("w_skin_strain", faces)
        nat.set_parameter_faces("w_skin_strain", faces)
        ref.params.set_vertices("target_volume", verts)
        nat.set_parameter_vertices("target_volume", verts)
        ref.params.set_global("gravity_strength", 1.7)
        nat.set_parameter("gravity_strength", 1.7)
        ref.params.set_vertices("dyn_beta", np.linspace(0.0, 0.9, nv))
        nat.set_parameter_vertices("dyn_beta", np.linspace(0.0, 0.9, nv))
    ref.prepare()
    nat.prepare()
    return ref, nat


def err_mm(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(np.asarray(a, float) - b).max() * 1e3)


@pytest.mark.parametrize("precision", ["default", "float", "half", "int8"])
@pytest.mark.parametrize("localise", [False, True])
def test_softdeca_static_and_dynamic(setup, precision, localise):
    ref, nat = pair(setup, precision, localise)
    worst = {"static": 0.0, "dynamic": 0.0, "surface": 0.0, "normals": 0.0}
    correction = 0.0
    for w in frames(6, 1):
        x, n = nat.evaluate_weights(w)
        xr, nr = ref.evaluate_weights(w)
        worst["static"] = max(worst["static"], err_mm(x, xr))
        worst["normals"] = max(worst["normals"], float(np.abs(n - nr).max()))
        correction = max(correction, err_mm(xr, ref.blend(w)))
        # Caller-supplied S_t: skin only (non-skin follows the jaw rule) and the whole head.
        s = ref.blend(w)
        for surface in (s, s[: ref.d.skin_vertices]):
            x, _ = nat.evaluate_surface(w, surface)
            xr, _ = ref.evaluate_surface(w, surface)
            worst["surface"] = max(worst["surface"], err_mm(x, xr))
    nat.set_dynamics(True)
    ref.dynamics = True
    for w in frames(12, 2):
        x, _ = nat.evaluate_weights(w)
        xr, _ = ref.evaluate_weights(w)
        worst["dynamic"] = max(worst["dynamic"], err_mm(x, xr))
    print(
        f"\nSoftDECA {precision} localised={localise}: {worst} mm; correction up to {correction:.3f} mm"
    )
    # the untrained model must correct S_t visibly for the test to mean anything
    above(
        correction,
        0.05,
        "random networks correct S_t by up to ~1 mm",
        what="correction mm",
    )
    stored = storage("softdeca", precision)
    bound = BOUND_MM[stored] * (3 if localise else 1)
    for key in ("static", "dynamic", "surface"):
        below(worst[key], bound, REASON[stored], what=f"{key} mm")
    below(
        worst["normals"],
        1e-3 * (10 if stored == "int8" else 1),
        "unit normals of surfaces within the storage error of each other",
        what="normals",
    )


@pytest.mark.parametrize("precision", ["default", "float", "half", "int8"])
@pytest.mark.parametrize("localise", [False, True])
def test_sparse_static_dynamic_and_retargeted(setup, precision, localise):
    head = setup[0]
    ref, nat = pair(setup, precision, localise)
    worst = {"uncalibrated": 0.0, "calibrated": 0.0, "dynamic": 0.0}
    for w in frames(5, 3):  # uncalibrated: the points are the avatar's own landmarks
        pts = head.definition.landmarks.evaluate(
            ref.blend(w)[: head.definition.skin_vertices],
            head.definition.skin_triangles,
        )
        x, _ = nat.evaluate_landmarks(pts)
        xr, _ = ref.evaluate_landmarks(pts)
        worst["uncalibrated"] = max(worst["uncalibrated"], err_mm(x, xr))
    nat.calibrate_landmarks(head.user_neutral)
    ref.calibrate(head.user_neutral)
    for w in frames(5, 4):
        face = head.user_face(
            w
        )  # the whole "ARKit" mesh: the runtime picks the landmark vertices
        x, _ = nat.evaluate_landmarks(face)
        xr, _ = ref.evaluate_landmarks(face)
        worst["calibrated"] = max(worst["calibrated"], err_mm(x, xr))
    nat.set_dynamics(True)
    ref.dynamics = True
    for w in frames(10, 5):
        face = head.user_face(w)
        x, _ = nat.evaluate_landmarks(face)
        xr, _ = ref.evaluate_landmarks(face)
        worst["dynamic"] = max(worst["dynamic"], err_mm(x, xr))
    print(f"\nSparse {precision} localised={localise}: {worst} mm")
    stored = storage("sparse", precision)
    for key, v in worst.items():
        below(v, BOUND_MM[stored], REASON[stored], what=f"{key} mm")


def test_the_vertex_stage_counts(setup):
    """The runtime adds SoftDECA's vertex stage: without it the reference lands far from the
    native output, and a localised parameter moves the result through the stage's own table."""
    head, nets, _, _, _ = setup
    assert nets.softdeca is not None and nets.softdeca.f_ph_v is not None
    ref, nat = pair(setup, "float")
    without = ReferenceAvatar(
        TorchNetworks(as_stored(replace_stage(nets, None))),
        head.definition,
        head.neutral,
        head.head_triangles,
        head.blendshapes,
    )
    without.prepare()
    w = frames(1, 9)[0]
    x, _ = nat.evaluate_weights(w)
    the_stage_counts(x, w, ref, without)
    # one vertex's own parameter: the stage's affine table moves that vertex
    nv = head.definition.skin_vertices
    values = np.full(nv, 1.0)
    values[nv // 2] = 1.4
    x2 = both_with_volume(ref, nat, values, w)
    above(
        err_mm(x2[nv // 2], x[nv // 2]), 1e-3, "the vertex's own table entry", what="mm"
    )


def the_stage_counts(x, w, ref, without) -> None:
    """The native output x for weights w is the reference's, and far from the reference
    without the stage."""
    below(
        err_mm(x, ref.evaluate_weights(w)[0]),
        BOUND_MM["float"],
        REASON["float"],
        what="mm",
    )
    above(
        err_mm(x, without.evaluate_weights(w)[0]),
        0.1,
        "the stage moves ~1 mm",
        what="mm",
    )


def both_with_volume(ref, nat, values: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Both avatars prepared with the per-vertex target_volume `values`; the native result
    for weights w, checked against the reference's."""
    nat.set_parameter_vertices("target_volume", values)
    ref.params.set_vertices("target_volume", values)
    nat.prepare()
    ref.prepare()
    x, _ = nat.evaluate_weights(w)
    below(
        err_mm(x, ref.evaluate_weights(w)[0]),
        BOUND_MM["float"],
        REASON["float"],
        what="mm",
    )
    return x


def replace_stage(nets, stage, name: str = "f_ph_v"):
    import copy

    out = copy.deepcopy(nets)
    setattr(out.softdeca, name, stage)
    return out


def test_the_residual_stage_counts(setup):
    """The runtime adds SoftDECA's residual stage: without it the reference lands far from the
    native output, its coefficients follow the weights, and a change of one region's parameter
    reaches the result through the region means (the stage's condition)."""
    head, nets, _, _, _ = setup
    assert nets.softdeca is not None and nets.softdeca.f_r is not None
    ref, nat = pair(setup, "float")
    without = ReferenceAvatar(
        TorchNetworks(as_stored(replace_stage(nets, None, "f_r"))),
        head.definition,
        head.neutral,
        head.head_triangles,
        head.blendshapes,
    )
    without.prepare()
    w0, w1 = frames(2, 11)
    x0, _ = nat.evaluate_weights(w0)
    x1, _ = nat.evaluate_weights(w1)
    the_stage_counts(x0, w0, ref, without)
    stage_only = [x - without.evaluate_weights(w)[0] for x, w in ((x0, w0), (x1, w1))]
    # not a constant offset
    above(
        err_mm(stage_only[0], stage_only[1]), 0.01, "coefficients follow w", what="mm"
    )
    # one region (region 0 of the definition) softer: the condition changes, so does the result
    regions = head.definition.skin_regions
    values = np.where(regions == 0, 1.4, 1.0)
    x2 = both_with_volume(ref, nat, values, w0)
    above(err_mm(x2, x0), 1e-3, "the region means condition the stage", what="mm")


def test_linear_blendshapes_are_exact(setup):
    ref, nat = pair(setup, "half")
    for w in frames(4, 6):
        x, n = nat.evaluate_linear(w)
        xr, nr = ref.evaluate_linear(w)
        below(
            err_mm(x, xr), 1e-4, "a float32 sum of 52 deltas against float64", what="mm"
        )
        below(
            np.abs(n - nr).max(),
            1e-4,
            "normals of the same float32 surface",
            what="normals",
        )


def test_native_errors_reach_python(setup):
    head, _, model, _, _ = setup
    nat = NativeAvatar(model, head.neutral, head.head_triangles, head.blendshapes)
    with pytest.raises(NativeError, match="prepare"):
        nat.evaluate_weights(np.zeros(52))
    nat.prepare()
    with pytest.raises(NativeError, match="not finite"):
        nat.evaluate_weights(np.full(52, np.nan))


def test_parity_on_the_template_topology(tmp_path, template):
    """The real S (28,068 triangles, sockets and all) with small networks."""
    from softdeca_train.models.topology import from_template

    d = from_template(template)
    specs = load_parameter_specs(TEST_PARAMETERS)
    nets = build_random(d, specs, TEST_SIZES, seed=3)
    export_bundle(tmp_path / "b", d, nets, BundleInfo(True, "template parity"))
    model = NativeModel(tmp_path / "b")
    h = template.sample_identity(2)
    neutral = template.identity_neutral(h)
    deltas = (
        template.arkit_to_ict.T @ template.expression_deltas.reshape(53, -1)
    ).reshape(52, -1, 3)
    ref = ReferenceAvatar(
        TorchNetworks(as_stored(nets)), d, neutral, template.triangles, deltas
    )
    nat = NativeAvatar(
        model,
        neutral,
        template.triangles,
        deltas,
        precision="half",
        sparse_precision="half",
    )
    ref.prepare()
    nat.prepare()
    nat.set_dynamics(True)
    ref.dynamics = True
    worst = 0.0
    for w in frames(4, 8):
        x, _ = nat.evaluate_weights(w)
        xr, _ = ref.evaluate_weights(w)
        worst = max(worst, err_mm(x, xr))
    pts = d.landmarks.evaluate(neutral[: d.skin_vertices], d.skin_triangles) + 0.002
    xs, _ = nat.evaluate_landmarks(pts)
    xsr, _ = ref.evaluate_landmarks(pts)
    print(
        f"\ntemplate topology: SoftDECA dynamic {worst:.5f} mm, sparse {err_mm(xs, xsr):.5f} mm"
    )
    assert worst < BOUND_MM["half"]
    assert err_mm(xs, xsr) < BOUND_MM["half"]


def test_rest_physics_parity_on_the_template_topology(tmp_path, template):
    """The physics at prepare on the real head: the tissue fill carried to an ICT identity, its
    lip and lid sets and each tet's skin vertex found on it, natively as in the reference."""
    from softdeca_train.models.rest_head import rest_head_from_template
    from softdeca_train.models.topology import from_template
    from softdeca_train.template.regions import REGIONS, region_labels

    d = from_template(template)
    nets = build_random(d, load_parameter_specs(TEST_PARAMETERS), TEST_SIZES, seed=3)
    rest = rest_head_from_template(template)
    export_bundle(
        tmp_path / "b", d, nets, BundleInfo(True, "rest physics"), rest_head=rest
    )
    neutral = template.identity_neutral(template.sample_identity(2))
    ref = ReferenceAvatar(
        TorchNetworks(as_stored(nets), rest_head=rest), d, neutral, template.triangles
    )
    nat = NativeAvatar(
        NativeModel(tmp_path / "b"), neutral, template.triangles, precision="float"
    )
    lips = np.where(region_labels(template) == REGIONS.index("lips"), 1.3, 1.0)
    for set_vertices in (ref.params.set_vertices, nat.set_parameter_vertices):
        set_vertices("target_volume", lips)
    for set_global in (ref.params.set_global, nat.set_parameter):
        set_global("gravity_strength", 1.8)
    ref.prepare()
    nat.prepare()
    assert ref.prep is not None and ref.prep.rest_offset is not None
    moved = float(np.abs(ref.prep.rest_offset).max() * 1e3)
    skin = neutral[: d.skin_vertices]
    x, _ = nat.evaluate_surface(np.zeros(52), skin)
    worst = err_mm(x[: d.skin_vertices], ref.softdeca_static(np.zeros(52), skin))
    print(
        f"\ntemplate rest physics: offset up to {moved:.3f} mm, native - reference {worst:.6f} mm"
    )
    # a fuller lip region and heavier gravity move the head at rest
    above(moved, 0.05, "1.8 g and fuller lips: tenths of a millimetre", what="mm")
    below(worst, 3 * BOUND_MM["float"], REASON_REST, what="mm")


def test_the_residual_stage_needs_version_three(setup, tmp_path):
    """A residual stage under an older version's manifest is refused, not dropped (a runtime
    reading only that version would run the model without it)."""
    import json
    import shutil

    folder = setup[3]
    copy = tmp_path / "bundle"
    shutil.copytree(folder, copy)
    manifest = json.loads((copy / "manifest.json").read_text())
    assert manifest["format_version"] == 4 and "residual_stage" in manifest
    manifest["format_version"] = 2
    (copy / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(NativeError, match="format version 3"):
        NativeModel(copy)


def closed_form(nets):
    """A copy of `nets` at SoftDECA's closed-form start: f_ph zero, so every G_f is I."""
    import copy

    zero = copy.deepcopy(nets)
    last = zero.softdeca.f_ph.body.rest[-1][-1]
    last.weight.data.zero_()
    last.bias.data.zero_()
    return zero


def test_a_zero_deformation_stage_skips_the_solve_and_keeps_parity(setup, tmp_path):
    """A bundle whose f_ph is zero (SoftDECA at its closed-form start): every G_f is I, so the
    runtime leaves DT out (S_t itself) and the stages after it still match the reference."""
    head, nets, _, _, _ = setup
    zero = closed_form(nets)
    export_bundle(tmp_path / "b", head.definition, zero, BundleInfo(True, "zero f_ph"))
    ref, nat = pair((head, zero, NativeModel(tmp_path / "b"), None, None), "float")
    for w in frames(3, 13):
        x, _ = nat.evaluate_weights(w)
        assert err_mm(x, ref.evaluate_weights(w)[0]) < BOUND_MM["float"]
        assert (
            err_mm(x, ref.blend(w)) > 0.05
        )  # the vertex and residual stages still act
    assert nat.stats().solve_ms == 0.0


def fitted_to_itself(tmp_path, head, nets, info: BundleInfo, **export):
    """`nets` exported with the template head into tmp_path / "b", and the head itself in
    centimetres as a user's mesh (its random shapes tell no unit) fitted to it: the bundle's
    model, the fit and the mesh."""
    skin = head.definition.skin_vertices
    template = template_head_of(head.neutral, head.blendshapes, skin)
    export_bundle(
        tmp_path / "b", head.definition, nets, info, template_head=template, **export
    )
    model = NativeModel(tmp_path / "b")
    mesh = AvatarArrays(100 * head.neutral, head.head_triangles, 100 * head.blendshapes)
    return model, NativeFit.create(model, mesh, metres_per_unit=0.01), mesh


def test_a_non_finite_frame_at_the_closed_form_start_leaves_the_last_output(
    setup, tmp_path
):
    """At SoftDECA's closed-form start the template's frame is written straight into the
    caller's output, and a fitted avatar's is contracted from the stages carried onto it at
    prepare: a model whose output is NaN (f_w's here) is still refused with the last good
    output left as it was, on both; so is SparseSoftDECA's when f_l's output is NaN. At the
    default and int8 storage too, whose kernels quantise the networks' coefficients."""
    head, nets, _, _, _ = setup
    broken = closed_form(nets)
    broken.softdeca.f_w.net[-1].bias.data.fill_(float("nan"))
    broken.sparse.f_l.net[-1].bias.data.fill_(float("nan"))
    info = BundleInfo(True, "f_w and f_l give NaN")
    model, fit, mesh = fitted_to_itself(tmp_path, head, broken, info, check=False)
    w = frames(1, 2)[0]
    for avatar in (
        NativeAvatar(model, head.neutral, head.head_triangles, head.blendshapes),
        NativeAvatar.fitted(model, fit, mesh),
    ):
        avatar.prepare()
        good_v, good_n = avatar.evaluate_linear(w)
        with pytest.raises(NativeError, match="non-finite"):
            avatar.evaluate_weights(w)
        assert np.array_equal(avatar.vertices, good_v)
        assert np.array_equal(avatar.normals, good_n)
    d = head.definition
    points = d.landmarks.evaluate(head.neutral[: d.skin_vertices], d.skin_triangles)
    for precision in ("default", "int8"):
        avatar = NativeAvatar(
            model,
            head.neutral,
            head.head_triangles,
            head.blendshapes,
            sparse_precision=precision,
        )
        avatar.prepare()
        good_v, _ = avatar.evaluate_linear(w)
        with pytest.raises(NativeError, match="non-finite"):
            avatar.evaluate_landmarks(points + 0.001)
        assert np.array_equal(avatar.vertices, good_v)


def test_the_rest_physics_needs_version_four(setup, tmp_path):
    import json
    import shutil

    copy = tmp_path / "bundle"
    shutil.copytree(setup[3], copy)
    manifest = json.loads((copy / "manifest.json").read_text())
    manifest["format_version"] = 3
    (copy / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(NativeError, match="format version 4"):
        NativeModel(copy)


def physics_change(solver, ref: ReferenceAvatar, ref0: ReferenceAvatar) -> np.ndarray:
    """P_rest(p) - P_rest(p0) of the parameters of `ref` against those of `ref0` (at the
    defaults), checked to move the head (gravity 1.7 g and the volumes)."""
    physics = solver.solve(ref.params) - solver.solve(ref0.params)
    above(
        np.abs(physics).max(),
        1e-4,
        "1.7 g and volumes 0.6-1.4: tenths of a mm",
        what="m",
    )
    return physics


def test_at_rest_the_response_is_the_physics(setup):
    """With the physics at prepare, what a parameter change does to the avatar at rest (zero
    weights) is what it does to the avatar's head under the physics, in the reference and the
    native runtime alike; at the defaults nothing is added; a rest-inert parameter (the skin
    strain here) keeps the networks' own response."""
    from softdeca_train.models.rest_physics import RestSolver

    head, _, _, _, rest = setup
    vs = head.definition.skin_vertices
    zero = np.zeros(52)
    ref0, nat0 = pair(setup, "float")
    assert ref0.prep is not None and ref0.prep.rest_offset is None
    assert nat0.stats().prepare_physics_ms == 0.0
    ref, nat = pair(setup, "float")
    for a in (ref.params.set_global, nat.set_parameter):
        a("gravity_strength", 1.7)
    for a in (ref.params.set_vertices, nat.set_parameter_vertices):
        a("target_volume", np.linspace(0.6, 1.4, vs))
    ref.prepare()
    nat.prepare()
    assert nat.stats().physics_iterations > 0 and nat.stats().prepare_physics_ms > 0
    solver = RestSolver(rest, head.neutral, head.definition.skin_triangles)
    physics = physics_change(solver, ref, ref0)
    moved_ref = ref.evaluate_weights(zero)[0] - ref0.evaluate_weights(zero)[0]
    moved_nat = nat.evaluate_weights(zero)[0] - nat0.evaluate_weights(zero)[0]
    below(err_mm(moved_ref[:vs], physics), 1e-6, REASON_SAME, what="mm")
    below(err_mm(moved_nat[:vs], physics), BOUND_MM["float"], REASON_REST, what="mm")
    # The skin strain moves nothing of the unloaded head: the networks' response to it alone
    # stays, M_rest(the skin strain alone) - M_rest(p0), on top of the physics' (which also
    # answers how the skin strain changes the sag under the heavier gravity).
    plain = ReferenceAvatar(
        ref.nets, head.definition, head.neutral, head.head_triangles, head.blendshapes,
        rest_physics=False,
    )  # fmt: skip
    plain.params.set_global("w_skin_strain", 30.0)
    plain.prepare()
    networks = (
        plain.evaluate_weights(zero)[0][:vs] - ref0.evaluate_weights(zero)[0][:vs]
    )
    for a in (ref.params.set_global, nat.set_parameter):
        a("w_skin_strain", 30.0)
    ref.prepare()
    nat.prepare()
    physics = solver.solve(ref.params) - solver.solve(ref0.params)
    moved_ref = ref.evaluate_weights(zero)[0] - ref0.evaluate_weights(zero)[0]
    below(err_mm(moved_ref[:vs], physics + networks), 1e-6, REASON_SAME, what="mm")
    below(
        err_mm(nat.evaluate_weights(zero)[0], ref.evaluate_weights(zero)[0]),
        BOUND_MM["float"],
        REASON_REST,
        what="mm",
    )


@pytest.fixture(scope="module")
def gated(tmp_path_factory):
    """A bundle trained exact at rest, as setup's (tests/python/gated_bundle.py)."""
    return gated_bundle(tmp_path_factory.mktemp("gated") / "bundle")


def test_a_bundle_exact_at_rest_runs_as_its_reference(gated):
    """A bundle trained exact at rest (a rest gate: every network of w gives g(w) - g(0), the
    residual stage's c(0) at the end of its condition, made at prepare): the native runtime
    matches its reference, and at rest its frame is the linear blend (no rest physics at the
    defaults), while a moving face is corrected."""
    ref, nat = pair(gated, "float")
    assert read_manifest(gated[3])["rest_gate"] == 0.1
    zero = np.zeros(52)
    below(
        err_mm(nat.evaluate_weights(zero)[0], nat.evaluate_linear(zero)[0]),
        1e-5,
        "float32 rounding of g(0) - g(0): exact at rest",
        what="mm",
    )
    for w in frames(4, 5):
        x = nat.evaluate_weights(w)[0]
        below(err_mm(x, ref.evaluate_weights(w)[0]), BOUND_MM["float"], REASON["float"])
        above(err_mm(x, nat.evaluate_linear(w)[0]), 0.05, "a moving face is corrected")


def gate_open_rest(avatar: ReferenceAvatar) -> np.ndarray:
    """M1: the networks' static frame at zero weights on the neutral with the rest gate open
    (z's last entry and the residual stage's mean mode at 1)."""
    assert avatar.prep is not None
    vs = avatar.d.skin_vertices
    return avatar._softdeca_static(
        avatar.prep, np.zeros(52), avatar.neutral[:vs], gate=1.0
    )


@pytest.mark.parametrize("precision", ["float", "half"])
def test_a_gated_bundle_counts_p_at_rest_once(gated, precision):
    """With a rest gate the networks add nothing at rest, so off the defaults the frame at
    rest is the linear blend plus the physics' change Pd = P_rest(p) - P_rest(p0); on an
    expression the gate opens the networks' own response to p at rest, which is taken off
    as it opens: frame(w, p) = networks(w, p) + Pd - g(w) [M1(p) - M1(p_inert)]. Without that
    term p's effect at rest is counted twice. The native runtime (the term folded into its
    stage table at prepare) matches the reference (which takes it off per frame)."""
    from softdeca_train.models.rest_physics import RestSolver

    head, _, _, _, rest = gated
    vs = head.definition.skin_vertices
    zero = np.zeros(52)
    ref0, nat0 = pair(gated, precision)
    # localised: the skin strain too, so p_inert is not p0
    ref, nat = pair(gated, precision, localise=True)
    d = head.definition
    plain = [
        ReferenceAvatar(
            ref.nets,
            d,
            head.neutral,
            head.head_triangles,
            head.blendshapes,
            rest_physics=False,
        )
        for _ in range(2)
    ]
    plain[0].params = ref.params
    plain[1].params = ref.params.with_defaults(
        [s.name for s in ref.nets.specs if s.name not in rest.inert]
    )
    for a in plain:
        a.prepare()
    solver = RestSolver(rest, head.neutral, head.definition.skin_triangles)
    physics = physics_change(solver, ref, ref0)
    # at rest: the linear blend and the physics' change
    below(
        err_mm(ref.evaluate_weights(zero)[0][:vs] - head.neutral[:vs], physics),
        1e-6,
        REASON_SAME,
        what="mm",
    )
    # on an expression: the networks' change from p0 to p, the physics' change, and the
    # networks' response at rest (gate open) taken off, as far as the gate is open
    model = gate_open_rest(plain[0]) - gate_open_rest(plain[1])
    strong = np.full(52, 0.6)  # |w|^2 = 18.7 against tau^2 = 0.01: the gate at 0.9995
    gate = float(ref.nets.f_w(strong.astype(np.float32)[None])[0, -1])
    above(gate, 0.5, "a strong expression opens the gate (0.9995)", what="gate")
    above(
        np.abs(gate * model).max(), 1e-5, "the networks respond to p at rest", what="m"
    )
    want = (
        plain[0].evaluate_weights(strong)[0][:vs]
        - ref0.evaluate_weights(strong)[0][:vs]
        + physics
        - gate * model
    )
    got = ref.evaluate_weights(strong)[0][:vs] - ref0.evaluate_weights(strong)[0][:vs]
    below(err_mm(got, want), 1e-6, REASON_SAME, what="mm")
    # the native runtime as its reference, at rest, on the strong expression and on others
    bound = 3 * BOUND_MM[precision]
    for w in [zero, strong, *frames(3, 21)]:
        x = nat.evaluate_weights(w)[0]
        below(err_mm(x, ref.evaluate_weights(w)[0]), bound, REASON_REST, what="mm")
    moved = nat.evaluate_weights(zero)[0][:vs] - nat0.evaluate_weights(zero)[0][:vs]
    below(err_mm(moved, physics), bound, REASON_REST, what="mm")


def test_a_fitted_avatar_takes_the_gated_rest_physics_off_as_the_template_does(
    gated, tmp_path
):
    """A fitted avatar at SoftDECA's closed-form start contracts the stage table carried onto
    it at prepare; that table holds the rest gate's share of the physics at prepare as the
    template's does: its frame is the template's whole frame carried (what a first frame with
    dynamics, which starts at rest, gives)."""
    head, nets, _, _, rest = gated
    info = BundleInfo(True, "gated closed form")
    model, fit, mesh = fitted_to_itself(
        tmp_path, head, closed_form(nets), info, rest_head=rest
    )
    # float storage: the carried table and the template's round differently in half
    avatar = NativeAvatar.fitted(model, fit, mesh, precision="float")
    avatar.set_parameter("gravity_strength", 1.7)
    avatar.set_parameter("target_volume", 1.3)
    avatar.prepare()
    w = np.full(52, 0.6)
    carried = avatar.evaluate_weights(w)[0] / 100
    avatar.set_dynamics(True)
    whole = avatar.evaluate_weights(w)[0] / 100
    linear = avatar.evaluate_linear(w)[0] / 100
    above(
        err_mm(whole, linear),
        0.05,
        "the model and the physics move the face",
        what="mm",
    )
    below(err_mm(carried, whole), 1e-4, "float32 sums in another order, cm", what="mm")


def test_the_rest_gate_needs_the_vertex_stage_at_export(tmp_path):
    head = synthetic_head()
    nets = build_random(
        head.definition,
        load_parameter_specs(TEST_PARAMETERS),
        replace(TEST_SIZES, rest_gate=0.1),
        constant_slot=True,
    )
    with pytest.raises(ValueError, match="vertex stage"):
        export_bundle(
            tmp_path / "b", head.definition, nets, BundleInfo(True, "no stage")
        )


def _no_vertex_stage(m: dict) -> None:
    del m["networks"]["softdeca.f_ph_v"]


@pytest.mark.parametrize(
    "edit, message",
    [
        (
            {"format_version": 5},
            r"rest_gate \(SoftDECA's rest gate\) needs bundle format version 6",
        ),
        ({"rest_gate": 0}, "rest_gate .* must be positive"),
        ({"rest_gate": -0.1}, "rest_gate .* must be positive"),
        ({"rest_gate": "0.1"}, "rest_gate must be a number, not a string"),
        ({"rest_gate": None}, "rest_gate must be a number, not null"),
        ({"rest_gate": 1e999}, "JSON: unexpected character"),  # Infinity
        (_no_vertex_stage, "rest_gate .* needs SoftDECA's vertex stage"),
    ],
)
def test_the_rest_gate_is_checked_at_load(gated, tmp_path, edit, message):
    """SoftDECA's rest gate is refused, by name, where it is not a positive number, where the
    format version does not hold it and where the bundle has no vertex stage to weigh."""
    copy = edited_copy(gated[3], tmp_path / "bundle", edit)
    with pytest.raises(NativeError, match=message):
        NativeModel(copy)
