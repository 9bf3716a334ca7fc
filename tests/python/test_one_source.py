"""Rules the product writes once, beside the plugin's other shared definitions in plugin/data/:
the contact rules' numbers (contact_rules.json) and the landmark definition (landmarks.json).
These tests fail where a second copy appears in the source trees."""

from __future__ import annotations

import ast
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


# ---- Algorithms written once ----------------------------------------------------------------
# Each algorithm the library and the training package share has one implementation, in the
# library; the training package calls it through softdeca_native. A Python function of one of
# these names must hand the work to softdeca_native; the names are the homes' own and those of
# the Python functions that call them.
PACKAGE = ROOT / "training" / "softdeca_train"
ONE_HOME: dict[str, tuple[str, tuple[str, ...], tuple[str, ...]]] = {
    # job: (home, its functions, the names a Python implementation would take)
    "the lip and lid contact sets": (
        "plugin/src/prepare/contact_sets.cpp",
        (
            "lip_contact_zone",
            "lip_sets",
            "eye_fissures",
            "lid_sides",
            "lid_sets",
            "contact_sets",
        ),
        (
            "lip_contact_zone",
            "lip_sets",
            "lip_sets_of",
            "eye_fissures",
            "fissure_line",
            "lid_sides",
            "lid_side_of_points",
            "lid_sets",
            "lid_sets_of",
            "contact_sets",
            "collision_sets",
        ),
    ),
    "the parameter localisation rules": (
        "plugin/src/prepare/parameters.cpp",
        ("skin_vertex_areas", "faces_from_vertex_map", "vertices_from_face_map"),
        (
            "localise_to_faces",
            "localise_to_vertices",
            "faces_from_vertex_map",
            "vertices_from_face_map",
            "skin_vertex_areas",
            "vertex_areas",
            "_column",  # ParameterState's per-element values
        ),
    ),
    # the data's identity fields (lhm/carried.py, carry_basis) take the same stiffness
    "the fill's carry to a neutral skin": (
        "plugin/src/prepare/rest_physics.cpp",
        ("carry_fill", "add_fill_stiffness"),
        ("carry_fill", "carried_vertices", "fill_stiffness", "stiffness_matrix"),
    ),
}
# Modules using the contact rules' landmarks for another job, with that job.
OTHER_LANDMARK_JOBS = {
    "lhm/tissue_depth.py": "soft-tissue depth anchors below the lower lids",
}


def package_modules() -> dict[str, ast.Module]:
    return {
        str(p.relative_to(PACKAGE)): ast.parse(p.read_text(encoding="utf-8"))
        for p in sorted(PACKAGE.rglob("*.py"))
    }


def calls_native(function: ast.AST) -> bool:
    """Whether the function calls softdeca_native (imported as itself or as `native`)."""
    return any(
        isinstance(n, ast.Call)
        and isinstance(n.func, ast.Attribute)
        and isinstance(n.func.value, ast.Name)
        and n.func.value.id in ("native", "softdeca_native")
        for n in ast.walk(function)
    )


def own_implementations(modules: dict[str, ast.Module]) -> list[str]:
    """Python functions of a listed name that do the work themselves."""
    names = {n: job for job, (_, _, py) in ONE_HOME.items() for n in py}
    return [
        f"{path}:{f.lineno}: {f.name} ({names[f.name]}) does not call softdeca_native"
        for path, tree in modules.items()
        for f in ast.walk(tree)
        if isinstance(f, ast.FunctionDef | ast.AsyncFunctionDef)
        and f.name in names
        and not calls_native(f)
    ]


def contact_landmarks() -> dict[str, frozenset[int]]:
    data = json.loads(CONTACT_RULES.read_text(encoding="utf-8"))
    return {name: frozenset(e["value"]) for name, e in data["landmarks"].items()}


def _int_literals(node: ast.AST) -> list[int] | None:
    """The ids a literal collection or a slice of int literals names, else None."""
    if isinstance(node, ast.Tuple | ast.List | ast.Set) and len(node.elts) >= 2:
        values = [e.value for e in node.elts if isinstance(e, ast.Constant)]
        if len(values) == len(node.elts) and all(type(v) is int for v in values):
            return values
    if (
        isinstance(node, ast.Slice)
        and isinstance(node.lower, ast.Constant)
        and isinstance(node.upper, ast.Constant)
        and type(node.lower.value) is int
        and type(node.upper.value) is int
        and node.step is None
        and node.upper.value - node.lower.value >= 2
    ):
        return list(range(node.lower.value, node.upper.value))
    return None


