"""A material parameter is described by one type per language, with the same field names
everywhere: the C ABI's softdeca_parameter_info (and its ctypes and C# mirrors), the native
ParameterSpec (plugin/src/core/parameter_spec.h), the training package's ParameterSpec
(softdeca_train/parameters.py) and Unity's ParameterInfo. These tests fail where a second type
with a default and a range appears in a language, or where the names drift apart."""

from __future__ import annotations

import ast
import dataclasses
import re
from pathlib import Path

from softdeca_train.parameters import ParameterSpec

ROOT = Path(__file__).resolve().parents[2]
HEADER = ROOT / "plugin" / "include" / "softdeca" / "softdeca.h"
NATIVE_SPEC = ROOT / "plugin" / "src" / "core" / "parameter_spec.h"
CSHARP_INFO = ROOT / "unity_package" / "Runtime" / "Core" / "Model.cs"

# The one description per language (and the C ABI's mirrors, which must exist beside them).
PYTHON = {
    ("softdeca_train/parameters.py", "ParameterSpec"),
    ("softdeca_train/host/native.py", "ParameterInfo"),  # the ctypes mirror
}
NATIVE = {
    ("src/core/parameter_spec.h", "ParameterSpec"),
    ("include/softdeca/softdeca.h", "softdeca_parameter_info"),
}
CSHARP = {
    ("Runtime/Core/Model.cs", "ParameterInfo"),
    ("Runtime/Core/NativeTypes.cs", "NativeParameterInfo"),  # the interop mirror
}

DEFAULTS = {"default", "defaultvalue"}
RANGES = ({"lo", "hi"}, {"min", "max"}, {"minimum", "maximum"})


def describes_a_parameter(fields: set[str]) -> bool:
    """A default beside a range, in any language's spelling."""
    plain = {re.sub(r"[^a-z0-9]", "", f.lower()) for f in fields}
    return bool(plain & DEFAULTS) and any(r <= plain for r in RANGES)


def python_types(tree: Path) -> dict[tuple[str, str], set[str]]:
    """Every class of the Python files under `tree` with its fields: annotated names, and the
    names of a ctypes `_fields_` list."""
    out = {}
    for path in tree.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if not isinstance(node, ast.ClassDef):
                continue
            fields = set()
            for item in node.body:
                if isinstance(item, ast.AnnAssign) and isinstance(
                    item.target, ast.Name
                ):
                    fields.add(item.target.id)
                elif isinstance(item, ast.Assign) and any(
                    isinstance(t, ast.Name) and t.id == "_fields_" for t in item.targets
                ):
                    fields |= {
                        e.elts[0].value
                        for e in ast.walk(item.value)
                        if _ctypes_field(e)
                    }
            out[(path.relative_to(tree).as_posix(), node.name)] = fields
    return out


def _ctypes_field(node: ast.AST) -> bool:
    return (
        isinstance(node, ast.Tuple)
        and len(node.elts) == 2
        and isinstance(node.elts[0], ast.Constant)
        and isinstance(node.elts[0].value, str)
    )


def braced_types(folder: Path, suffixes: tuple[str, ...]) -> dict[tuple[str, str], str]:
    """Every struct and class body of the files under `folder`, by (file, type name)."""
    return {
        (path.relative_to(folder).as_posix(), name): body
        for path in folder.rglob("*")
        if path.suffix in suffixes
        for name, body in bodies(path.read_text(errors="replace")).items()
    }


def bodies(text: str) -> dict[str, str]:
    """The body of every struct and class of a C, C++ or C# text, by name."""
    out = {}
    for m in re.finditer(r"\b(?:struct|class)\s+(\w+)[^;{()]*\{", text):
        depth, end = 1, m.end()
        while depth and end < len(text):
            depth += {"{": 1, "}": -1}.get(text[end], 0)
            end += 1
        out[m.group(1)] = text[m.end() : end - 1]
    return out


def member_names(body: str) -> set[str]:
    """Names a C, C++ or C# body declares: the identifiers before `;`, `,`, `=` or `[` outside
    nested braces (method bodies, initialisers)."""
    while (flat := re.sub(r"\{[^{}]*\}", "", body)) != body:
        body = flat
    return set(re.findall(r"\b([A-Za-z_]\w*)\s*(?=[;,=\[])", body))


def abi_fields() -> list[str]:
    body = bodies(HEADER.read_text())["softdeca_parameter_info"]
    body = re.sub(r"/\*.*?\*/", "", body, flags=re.DOTALL)
    return [f for f in re.findall(r"\b(\w+)\s*(?=[;,])", body) if f != "struct_size"]


def pascal(name: str) -> str:
    return "".join(w.title() for w in name.split("_"))


def test_python_has_one_parameter_description() -> None:
    types = python_types(ROOT / "training")
    assert {k for k, fields in types.items() if describes_a_parameter(fields)} == PYTHON
    assert [k for k in types if k[1] == "ParameterSpec"] == [
        ("softdeca_train/parameters.py", "ParameterSpec")
    ]


def test_the_library_has_one_parameter_description() -> None:
    types = braced_types(ROOT / "plugin", (".h", ".cpp", ".c"))
    found = {
        k for k, body in types.items() if describes_a_parameter(member_names(body))
    }
    assert found == NATIVE


def test_unity_has_one_parameter_description() -> None:
    types = braced_types(ROOT / "unity_package", (".cs",))
    found = {
        k for k, body in types.items() if describes_a_parameter(member_names(body))
    }
    assert found == CSHARP


def test_every_description_names_the_fields_as_the_c_abi_does() -> None:
    fields = abi_fields()
    assert fields[4:7] == ["default_value", "minimum", "maximum"]
    native = member_names(bodies(NATIVE_SPEC.read_text())["ParameterSpec"])
    python = {f.name for f in dataclasses.fields(ParameterSpec)}
    csharp = member_names(bodies(CSHARP_INFO.read_text())["ParameterInfo"])
    # name..log_scale: the strings, the default, the range and the scale in every language
    assert [f for f in fields if f not in native] == []
    assert [f for f in fields if f not in python] == []
    assert [pascal(f) for f in fields if pascal(f) not in csharp] == []


def test_the_scan_sees_a_second_description(tmp_path: Path) -> None:
    """The rule itself: a default beside a range counts, in any language and spelling; a range
    alone (a sweep, a box) or a default alone does not."""
    (tmp_path / "old.py").write_text(
        "class Sweep:\n    lo: float\n    hi: float\n\n"
        "class Old:\n    name: str\n    default: float\n    min: float\n    max: float\n"
    )
    (tmp_path / "old.h").write_text(
        "struct Old {\n  std::string name;\n  double default_value = 0, min = 0, max = 0;\n};\n"
        "struct Box {\n  double lo[3], hi[3];\n  void grow() { default_value = lo; }\n};\n"
    )
    (tmp_path / "Old.cs").write_text(
        "public struct Old\n{\n    public double DefaultValue;\n    public double Lo;\n"
        "    public double Hi;\n}\n"
    )
    python = python_types(tmp_path)
    assert {k for k, f in python.items() if describes_a_parameter(f)} == {
        ("old.py", "Old")
    }
    native = braced_types(tmp_path, (".h", ".cs"))
    found = {
        k for k, body in native.items() if describes_a_parameter(member_names(body))
    }
    assert found == {("old.h", "Old"), ("Old.cs", "Old")}
    assert not describes_a_parameter({"name", "default_value"})
