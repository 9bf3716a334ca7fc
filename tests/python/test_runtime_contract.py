"""The model bundle contract on the Python side: the manifest, the exported ONNX files, the
deformation transfer (exactness, symmetry, gradients) and the parameter localisation rules."""

from __future__ import annotations

import json
import tarfile

import numpy as np
import pytest
import torch
from softdeca_train.models import (
    FORMAT_VERSION,
    TEST_SIZES,
    BundleInfo,
    OnnxNetworks,
    ParameterState,
    build_random,
    deformation_transfer,
    dt_system,
    export_bundle,
    load_parameter_specs,
    pack_bundle,
    read_definition,
    read_manifest,
)
from softdeca_train.models.dt import residual_rhs
from softdeca_train.models.synthetic import TEST_PARAMETERS, synthetic_head


@pytest.fixture(scope="module")
def head():
    return synthetic_head()


@pytest.fixture(scope="module")
def bundle(tmp_path_factory, head):
    specs = load_parameter_specs(TEST_PARAMETERS)
    nets = build_random(head.definition, specs, TEST_SIZES, seed=4)
    folder = export_bundle(
        tmp_path_factory.mktemp("bundle") / "b",
        head.definition,
        nets,
        BundleInfo(True, "test"),
    )
    return folder, nets


def test_manifest_states_the_contract(bundle, head):
    folder, _ = bundle
    m = read_manifest(folder)
    d = head.definition
    # no vertex stage: version 1, which runtimes reading only version 1 still run
    assert m["format_version"] == 1 and m["untrained"] is True
    assert m["template"] == {
        "name": d.name,
        "head_vertices": d.head_vertices,
        "skin_vertices": d.skin_vertices,
        "skin_triangles": d.n_faces,
    }
    assert len(m["blendshapes"]) == 52 and m["blendshapes"][24] == "jawOpen"
    f_ph = m["networks"]["softdeca.f_ph"]
    assert f_ph["outputs"] == [
        {"name": "L", "dtype": "float32", "shape": [d.n_faces, 32, 9]}
    ]
    assert f_ph["parameter_columns"] == [p["name"] for p in TEST_PARAMETERS]
    assert m["networks"]["sparse.f_l"]["inputs"][0]["shape"] == [
        "batch",
        3 * len(d.landmarks),
    ]
    assert m["deformation_transfer"]["formulation"] == "cotangent-poisson-1"
    assert m["training"] is None and m["errors"] is None
    # Every ONNX file reproduces its torch module.
    assert max(m["export_check_max_abs"].values()) < 1e-4
    # The topology round-trips.
    back = read_definition(folder)
    assert np.array_equal(back.skin_triangles, d.skin_triangles)
    assert np.array_equal(back.non_skin_bones, d.non_skin_bones)
    assert np.allclose(back.landmarks.bary, d.landmarks.bary)
    # Global parameters are marked as such.
    gravity = next(p for p in m["parameters"] if p["name"] == "gravity_strength")
    assert gravity["localisable"] is False


def test_manifest_of_another_version_is_refused(bundle, tmp_path):
    folder, _ = bundle
    m = json.loads((folder / "manifest.json").read_text())
    m["format_version"] = FORMAT_VERSION + 1
    (tmp_path / "manifest.json").write_text(json.dumps(m))
    with pytest.raises(ValueError, match="version"):
        read_manifest(tmp_path)


def test_the_manifest_is_read_from_a_packed_bundle_too(bundle, tmp_path):
    folder, _ = bundle
    packed = tmp_path / "bundle.tar"
    packed.write_bytes(pack_bundle(folder))
    assert read_manifest(packed) == read_manifest(folder)
    other = tmp_path / "other.tar"
    with tarfile.open(other, "w") as tar:
        tar.add(folder / "skin_triangles.i32", arcname="skin_triangles.i32")
    with pytest.raises(ValueError, match="not a bundle"):
        read_manifest(other)


def test_dynamics_networks_stay_in_the_stable_equilibrium_set(bundle, head):
    folder, _ = bundle
    onnx = OnnxNetworks(folder)
    rng = np.random.default_rng(0)
    specs = onnx.specs
    lo = np.array([s.minimum for s in specs])
    hi = np.array([s.maximum for s in specs])
    p = lo + (hi - lo) * rng.uniform(size=(head.definition.skin_vertices, len(specs)))
    for model in ("softdeca", "sparse"):
        a, b, g = onnx.f_dyn(model, p, rng.normal(size=TEST_SIZES.identity) * 3)
        assert np.allclose(g + 2 * a - b, 1.0, atol=1e-6)
        assert (b >= 0).all() and (b < 1).all() and (g > 0).all() and (g < 2).all()