def landmark_copies(
    modules: dict[str, ast.Module], landmarks: dict[str, frozenset[int]]
) -> list[str]:
    """Literal collections of two or more landmark ids from one of the rules' landmark lists
    (the inner lip contour, its corners, an eye's fissure), outside the reader."""
    out = []
    for path, tree in modules.items():
        if path == "contact_rules.py" or path in OTHER_LANDMARK_JOBS:
            continue
        for node in ast.walk(tree):
            ids = _int_literals(node)
            if ids is None:
                continue
            out += [
                f"{path}:{node.lineno}: {ids} are contact_rules.json's landmarks.{name}"
                for name, members in landmarks.items()
                if set(ids) <= members
            ][:1]
    return out


def test_each_shared_algorithm_has_one_home() -> None:
    for job, (home, functions, _) in ONE_HOME.items():
        text = (ROOT / home).read_text(encoding="utf-8")
        for f in functions:
            assert re.search(rf"\b{f}\(", text), f"{job}: {home} defines no {f}"
        bindings = (ROOT / "plugin/python/prepare_bindings.cpp").read_text(
            encoding="utf-8"
        )
        area = Path(home).parts[2]  # plugin/src/<area>/..., namespace softdeca::<area>
        assert all(f"{area}::{f}(" in bindings for f in functions), job
    modules = package_modules()
    # the check finds a copy: a function of a listed name that computes on its own
    copy = ast.parse(
        "def lip_sets_of(skin, tris, rules):\n"
        "    return np.flatnonzero(np.linalg.norm(skin - skin[60], axis=1) < 0.012)\n"
        "def fissure_line(skin, lm68, eye):\n"
        "    return native.eye_fissures(skin, lm68)[0]\n"
    )
    assert own_implementations({"copy.py": copy}) == [
        "copy.py:1: lip_sets_of (the lip and lid contact sets) does not call softdeca_native"
    ]
    wrappers = [
        f.name
        for tree in modules.values()
        for f in ast.walk(tree)
        if isinstance(f, ast.FunctionDef) and calls_native(f)
    ]
    assert {"lip_sets_of", "lid_sets_of", "fissure_line", "lid_side_of_points"} <= set(
        wrappers
    )
    assert own_implementations(modules) == []


# ---- Deliberate oracles -----------------------------------------------------------------------
# The Python implementations kept on purpose as independent references, named here and nowhere
# else: module (in the training package) -> (the library's home of the same job, the test that
# compares the two). Each says so in its docstring ("Oracle:").
ORACLES: dict[str, tuple[str, str]] = {
    "models/reference.py": (
        "plugin/src/runtime/avatar_evaluate.cpp",
        "test_runtime_parity.py",
    ),
    "models/rest_physics.py": (
        "plugin/src/prepare/rest_physics.cpp",
        "test_runtime_parity.py",
    ),
    "host/fit_coverage.py": (
        "plugin/src/fit/fit_quality.cpp",
        "test_fit_avatars.py",
    ),
}


def test_the_oracles_are_named_once_and_compared() -> None:
    modules = package_modules()
    declared = [
        path
        for path, tree in modules.items()
        if (ast.get_docstring(tree) or "").count("\nOracle:")
        or (ast.get_docstring(tree) or "").startswith("Oracle:")
    ]
    assert sorted(declared) == sorted(ORACLES), (
        "an oracle is named here and in its docstring"
    )
    for module, (home, test) in ORACLES.items():
        assert (ROOT / home).is_file(), home
        text = (ROOT / "tests" / "python" / test).read_text(encoding="utf-8")
        own = [
            n.name
            for n in modules[module].body
            if isinstance(n, ast.FunctionDef | ast.ClassDef)
            and not n.name.startswith("_")
        ]
        used = [name for name in own if re.search(rf"\b{name}\b", text)]
        assert used, (
            f"{test} uses nothing of {module}: it does not compare the library with it"
        )


def test_the_contact_landmarks_are_written_once() -> None:
    landmarks = contact_landmarks()
    assert landmarks["inner_lip"] == frozenset(range(60, 68))
    from softdeca_train.contact_rules import CONTACT_LANDMARKS

    assert {k: frozenset(v) for k, v in vars(CONTACT_LANDMARKS).items()} == landmarks
    # the check finds a copy of a list, a pair of them, or a range
    copies = ast.parse(
        "EYES = {'right': (36, (37, 38), 39, (41, 40))}\n"
        "corner = lm[[60, 64]]\n"
        "mouth = lm68[60:68]\n"
        "face = (27, 8)\n"
    )
    found = landmark_copies({"copy.py": copies}, landmarks)
    assert sorted(f.split(":")[1] for f in found) == ["1", "1", "2", "3"], found
    assert landmark_copies(package_modules(), landmarks) == []
