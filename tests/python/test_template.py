"""The head template built from ICT-FaceKit."""

from __future__ import annotations

import tarfile
from pathlib import Path

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from softdeca_train.paths import default_ict_path
from softdeca_train.template import ARKIT_BLENDSHAPES, Template, load_ict
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.plausibility import (
    HUMAN_RANGES_MM,
    face_measures,
    implausibilities,
    skin_self_intersections,
)


def test_units_frame_and_sizes(template: Template) -> None:
    v = template.neutral
    nose_tip = v[template.landmarks68[30]]
    assert nose_tip[2] == pytest.approx(
        v[:N_SKIN, 2].max(), abs=0.01
    )  # +Z out of the face
    assert v[template.landmarks68[27], 1] > v[template.landmarks68[8], 1]  # +Y up
    width = np.ptp(v[:, 0])
    assert (
        0.2 < width < 0.3
    )  # metres (ICT is about 25 cm wide with the shoulders' start)
    for name, value in face_measures(v, template.landmarks68).items():
        lo, hi = HUMAN_RANGES_MM[name]
        assert lo < value < hi, name


def test_skin_is_one_connected_consistently_oriented_outward_surface(
    template: Template,
) -> None:
    f = template.skin_triangles
    assert f.max() < N_SKIN and len(np.unique(f)) == N_SKIN
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    adj = coo_matrix(
        (np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(N_SKIN, N_SKIN)
    )
    n_comp, _ = connected_components(adj, directed=False)
    assert n_comp == 1
    # Consistent orientation: no directed edge twice; manifold: undirected edges used <= 2x.
    assert len(np.unique(edges, axis=0)) == len(edges)
    _, count = np.unique(np.sort(edges, axis=1), axis=0, return_counts=True)
    assert count.max() == 2
    # Outward: the enclosed volume, with the neck opening closed by a fan, is positive.
    v = template.neutral[:N_SKIN]
    p = v[f]
    vol = np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6
    assert vol > 0.002  # m³: a head, not an inside-out surface


def test_left_suffix_is_derived_from_geometry(template: Template) -> None:
    assert template.left_suffix == "_L"  # ICT's _L moves the subject's left (+x)
    for name in ("eyeBlink_L", "mouthSmile_L", "browOuterUp_L", "noseSneer_L"):
        d = np.linalg.norm(
            template.expression_deltas[template.expression_names.index(name)], axis=1
        )
        x = (template.neutral[:, 0] * d).sum() / d.sum()
        assert x > 0.01, name


def test_arkit_map(template: Template) -> None:
    m = template.arkit_to_ict
    assert m.shape == (53, 52)
    col = {n: m[:, i] for i, n in enumerate(ARKIT_BLENDSHAPES)}
    names = template.expression_names
    assert col["tongueOut"].sum() == 0
    assert col["eyeBlinkLeft"][names.index("eyeBlink_L")] == 1
    assert col["eyeBlinkRight"][names.index("eyeBlink_R")] == 1
    assert col["browInnerUp"][
        [names.index("browInnerUp_L"), names.index("browInnerUp_R")]
    ].tolist() == [1, 1]
    assert col["jawOpen"][names.index("jawOpen")] == 1
    assert (m.sum(axis=1) == 1).all()  # every ICT shape driven exactly once


def test_arkit_left_shapes_move_the_subjects_left(template: Template) -> None:
    w = np.zeros(52)
    w[ARKIT_BLENDSHAPES.index("mouthSmileLeft")] = 1.0
    d = np.linalg.norm(template.blend(w) - template.neutral, axis=1)
    assert (template.neutral[:, 0] * d).sum() / d.sum() > 0.01


def test_blend_is_linear_and_checks_sizes(template: Template) -> None:
    w = np.zeros(52)
    w[ARKIT_BLENDSHAPES.index("jawOpen")] = 0.5
    delta = template.expression_deltas[template.expression_names.index("jawOpen")]
    assert np.allclose(template.blend(w), template.neutral + 0.5 * delta, atol=1e-6)
    assert np.linalg.norm(delta, axis=1).max() == pytest.approx(
        0.042, abs=0.001
    )  # DATA.md: 4.2 cm
    with pytest.raises(ValueError, match="52 ARKit weights"):
        template.blend(np.zeros(51))


def test_identity_sampling_is_seeded_and_truncated(template: Template) -> None:
    a, b = template.sample_identity(7), template.sample_identity(7)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, template.sample_identity(8))
    assert np.abs(a).max() <= 3.0
    assert np.std(
        np.concatenate([template.sample_identity(s) for s in range(50)])
    ) == pytest.approx(1, abs=0.05)


@pytest.mark.parametrize("seed", range(20))
def test_sampled_identity_is_plausible(template: Template, seed: int) -> None:
    head = template.identity_neutral(template.sample_identity(seed))
    assert (
        skin_self_intersections(head, template.skin_triangles, template.landmarks68)
        == []
    )
    for name, value in face_measures(head, template.landmarks68).items():
        lo, hi = HUMAN_RANGES_MM[name]
        assert lo < value < hi, f"{name} = {value:.1f} mm"


def test_raw_draws_can_fold_and_the_check_sees_it(template: Template) -> None:
    # Seed 1's first raw draw folds at the columella: the check must catch such heads.
    rng = np.random.default_rng(1)
    h = np.clip(rng.standard_normal(100), -3, 3)
    head = template.identity_neutral(h)
    assert skin_self_intersections(head, template.skin_triangles, template.landmarks68)
    assert implausibilities(head, template.skin_triangles, template.landmarks68)
    assert not np.array_equal(h, template.sample_identity(1))


def test_exaggerated_identity_fails_the_size_check(template: Template) -> None:
    # The plausibility test can fail: 8 sigma along the first mode leaves the human range.
    h = np.zeros(100)
    h[0] = 8.0
    head = template.identity_neutral(h)
    m = face_measures(head, template.landmarks68)
    assert any(
        not (HUMAN_RANGES_MM[k][0] < v < HUMAN_RANGES_MM[k][1]) for k, v in m.items()
    )


def test_loads_from_an_archive_like_from_a_checkout(
    tmp_path: Path, template: Template, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder = default_ict_path() / "FaceXModel"
    partial = tmp_path / "checkout" / "FaceXModel"
    partial.mkdir(parents=True)
    keep = (
        "generic_neutral_mesh.obj",
        "vertex_indices.json",
        "jawOpen.obj",
        "eyeBlink_L.obj",
    )
    for f in folder.iterdir():
        if f.name in keep or f.name.startswith("identity00"):
            (partial / f.name).symlink_to(f)
    monkeypatch.setenv("SOFTDECA_CACHE", str(tmp_path / "cache"))
    # A partial checkout is refused with a clear message naming what is missing.
    with pytest.raises(FileNotFoundError, match="lacks shapes"):
        load_ict(tmp_path / "checkout")
    with pytest.raises(FileNotFoundError, match="no ICT-FaceKit"):
        load_ict(tmp_path / "nowhere")
    # The folder packed as an archive (as ICT-FaceKit-FaceXModel.tar.xz holds it, uncompressed
    # here for speed) gives the same arrays as the folder the template was loaded from.
    archive = tmp_path / "ICT-FaceKit-FaceXModel.tar"
    with tarfile.open(archive, "w") as tar:
        tar.add(folder, arcname="FaceXModel")
    raw = load_ict(archive)
    assert np.array_equal(raw["neutral"], template.neutral)
    assert np.array_equal(raw["identity_modes"], template.identity_modes)