def test_dt_reproduces_the_input_for_identity_gradients_and_matches_a_dense_solve(head):
    skin = head.neutral[: head.definition.skin_vertices]
    tri = head.definition.skin_triangles
    system = dt_system(skin, tri)
    k = system.matrix.toarray()
    assert np.allclose(k, k.T)
    assert np.allclose(
        k.sum(axis=1), system.mu * system.mass
    )  # Laplacian rows sum to zero
    s = torch.from_numpy(skin[None] + 0.001)
    zero = torch.zeros(1, len(tri), 3, 3, dtype=torch.float64)
    assert torch.equal(deformation_transfer(system, s, zero), s)
    rng = np.random.default_rng(1)
    g = torch.from_numpy(rng.normal(size=(1, len(tri), 3, 3)) * 0.05)
    x = deformation_transfer(system, s, g)[0].numpy()
    r = residual_rhs(system, s, g)[0].numpy()
    assert np.allclose(x, s[0].numpy() + np.linalg.solve(k, r), atol=1e-12)


def test_dt_is_the_least_squares_minimiser(head):
    """The gradient of the stated energy vanishes at DT's output."""
    skin = head.neutral[: head.definition.skin_vertices]
    tri = head.definition.skin_triangles.astype(np.int64)
    system = dt_system(skin, tri)
    rng = np.random.default_rng(2)
    s = skin + rng.normal(size=skin.shape) * 0.002
    g = np.eye(3) + rng.normal(size=(len(tri), 3, 3)) * 0.05
    x = deformation_transfer(
        system, torch.from_numpy(s[None]), torch.from_numpy(g[None] - np.eye(3))
    )
    xt = x[0].clone().requires_grad_(True)

    def edges(v: torch.Tensor) -> torch.Tensor:
        return torch.stack(
            [v[tri[:, 1]] - v[tri[:, 0]], v[tri[:, 2]] - v[tri[:, 0]]], dim=-1
        )

    n = torch.from_numpy(skin)
    en = edges(n)
    w = torch.linalg.inv(en.transpose(1, 2) @ en)
    area = torch.from_numpy(system.area)
    target = torch.from_numpy(g) @ edges(torch.from_numpy(s))
    d = edges(xt) - target
    energy = (area * torch.einsum("fij,fjk,fik->f", d, w, d)).sum()
    energy = (
        energy
        + system.mu
        * (
            torch.from_numpy(system.mass)[:, None] * (xt - torch.from_numpy(s)) ** 2
        ).sum()
    )
    (grad,) = torch.autograd.grad(energy, xt)
    assert grad.abs().max() < 1e-9


def test_dt_gradients(head):
    skin = head.neutral[: head.definition.skin_vertices]
    system = dt_system(skin, head.definition.skin_triangles)
    s = torch.from_numpy(skin[None]).requires_grad_(True)
    nf = len(head.definition.skin_triangles)
    g = (torch.randn(1, nf, 3, 3, dtype=torch.float64) * 0.01).requires_grad_(True)
    assert torch.autograd.gradcheck(
        lambda a, b: deformation_transfer(system, a, b), (s, g), eps=1e-6, atol=1e-5
    )


def test_parameter_localisation_rules(head):
    specs = load_parameter_specs(TEST_PARAMETERS)
    tri = head.definition.skin_triangles
    area = dt_system(head.neutral[: head.definition.skin_vertices], tri).area
    state = ParameterState(specs, tri, area)
    assert np.allclose(state.face_matrix()[:, 2], 1.0)  # defaults
    faces = np.full(len(tri), 1.0)
    faces[:10] = 50.0
    state.set_faces("w_skin_strain", faces)
    v = state.vertex_matrix(["w_skin_strain"])[:, 0]
    i = int(tri[0, 0])
    incident = np.nonzero((tri == i).any(axis=1))[0]
    assert np.isclose(
        v[i], (faces[incident] * area[incident]).sum() / area[incident].sum()
    )
    verts = np.linspace(0.5, 1.5, head.definition.skin_vertices)
    state.set_vertices("target_volume", verts)
    assert np.allclose(
        state.face_matrix(["target_volume"])[:, 0], verts[tri].mean(axis=1)
    )
    with pytest.raises(ValueError, match="global"):
        state.set_faces("gravity_strength", np.full(len(tri), 1.5))
    with pytest.raises(ValueError, match="outside"):
        state.set_global("target_volume", 3.0)
    with pytest.raises(ValueError, match="finite"):
        state.set_global("target_volume", float("nan"))
