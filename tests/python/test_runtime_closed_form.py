"""Frames of a bundle at SoftDECA's closed-form start (f_ph zero: DT at identity), as the
committed bundle runs them: the template's frame is written straight into the caller's output,
and a fitted avatar's is contracted from the stages carried onto its own vertices at prepare.
Neither may leave a half-written output behind: a model whose output is not finite is refused
with the last good output left as it was, on the template and on a fitted avatar."""

from __future__ import annotations

import numpy as np
import pytest
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
    build_random,
    export_bundle,
    load_parameter_specs,
)
from softdeca_train.models.synthetic import TEST_PARAMETERS, synthetic_head
from softdeca_train.models.template_head import template_head_of


@pytest.fixture(scope="module")
def broken(tmp_path_factory):
    """The synthetic head and a closed-form bundle whose f_w gives NaN for every weight."""
    head = synthetic_head()
    specs = load_parameter_specs(TEST_PARAMETERS)
    nets = build_random(
        head.definition,
        specs,
        TEST_SIZES,
        seed=5,
        dg_scale=0.0,
        vertex_stage=True,
        residual_stage=True,
    )
    nets.softdeca.f_w.net[-1].bias.data.fill_(float("nan"))
    folder = tmp_path_factory.mktemp("nan") / "bundle"
    export_bundle(
        folder,
        head.definition,
        nets,
        BundleInfo(True, "f_w gives NaN"),
        check=False,
        template_head=template_head_of(
            head.neutral, head.blendshapes, head.definition.skin_vertices
        ),
    )
    return head, NativeModel(folder)


def weights() -> np.ndarray:
    return np.random.default_rng(2).uniform(0, 1, 52)


def refused_and_kept(avatar: NativeAvatar) -> None:
    avatar.prepare()
    good_v, good_n = avatar.evaluate_linear(weights())
    with pytest.raises(NativeError, match="non-finite"):
        avatar.evaluate_weights(weights())
    assert np.array_equal(avatar.vertices, good_v)
    assert np.array_equal(avatar.normals, good_n)


def test_the_template_keeps_its_last_output(broken) -> None:
    head, model = broken
    refused_and_kept(
        NativeAvatar(model, head.neutral, head.head_triangles, head.blendshapes)
    )


def test_a_fitted_avatar_keeps_its_last_output(broken) -> None:
    head, model = broken
    # the head in centimetres, fitted as a user's mesh (its random shapes tell no unit)
    mesh = AvatarArrays(100 * head.neutral, head.head_triangles, 100 * head.blendshapes)
    fit = NativeFit.create(model, mesh, metres_per_unit=0.01)
    refused_and_kept(NativeAvatar.fitted(model, fit, mesh))
