"""bundle-carry: one model's networks copied as they are between bundles that read the same
inputs, with what was carried and from where in the manifest; refused, with nothing written,
between bundles that differ in what the networks read or from a source that fails its hashes."""

from __future__ import annotations

import json
import shutil

import pytest
from softdeca_train.models import (
    TEST_SIZES,
    BundleInfo,
    build_random,
    export_bundle,
    load_parameter_specs,
    read_manifest,
)
from softdeca_train.models.bundle_carry import carry_model
from softdeca_train.models.synthetic import TEST_PARAMETERS, synthetic_head

SPARSE = ("sparse.f_l", "sparse.f_ph_v", "sparse.f_dyn")


@pytest.fixture()
def bundles(tmp_path):
    """Two random bundles of one head and parameter list that share the identity encoder
    (as two trainings on one template do: it is an exact least-squares fit)."""
    head = synthetic_head()
    specs = load_parameter_specs(TEST_PARAMETERS)
    out = []
    for seed, name in ((4, "dest"), (5, "source")):
        nets = build_random(head.definition, specs, TEST_SIZES, seed=seed)
        out.append(
            export_bundle(
                tmp_path / name, head.definition, nets, BundleInfo(True, name)
            )
        )
    dest, source = out
    m_dest, m_src = read_manifest(dest), read_manifest(source)
    enc = m_dest["networks"]["identity_encoder"]
    shutil.copy(dest / enc["file"], source / enc["file"])
    m_src["networks"]["identity_encoder"] = enc
    m_src["errors"] = {
        "sparse_other_head": {"mean_mm": 0.5},
        "softdeca_static": {"mean_mm": 9},
    }
    (source / "manifest.json").write_text(json.dumps(m_src))
    return dest, source


def _files(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def test_carried_networks_are_the_sources_and_nothing_else_changes(bundles) -> None:
    dest, source = bundles
    before, src = read_manifest(dest), read_manifest(source)
    carried = carry_model(source, dest, "sparse", "carry")
    assert carried == list(SPARSE)
    after = read_manifest(dest)
    for name, spec in after["networks"].items():
        if name in SPARSE:
            assert spec == src["networks"][name], name
            assert (dest / spec["file"]).read_bytes() == (
                source / spec["file"]
            ).read_bytes()
        else:
            assert spec == before["networks"][name], name
    record = after["training"]["replaced"][-1]
    assert record["networks"] == list(SPARSE) and record["carried_from"] == str(source)
    assert record["command"] == "carry" and record["source_description"] == "source"
    # the source's SparseSoftDECA errors come along; SoftDECA's stay the destination's
    assert after["errors"]["sparse_other_head"] == {"mean_mm": 0.5}
    assert after["errors"].get("softdeca_static") == (before.get("errors") or {}).get(
        "softdeca_static"
    )
    assert "sparse.f_l" in after["description"] and after["description"].startswith(
        "dest"
    )
    assert not list(dest.glob("*.partial"))
    # the evaluation report names the carried networks (they are not its run's)
    from softdeca_train.train.report import _carried

    assert _carried(dest) == dict.fromkeys(SPARSE, "unknown")
    assert _carried(source) == {}


def test_bundles_that_read_other_inputs_are_refused_and_left_as_they_were(
    bundles, tmp_path
) -> None:
    dest, source = bundles
    before = _files(dest)
    other = tmp_path / "other"
    shutil.copytree(source, other)
    m = read_manifest(other)
    m["parameters"][0]["default"] = m["parameters"][0]["default"] + 0.5
    (other / "manifest.json").write_text(json.dumps(m))
    with pytest.raises(ValueError, match="parameters"):
        carry_model(other, dest, "sparse", "carry")
    # another identity code: the encoder of the source's own seed
    m = read_manifest(source)
    m["networks"]["identity_encoder"]["sha256"] = "0" * 64
    (other / "manifest.json").write_text(json.dumps(m))
    with pytest.raises(ValueError, match="identity encoder"):
        carry_model(other, dest, "sparse", "carry")
    # a source file that is not what its manifest says
    shutil.rmtree(other)
    shutil.copytree(source, other)
    f = other / read_manifest(other)["networks"]["sparse.f_dyn"]["file"]
    f.write_bytes(f.read_bytes()[:-1] + b"\0")
    with pytest.raises(ValueError, match="sha256"):
        carry_model(other, dest, "sparse", "carry")
    # a source without one of the model's networks: the destination would mix two origins
    m = read_manifest(source)
    del m["networks"]["sparse.f_dyn"]
    (other / "manifest.json").write_text(json.dumps(m))
    with pytest.raises(ValueError, match="lacks"):
        carry_model(other, dest, "sparse", "carry")
    with pytest.raises(ValueError, match="unknown model"):
        carry_model(source, dest, "everything", "carry")
    assert _files(dest) == before


def test_softdeca_brings_its_rest_gate(bundles, tmp_path) -> None:
    """SoftDECA's rest gate says what its f_w's last entry is: carried with its networks (and
    the format version that holds it), taken away by a SoftDECA without one."""
    dest, source = bundles
    plain = tmp_path / "plain"
    shutil.copytree(source, plain)
    m = read_manifest(source)
    m["rest_gate"], m["format_version"] = 0.3, 6
    (source / "manifest.json").write_text(json.dumps(m))
    carry_model(source, dest, "softdeca", "carry")
    after = read_manifest(dest)
    assert after["rest_gate"] == 0.3 and after["format_version"] == 6
    carry_model(plain, dest, "softdeca", "carry")
    assert "rest_gate" not in read_manifest(dest)
    # SparseSoftDECA's networks leave it as it is
    carry_model(source, dest, "softdeca", "carry")
    carry_model(plain, dest, "sparse", "carry")
    assert read_manifest(dest)["rest_gate"] == 0.3


def test_the_bench_figures_are_of_the_shipped_sparse_networks(tmp_path) -> None:
    """models.json names what the bundle ships: the run's own SparseSoftDECA figures, or with
    carried networks the bundle's figure on the same split, never the run's in their place."""
    from types import SimpleNamespace

    from softdeca_train.train.report import _write_bench

    errors = {
        "sparse/other_head_noise": {"mean_mm": 0.7},
        "sparse/arkit_face": {"mean_mm": 0.65},
    }
    result = {
        "errors": errors,
        "ms_per_frame": {},
        "bundle": {"sparse": {"mean_mm": 0.6}},
    }
    run = SimpleNamespace(folder=tmp_path / "run")
    for carried, expected in ((False, {0.7, 0.65}), (True, {0.6})):
        _write_bench(tmp_path, result, run, carried)  # type: ignore[arg-type]
        figs = json.loads((tmp_path / "models.json").read_text())
        assert {
            f["value"] for k, f in figs.items() if k.startswith("sparse")
        } == expected
