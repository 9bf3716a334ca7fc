"""ARKit's blendshape names and the Live Link Face values have one definition,
plugin/data/face_names.json: the C++ library embeds it at build time, the training package
reads it, the Swift package's tests check its copy (FaceNamesTests.swift), and no other source
file spells the lists out."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

from softdeca_train.face_names import ARKIT_BLENDSHAPES, DEFINITION, LIVELINKFACE_VALUES
from softdeca_train.host.native import blendshape_index
from softdeca_train.streaming.livelinkface import CANONICAL, VALUE_NAMES

ROOT = Path(__file__).resolve().parents[2]
# Two neighbours that stand next to each other only in a spelled-out list of that order.
LIST_MARKERS = {
    "ARKit canonical order": re.compile(r'browOuterUpRight"\s*,\s*"cheekPuff"'),
    "Live Link Face order": re.compile(r'EyeWideLeft"\s*,\s*"EyeBlinkRight"'),
}
# The Swift package keeps a copy (an app bundle reads no repository file); FaceNamesTests
# checks it against the definition.
CHECKED_COPIES = {
    "ios_capture/Sources/SoftDecaCapture/ARKitBlendshapes.swift",
    "ios_capture/Sources/SoftDecaCapture/LiveLinkFace.swift",
}


def test_training_reads_the_definition() -> None:
    data = json.loads(DEFINITION.read_text())
    assert list(ARKIT_BLENDSHAPES) == data["arkit_blendshapes"]
    assert list(LIVELINKFACE_VALUES) == data["livelinkface_values"] == list(VALUE_NAMES)
    assert ARKIT_BLENDSHAPES == tuple(
        sorted(ARKIT_BLENDSHAPES)
    )  # ARKit's alphabetical order
    assert sorted(CANONICAL.tolist()) == list(range(52))


def test_no_source_file_spells_the_lists_out() -> None:
    tracked = subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT, capture_output=True, text=True, check=True,
    ).stdout.split()  # fmt: skip
    suffixes = {".py", ".cpp", ".h", ".cs", ".swift", ".cmake", ".txt"}
    spelled = []
    for name in tracked:
        path = ROOT / name
        if path.suffix not in suffixes or name in CHECKED_COPIES or not path.is_file():
            continue
        text = path.read_text(encoding="utf-8", errors="replace")
        spelled += [
            f"{name}: {what}" for what, rx in LIST_MARKERS.items() if rx.search(text)
        ]
    assert spelled == []


def test_the_swift_copies_are_the_ones_its_tests_check() -> None:
    for name in CHECKED_COPIES:
        text = (ROOT / name).read_text()
        assert any(rx.search(text) for rx in LIST_MARKERS.values()), name
    swift_test = ROOT / "ios_capture/Tests/SoftDecaCaptureTests/FaceNamesTests.swift"
    assert "plugin/data/face_names.json" in swift_test.read_text()


def test_rig_names_map_as_the_librarys_table_says() -> None:
    """The library's rule for rigs' names, through the C ABI, on the table the native and C#
    tests read too."""
    table = ROOT / "tests" / "golden" / "names" / "rig_blendshape_names.tsv"
    rows = [
        line.split("\t")
        for line in table.read_text().splitlines()
        if "\t" in line and not line.startswith("#")
    ]
    assert len(rows) > 30
    for name, want in rows:
        expected = -1 if want == "-" else ARKIT_BLENDSHAPES.index(want)
        assert blendshape_index(name) == expected, name
