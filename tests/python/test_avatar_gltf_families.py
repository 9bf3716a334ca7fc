"""glTF avatars written as Ready Player Me and VRoid (through gltfpack) write them
(sample_avatars/gltf_families.py), through the command line as a user runs it: `softdeca fit` reads
the file and passes its own quality verdict; the independent check (the avatar's moving face
vertices to the registered template, host/fit_coverage.py) puts the face a median under
1 mm from it with at least 70 % within 3 mm; and `softdeca replay` of a real take moves no
vertex more than 20 mm from the avatar's own linear blend."""

from __future__ import annotations

import json
import shutil
import struct
import subprocess
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from bounds import above, below
from softdeca_train.host.fit_check import DEFAULT_BUNDLE
from softdeca_train.host.fit_coverage import face_coverage
from softdeca_train.host.native import NativeFit, NativeModel
from softdeca_train.mesh_files import read_pc2
from softdeca_train.paths import default_takes_path
from softdeca_train.sample_avatars.build import make_avatar
from softdeca_train.sample_avatars.config import AvatarConfig, low_poly
from softdeca_train.sample_avatars.gltf_families import (
    VROID_PRIMITIVES,
    VROID_TARGETS,
    write_ready_player_me,
    write_vroid,
)
from softdeca_train.template import Template
from streaming_cli import CLI

# Ready Player Me: a head of a few thousand vertices with eyes and teeth as meshes of their own,
# hair cards and eyebrow fins; VRoid: a low-poly face with everything in one mesh.
FAMILIES = {
    "ready player me": AvatarConfig(
        identity="seed 606",
        remesh=3000,
        remesh_style="adaptive",
        separate_eyes_teeth=True,
        hair_cards=8,
        eyebrows=True,
    ),
    "vroid": replace(
        low_poly(AvatarConfig(identity="seed 707")), unit="m", up="y", names="arkit"
    ),
}
LIMIT_FROM_LINEAR_M = 0.020  # acceptance: no vertex 20 mm from the avatar's own blend


def glb_json(path: Path) -> dict:
    data = path.read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    return json.loads(data[20 : 20 + length])


def check_written_as_the_family_writes(family: str, doc: dict) -> None:
    """The file holds the encodings the family is known for (so the test reads them)."""
    accessors = doc["accessors"]
    if family == "ready player me":
        targets = [
            t["POSITION"] for m in doc["meshes"] for t in m["primitives"][0]["targets"]
        ]
        assert len(doc["meshes"]) >= 3
        assert all(len(m["extras"]["targetNames"]) == 52 for m in doc["meshes"])
        assert any(
            "bufferView" not in accessors[t] and "sparse" not in accessors[t]
            for t in targets
        )
        assert any("sparse" in accessors[t] for t in targets)
    else:
        assert {"EXT_meshopt_compression", "KHR_mesh_quantization"} <= set(
            doc["extensionsUsed"]
        )
        assert any(b.get("extensions", {}).get("EXT_meshopt_compression", {}).get("fallback")
                   for b in doc["buffers"])  # fmt: skip
        # gltfpack keeps the face's name on its node, the primitives (a material each) apart
        (face,) = doc["meshes"]
        assert len(face["primitives"]) == VROID_PRIMITIVES
        assert len(face["extras"]["targetNames"]) == VROID_TARGETS
        assert face["extras"]["targetNames"][0].startswith("Fcl_")


def max_distance_m(moves: np.ndarray, replay: dict) -> float:
    """The largest of the point caches' moves (frames x vertices x 3, in each mesh's own units
    and axes: a gltfpack file's are quantised integers) in metres, through each part's map to
    the view (replay.json's avatar_mesh.view)."""
    view = replay["avatar_mesh"]["view"]
    worst = 0.0
    for part in view["parts"]:
        linear = (
            np.asarray(part["to_view"]).reshape(3, 4)[:, :3] * view["metres_per_unit"]
        )
        first, count = part["first_vertex"], part["vertex_count"]
        metres = moves[:, first : first + count] @ linear.T
        worst = max(worst, float(np.linalg.norm(metres, axis=2).max()))
    return worst


@pytest.mark.parametrize("family", list(FAMILIES))
def test_gltf_families_fit_cover_the_face_and_replay(
    shipped_model: NativeModel, template: Template, tmp_path: Path, family: str
) -> None:
    if family == "vroid" and shutil.which("gltfpack") is None:
        pytest.skip("gltfpack is not installed (.ci/setup installs it)")
    a = make_avatar(FAMILIES[family], template)
    write = write_ready_player_me if family == "ready player me" else write_vroid
    path = write(a, tmp_path / "avatar.glb")
    check_written_as_the_family_writes(family, glb_json(path))

    fit_dir = tmp_path / "fit"
    run = subprocess.run(
        [CLI, "fit", str(path), "--bundle", str(DEFAULT_BUNDLE), "--out", str(fit_dir)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    quality = json.loads((fit_dir / "fit.json").read_text())["fit"]["quality"]
    assert quality["passed"], quality
    c = face_coverage(
        shipped_model, NativeFit.load(shipped_model, fit_dir / "avatar.fit"), a
    )
    below(
        c.median_mm,
        1.0,
        "acceptance: the face a median 1 mm from the registered template",
    )
    above(c.within, 0.7, "acceptance: 70 % of the face within 3 mm of it")

    out = tmp_path / "replay"
    run = subprocess.run(
        [
            CLI, "replay", str(default_takes_path() / "S07-001.csv"), "--bundle",
            str(DEFAULT_BUNDLE), "--avatar", str(fit_dir), "--start", "300", "--frames", "40",
            "--out", str(out),
        ],
        capture_output=True,
        text=True,
        check=False,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    linear, softdeca = read_pc2(out / "linear.pc2"), read_pc2(out / "softdeca.pc2")
    assert linear.shape == softdeca.shape and len(linear) == 40
    worst = max_distance_m(
        softdeca - linear, json.loads((out / "replay.json").read_text())
    )
    below(
        worst,
        LIMIT_FROM_LINEAR_M,
        "acceptance: no vertex 20 mm from the avatar's own blend",
    )
    assert worst > 0, "SoftDECA moved nothing: the replay did not run the model"
