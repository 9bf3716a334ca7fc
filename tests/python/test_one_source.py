"""Rules the product writes once, beside the plugin's other shared definitions in plugin/data/:
the contact rules' numbers (contact_rules.json) and the landmark definition (landmarks.json).
These tests fail where a second copy appears in the source trees."""

from __future__ import annotations

import json
import math
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "plugin" / "data"
CONTACT_RULES = DATA / "contact_rules.json"
LANDMARKS = DATA / "landmarks.json"

# The product's sources: the library, its command lines, the training package, Unity, iOS,
# and the build scripts.
SOURCE_SUFFIXES = (".py", ".h", ".cpp", ".cs", ".swift", ".cmake", ".txt", ".m", ".mm")
SOURCE_TREES = ("plugin", "training", "unity_package", "ios_capture", "cmake")
# The implementations of the contact rules: every number in them counts as a rule's.
CONTACT_FILES = (
    "plugin/src/prepare/contact_sets.h",
    "plugin/src/prepare/contact_sets.cpp",
    "training/softdeca_train/contact_rules.py",
    "training/softdeca_train/sim/lips.py",
    "training/softdeca_train/sim/lids.py",
    "training/softdeca_train/lhm/eyes.py",
    "training/softdeca_train/template/plausibility.py",
    "training/softdeca_train/models/rest_head.py",
)
NUMBER = re.compile(r"(?<![\w.])(\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])")


def repository_files() -> list[str]:
    """Committed and new (not ignored) files, relative to the repository."""
    out = subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    return [f for f in out.splitlines() if (ROOT / f).is_file()]


def source_files() -> list[str]:
    return [
        f
        for f in repository_files()
        if f.endswith(SOURCE_SUFFIXES) and f.split("/")[0] in SOURCE_TREES
    ]


def contact_rules() -> dict[str, float]:
    data = json.loads(CONTACT_RULES.read_text(encoding="utf-8"))
    assert data["format"] == "softdeca-contact-rules"
    return {name: float(rule["value"]) for name, rule in data["rules"].items()}


def rule_name_pattern(names: list[str]) -> re.Pattern[str]:
    """A rule's name in any language's spelling: lip_radius, LIP_RADIUS, lipRadius, LipRadius."""
    words = ["_?".join(name.split("_")) for name in names]
    return re.compile("|".join(words), re.IGNORECASE)


def contact_numbers_in(
    line: str, rules: dict[str, float], in_rule_file: bool
) -> list[str]:
    """The rules' numbers written on `line` where it is about the contact rules."""
    if not in_rule_file and not rule_name_pattern(list(rules)).search(line):
        return []
    found = []
    for m in NUMBER.finditer(line):
        value = float(m.group(0))
        found += [
            f"{name} = {m.group(0)}"
            for name, rule in rules.items()
            if math.isclose(value, rule, rel_tol=1e-9)
        ]
    return found


def test_the_contact_rules_are_read_from_their_file() -> None:
    rules = contact_rules()
    assert set(rules) == {
        "lip_radius",
        "lip_corner_radius",
        "lid_reach",
        "lid_corner_radius",
        "eye_zone_share",
    }
    from softdeca_train.contact_rules import CONTACT_RULES as python_rules

    assert vars(python_rules) == rules
    for f in CONTACT_FILES:
        assert (ROOT / f).is_file(), f


def test_a_contact_rule_number_is_written_only_in_its_file() -> None:
    rules = contact_rules()
    # the check finds a copy in either kind of place
    assert contact_numbers_in("    lip_radius: float = 0.012", rules, False)
    assert contact_numbers_in("  double lidReach = 8e-3;", rules, False)
    assert contact_numbers_in("    reach: float = 0.008,", rules, True)
    assert not contact_numbers_in("    reach: float = 0.008,", rules, False)
    files = source_files()
    assert len(files) > 300
    offenders = []
    for f in files:
        in_rule_file = f in CONTACT_FILES
        for k, line in enumerate(
            (ROOT / f).read_text(encoding="utf-8").splitlines(), 1
        ):
            offenders += [
                f"{f}:{k}: {n}" for n in contact_numbers_in(line, rules, in_rule_file)
            ]
    assert offenders == [], (
        "contact rule numbers written outside "
        + str(CONTACT_RULES.relative_to(ROOT))
        + ":\n"
        + "\n".join(offenders)
    )


def is_landmark_definition(data: object) -> bool:
    """The landmark definition's shape: ARKit vertex indices of named landmarks and contours
    on a stated topology (a bundle's manifest carries the indices in a shape of its own)."""
    return (
        isinstance(data, dict)
        and isinstance(data.get("landmarks"), list)
        and {"topology", "contours"} <= set(data)
        and all(isinstance(p, dict) and "arkit_vertex" in p for p in data["landmarks"])
    )


def test_the_landmark_definition_is_one_file() -> None:
    assert is_landmark_definition(json.loads(LANDMARKS.read_text(encoding="utf-8")))
    definitions = []
    for f in repository_files():
        if not f.endswith(".json") or f.startswith("tests/fuzz/corpus/"):
            continue
        try:
            data = json.loads((ROOT / f).read_text(encoding="utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError):
            continue
        if is_landmark_definition(data):
            definitions.append(f)
    assert definitions == [str(LANDMARKS.relative_to(ROOT))]


def test_every_reader_names_the_landmark_file() -> None:
    """No source names the definition's old place or another landmark file: its readers (the
    training package, the iOS app) name plugin/data/landmarks.json."""
    files = source_files() + [f for f in repository_files() if f.endswith(".md")]
    stale = re.compile(r"landmarks/definition\.json|\bdefinition\.json")
    offenders = [
        f"{f}:{k}"
        for f in files
        for k, line in enumerate((ROOT / f).read_text(encoding="utf-8").splitlines(), 1)
        if stale.search(line) and not f.startswith("docs/datasets/")
    ]
    assert offenders == []
    readers = [
        f
        for f in source_files()
        if '"plugin" / "data" / "landmarks.json"'
        in (ROOT / f).read_text(encoding="utf-8")
        or "plugin/data/landmarks.json" in (ROOT / f).read_text(encoding="utf-8")
    ]
    assert "training/softdeca_train/landmarks/definition.py" in readers
    assert "ios_capture/Sources/SoftDecaCapture/LandmarkProfile.swift" in readers
