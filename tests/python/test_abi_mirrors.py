"""The C ABI's structs are written once, in plugin/include/softdeca/softdeca.h; Unity's C#
(unity_package/Runtime/Core/NativeTypes.cs) and the Python binding (softdeca_train/host/
native.py) mirror them by hand. These tests parse the header and hold every mirror to it: the
same fields in the same order with the same types (and names, up to the languages' spelling),
the same ABI version, the same enum values (C#'s enums, Python's PRECISIONS), and C#'s
P/Invoke declarations (NativeMethods.cs) the header's signatures, and Python's function table
(native.SIGNATURES) the same.

Kept whole: one parser of the header, and every mirror held to what it read."""

from __future__ import annotations

import ctypes as C
import re
from dataclasses import dataclass
from pathlib import Path

import pytest
from softdeca_train.host import native

ROOT = Path(__file__).resolve().parents[2]
HEADER = ROOT / "plugin" / "include" / "softdeca" / "softdeca.h"
CSHARP_TYPES = ROOT / "unity_package" / "Runtime" / "Core" / "NativeTypes.cs"
CSHARP_METHODS = ROOT / "unity_package" / "Runtime" / "Core" / "NativeMethods.cs"

# Header struct -> (C# mirror, Python mirror or None where Python needs none).
MIRRORS: dict[str, tuple[str, str | None]] = {
    "softdeca_model_options": ("ModelOptions", "ModelOptions"),
    "softdeca_model_info": ("ModelInfo", "ModelInfo"),
    "softdeca_parameter_info": ("NativeParameterInfo", "ParameterInfo"),
    "softdeca_avatar_desc": ("AvatarDesc", "AvatarDesc"),
    "softdeca_output": ("Output", "Output"),
    "softdeca_stats": ("AvatarStats", "Stats"),
    "softdeca_avatar_mesh": ("NativeAvatarMesh", "AvatarMesh"),
    "softdeca_fit_options": ("FitOptions", "FitOptions"),
    "softdeca_pose": ("Pose", None),
    "softdeca_frame": ("Frame", None),
    "softdeca_receiver_config": ("ReceiverConfig", None),
    "softdeca_receiver_stats": ("ReceiverStats", None),
    "softdeca_recording_header": ("RecordingHeader", None),
    "softdeca_recording_info": ("NativeRecordingInfo", None),
    "softdeca_convert_report": ("ConvertReport", None),
}


@dataclass(frozen=True)
class Field:
    name: str
    kind: str  # u8 i32 u32 u64 f32 f64 ptr, or struct:<header name>
    count: int = 1  # array length


def spelling(name: str) -> str:
    """A field's name without the languages' spelling (snake_case, PascalCase)."""
    return re.sub(r"[^a-z0-9]", "", name.lower())


# ---- the header -----------------------------------------------------------------------------
C_KINDS = {
    "uint8_t": "u8",
    "char": "u8",
    "int32_t": "i32",
    "uint32_t": "u32",
    "int64_t": "i64",
    "uint64_t": "u64",
    "float": "f32",
    "double": "f64",
}


def _evaluate(expr: str, constants: dict[str, int]) -> int:
    tokens = re.findall(r"[A-Za-z_]\w*|\d+|[*+()-]", expr)
    text = " ".join(str(constants[t]) if t in constants else t for t in tokens)
    if not re.fullmatch(r"[\d\s*+()-]+", text):
        raise ValueError(f"array size {expr!r}: unknown name")
    return int(eval(text))  # digits and operators only (checked above)


def _header_text() -> str:
    text = HEADER.read_text(encoding="utf-8")
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.DOTALL)
    return re.sub(r"//[^\n]*", " ", text)


def _type_kinds(text: str) -> dict[str, str]:
    """C_KINDS with the header's typedefs of them and its enums."""
    kinds = dict(C_KINDS)
    for m in re.finditer(r"typedef\s+(\w+)\s+(\w+)\s*;", text):
        if m[1] in kinds:
            kinds[m[2]] = kinds[m[1]]
    for m in re.finditer(r"typedef\s+enum\s+\w*\s*\{[^}]*\}\s*(\w+)\s*;", text):
        kinds[m[1]] = (
            "i32"  # the C ABI's enums have int's size on every platform it targets
        )
    return kinds


def header_structs() -> tuple[dict[str, list[Field]], int]:
    text = _header_text()
    constants = {
        m[1]: int(m[2])
        for m in re.finditer(r"#define\s+(\w+)\s+(\d+)u?\b", text, re.MULTILINE)
    }
    kinds = _type_kinds(text)
    structs: dict[str, list[Field]] = {}
    for m in re.finditer(r"typedef\s+struct\s+(\w+)\s*\{([^}]*)\}\s*(\w+)\s*;", text):
        fields = []
        for decl in filter(None, (d.strip() for d in m[2].split(";"))):
            first = re.match(r"(?:const\s+)?(\w+)\s*(\**)\s*(.*)", decl, re.DOTALL)
            assert first, decl
            base, star, rest = first.groups()
            for item in rest.split(","):
                one = re.fullmatch(r"\s*(\**)\s*(\w+)\s*(?:\[(.+)\])?\s*", item)
                assert one, f"{m[3]}: cannot read {decl!r}"
                pointer = bool(star or one[1])
                kind = (
                    "ptr"
                    if pointer
                    else kinds.get(
                        base, f"struct:{base}" if base.startswith("softdeca_") else "?"
                    )
                )
                assert kind != "?", f"{m[3]}.{one[2]}: unknown type {base}"
                count = _evaluate(one[3], constants) if one[3] else 1
                fields.append(Field(one[2], kind, count))
        structs[m[3]] = fields
    return structs, constants["SOFTDECA_ABI_VERSION"]


# ---- C# -------------------------------------------------------------------------------------
CS_KINDS = {
    "byte": "u8",
    "int": "i32",
    "uint": "u32",
    "long": "i64",
    "ulong": "u64",
    "float": "f32",
    "double": "f64",
    "IntPtr": "ptr",
}


def csharp_structs() -> dict[str, list[Field]]:
    text = CSHARP_TYPES.read_text(encoding="utf-8")
    text = re.sub(r"//[^\n]*", " ", text)
    by_mirror = {cs: c for c, (cs, _) in MIRRORS.items()}
    out = {}
    for m in re.finditer(r"\bstruct\s+(\w+)\s*\{", text):
        # the struct's body: up to its matching brace
        depth, k = 1, m.end()
        while depth:
            depth += {"{": 1, "}": -1}.get(text[k], 0)
            k += 1
        body = text[m.end() : k - 1]
        # drop member functions' bodies, keep the fields (declarations at the top level)
        flat, depth = [], 0
        for ch in body:
            depth += ch == "{"
            if depth == 0:
                flat.append(ch)
            depth -= ch == "}"
        constants = {
            c[1]: int(c[2])
            for c in re.finditer(r"\bconst\s+int\s+(\w+)\s*=\s*(\d+)\s*;", body)
        }
        fields = []
        for decl in re.finditer(
            r"\bpublic\s+(fixed\s+)?(\w+)\s+([\w\s,\[\]*+]+?)\s*;", "".join(flat)
        ):
            kind = CS_KINDS.get(decl[2]) or (
                f"struct:{by_mirror[decl[2]]}" if decl[2] in by_mirror else None
            )
            assert kind, f"{m[1]}: unknown field type {decl[2]}"
            for item in decl[3].split(","):
                one = re.fullmatch(r"\s*(\w+)\s*(?:\[(.+)\])?\s*", item)
                assert one, f"{m[1]}: cannot read {item!r}"
                count = _evaluate(one[2], constants) if one[2] else 1
                fields.append(Field(one[1], kind, count))
        out[m[1]] = fields
    return out


def csharp_abi_version() -> int:
    m = re.search(
        r"\bconst\s+uint\s+AbiVersion\s*=\s*(\d+)\s*;", CSHARP_METHODS.read_text()
    )
    assert m, f"{CSHARP_METHODS}: no AbiVersion"
    return int(m[1])


# ---- Python ---------------------------------------------------------------------------------
PY_KINDS = {
    C.c_uint8: "u8",
    C.c_char: "u8",
    C.c_int32: "i32",
    C.c_uint32: "u32",
    C.c_int64: "i64",
    C.c_uint64: "u64",
    C.c_float: "f32",
    C.c_double: "f64",
    C.c_char_p: "ptr",
    C.c_void_p: "ptr",
}


def python_fields(structure: type[C.Structure]) -> list[Field]:
    by_mirror = {py: c for c, (_, py) in MIRRORS.items() if py}
    out = []
    for name, ctype in structure._fields_:
        count = 1
        if issubclass(ctype, C.Array):
            count, ctype = ctype._length_, ctype._type_
        if issubclass(ctype, C._Pointer):
            kind = "ptr"
        elif issubclass(ctype, C.Structure):
            kind = f"struct:{by_mirror[ctype.__name__]}"
        else:
            kind = PY_KINDS[ctype]
        out.append(Field(name, kind, count))
    return out


# ---- the comparison -------------------------------------------------------------------------
def differences(header: list[Field], mirror: list[Field]) -> list[str]:
    """Where `mirror` leaves the header's layout. A header array may be mirrored by as many
    scalar fields named after it (C#'s Pose: position[3] as PositionX, PositionY, PositionZ)."""
    out, k = [], 0
    for f in header:
        m = mirror[k] if k < len(mirror) else None
        if m and (spelling(m.name), m.kind, m.count) == (
            spelling(f.name),
            f.kind,
            f.count,
        ):
            k += 1
            continue
        split = mirror[k : k + f.count]
        if (
            f.count > 1
            and len(split) == f.count
            and all(
                s.count == 1
                and s.kind == f.kind
                and spelling(s.name).startswith(spelling(f.name))
                for s in split
            )
        ):
            k += f.count
            continue
        out.append(f"field {f.name} ({f.kind} x{f.count}): the mirror has {m}")
        break
    else:
        if k != len(mirror):
            out.append(f"extra fields: {[m.name for m in mirror[k:]]}")
    return out


def test_the_header_parses_into_every_mirrored_struct() -> None:
    structs, version = header_structs()
    assert version >= 1
    assert set(MIRRORS) <= set(structs)
    assert Field("struct_size", "u32") == structs["softdeca_frame"][0]
    assert Field("weights", "f32", 52) in structs["softdeca_frame"]
    assert Field("head", "struct:softdeca_pose") in structs["softdeca_frame"]
    assert [f.name for f in structs["softdeca_parameter_info"]][5:8] == [
        "default_value",
        "minimum",
        "maximum",
    ]


def test_csharp_mirrors_match_the_header() -> None:
    structs, _ = header_structs()
    mirrors = csharp_structs()
    assert sorted(mirrors) == sorted(cs for cs, _ in MIRRORS.values()), (
        "every struct of NativeTypes.cs mirrors one of the header (MIRRORS)"
    )
    problems = {
        c: d
        for c, (cs, _) in MIRRORS.items()
        if (d := differences(structs[c], mirrors[cs]))
    }
    assert problems == {}


def test_python_mirrors_match_the_header() -> None:
    structs, _ = header_structs()
    mirrors = {
        n: v
        for n, v in vars(native).items()
        if isinstance(v, type)
        and issubclass(v, C.Structure)
        and v.__module__ == native.__name__
    }
    assert sorted(mirrors) == sorted(py for _, py in MIRRORS.values() if py), (
        "every ctypes structure of host/native.py mirrors one of the header (MIRRORS)"
    )
    problems = {
        c: d
        for c, (_, py) in MIRRORS.items()
        if py and (d := differences(structs[c], python_fields(mirrors[py])))
    }
    assert problems == {}


def test_mirrors_name_the_headers_abi_version() -> None:
    _, version = header_structs()
    assert csharp_abi_version() == version, "NativeMethods.AbiVersion"
    assert native.ABI_VERSION == version, "softdeca_train.host.native.ABI_VERSION"


# ---- enums: C#'s and Python's values against the header's ------------------------------------
# Header enum -> (C# mirror, the prefix its members' names drop there).
ENUM_MIRRORS: dict[str, tuple[str, str]] = {
    "softdeca_status": ("Status", r"SOFTDECA_(ERROR_)?"),
    "softdeca_precision": ("Precision", "SOFTDECA_PRECISION_"),
    "softdeca_tracking": ("Tracking", "SOFTDECA_TRACKING_"),
    "softdeca_stream_format": ("StreamFormat", "SOFTDECA_FORMAT_"),
}


def _enum_values(body: str) -> dict[str, int]:
    return {k: int(v) for k, v in re.findall(r"(\w+)\s*=\s*(\d+)", body)}


def header_enums() -> dict[str, dict[str, int]]:
    """Every enum of the header: its members' values by name."""
    pattern = r"typedef\s+enum\s+\w*\s*\{([^}]*)\}\s*(\w+)\s*;"
    return {m[2]: _enum_values(m[1]) for m in re.finditer(pattern, _header_text())}


def csharp_enums() -> dict[str, dict[str, int]]:
    text = re.sub(r"//[^\n]*", " ", CSHARP_TYPES.read_text(encoding="utf-8"))
    pattern = r"\benum\s+(\w+)\s*\{([^}]*)\}"
    return {m[1]: _enum_values(m[2]) for m in re.finditer(pattern, text)}


def spelled(values: dict[str, int], prefix: str = "") -> dict[str, int]:
    return {spelling(re.sub(f"^{prefix}", "", k)): v for k, v in values.items()}


def test_enum_mirrors_have_the_headers_values() -> None:
    header, cs = header_enums(), csharp_enums()
    assert sorted(header) == sorted(ENUM_MIRRORS), (
        "every enum of the header has a mirror"
    )
    problems = {
        c: (spelled(header[c], prefix), spelled(cs.get(mirror, {})))
        for c, (mirror, prefix) in ENUM_MIRRORS.items()
        if spelled(header[c], prefix) != spelled(cs.get(mirror, {}))
    }
    assert problems == {}
    precision = spelled(header["softdeca_precision"], "SOFTDECA_PRECISION_")
    assert native.PRECISIONS == precision, "softdeca_train.host.native.PRECISIONS"


# ---- functions: C#'s P/Invoke declarations against the header's prototypes -------------------
# A parameter's kind: a scalar kind, "struct:<header name>", "opaque" (a handle's struct, which
# the header never defines), "void", "any" (IntPtr: any pointer), or "ptr:" + the pointee's kind.
C_SCALARS = {**C_KINDS, "void": "void"}


def _c_kind(text: str, structs: dict[str, list[Field]], kinds: dict[str, str]) -> str:
    text = re.sub(r"\b(const|struct)\b", " ", text).strip()
    if text.endswith("*"):
        return "ptr:" + _c_kind(text[:-1], structs, kinds)
    base = text.strip()
    if base in C_SCALARS:
        return C_SCALARS[base]
    if base in kinds:
        return kinds[base]
    if base in structs:
        return f"struct:{base}"
    assert base.startswith("softdeca_"), f"unknown C type {base!r}"
    return "opaque"


def header_functions() -> dict[str, tuple[str, list[str]]]:
    """name -> (return kind, parameter kinds) of every SOFTDECA_API function."""
    structs, _ = header_structs()
    text = _header_text()
    kinds = _type_kinds(text)
    out = {}
    for m in re.finditer(
        r"SOFTDECA_API\s+([^;(]*?)\b(softdeca_\w+)\s*\(([^)]*)\)\s*;", text
    ):
        params = [p.strip() for p in m[3].split(",")]
        if params == ["void"]:
            params = []
        # each parameter without its name: the last identifier
        types = [re.sub(r"\w+\s*$", "", p) for p in params]
        out[m[2]] = (
            _c_kind(m[1], structs, kinds),
            [_c_kind(t, structs, kinds) for t in types],
        )
    return out


CS_SCALARS = {**CS_KINDS, "void": "void", "Status": "i32", "IntPtr": "any"}


def _cs_kind(text: str) -> str:
    text = text.strip()
    m = re.fullmatch(r"(ref|out)\s+(.+)", text)
    if m:
        return "ptr:" + _cs_kind(m[2])
    if text.endswith("*"):
        return "ptr:" + _cs_kind(text[:-1])
    if text.endswith("Handle"):
        return "ptr:opaque"  # a SafeHandle (Handles.cs) passes the handle's pointer
    by_mirror = {cs: c for c, (cs, _) in MIRRORS.items()}
    if text in by_mirror:
        return f"struct:{by_mirror[text]}"
    assert text in CS_SCALARS, f"unknown C# type {text!r}"
    return CS_SCALARS[text]


def csharp_functions() -> dict[str, tuple[str, list[str]]]:
    text = re.sub(r"//[^\n]*", " ", CSHARP_METHODS.read_text(encoding="utf-8"))
    out = {}
    for m in re.finditer(
        r"\bstatic\s+extern\s+([\w*]+)\s+(softdeca_\w+)\s*\(([^)]*)\)\s*;", text
    ):
        params = [p.strip() for p in m[3].split(",") if p.strip()]
        types = [re.sub(r"\w+$", "", p) for p in params]
        out[m[2]] = (_cs_kind(m[1]), [_cs_kind(t) for t in types])
    return out


def kinds_match(c: str, cs: str) -> bool:
    """IntPtr stands for any pointer, and void* takes any pointer."""
    if c == cs or (cs == "any" and c.startswith("ptr:")):
        return True
    if c.startswith("ptr:") and cs.startswith("ptr:"):
        return c == "ptr:void" or kinds_match(c[4:], cs[4:])
    return False


def signature_problems(header: dict, declared: dict) -> dict[str, str]:
    problems = {}
    for name, (ret, params) in declared.items():
        if name not in header:
            problems[name] = "not in the header"
            continue
        c_ret, c_params = header[name]
        if not kinds_match(c_ret, ret):
            problems[name] = f"returns {ret}, the header {c_ret}"
        elif len(params) != len(c_params):
            problems[name] = f"{len(params)} parameters, the header {len(c_params)}"
        else:
            bad = [
                i
                for i, (c, cs) in enumerate(zip(c_params, params))
                if not kinds_match(c, cs)
            ]
            if bad:
                problems[name] = (
                    f"parameter {bad[0]}: {params[bad[0]]}, the header {c_params[bad[0]]}"
                )
    return problems


def test_csharp_declarations_match_the_headers_prototypes() -> None:
    header, declared = header_functions(), csharp_functions()
    assert len(declared) > 60 and "softdeca_avatar_fit_create" in declared
    assert header["softdeca_avatar_fit_create"] == (
        "i32",
        [
            "ptr:opaque",
            "ptr:struct:softdeca_avatar_mesh",
            "ptr:struct:softdeca_fit_options",
            "ptr:ptr:opaque",
        ],
    )
    assert signature_problems(header, declared) == {}


def test_a_signature_mismatch_is_found() -> None:
    header = {"f": ("i32", ["ptr:opaque", "u32", "ptr:f32"])}
    assert (
        signature_problems(header, {"f": ("i32", ["ptr:opaque", "u32", "ptr:f32"])})
        == {}
    )
    assert (
        signature_problems(header, {"f": ("i32", ["ptr:opaque", "u32", "any"])}) == {}
    )
    for wrong in (
        ["ptr:opaque", "i32", "ptr:f32"],
        ["ptr:opaque", "u32"],
        ["ptr:opaque", "u32", "ptr:f64"],
    ):
        assert "f" in signature_problems(header, {"f": ("i32", wrong)}), wrong
    assert signature_problems(header, {"g": ("void", [])}) == {"g": "not in the header"}


@pytest.mark.parametrize(
    ("mirror", "problem"),
    [
        ([Field("struct_size", "u32"), Field("b", "u32")], "field a"),
        (
            [Field("struct_size", "u32"), Field("a", "f32"), Field("b", "u32")],
            "field a",
        ),
        (
            [Field("struct_size", "u32"), Field("b", "u32"), Field("a", "u32")],
            "field a",
        ),
        (
            [
                Field("struct_size", "u32"),
                Field("a", "u32"),
                Field("b", "u32"),
                Field("c", "u32"),
            ],
            "extra",
        ),
    ],
)
def test_a_mismatch_is_found(mirror: list[Field], problem: str) -> None:
    header = [Field("struct_size", "u32"), Field("a", "u32"), Field("b", "u32")]
    assert differences(header, header) == []
    found = differences(header, mirror)
    assert found and problem in found[0], found


# ---- Python's function table ----------------------------------------------------------------
def python_functions() -> dict[str, tuple[str, list[str]]]:
    """native.SIGNATURES in the kinds above: c_void_p stands for any pointer, as C#'s IntPtr."""

    def kind(ctype: type | None) -> str:
        if ctype is None:
            return "void"
        if ctype is C.c_void_p:
            return "any"
        if ctype is C.c_char_p:
            return "ptr:u8"
        return PY_KINDS[ctype]

    return {
        name: (kind(restype), [kind(a) for a in argtypes])
        for name, (restype, argtypes) in native.SIGNATURES.items()
    }


def test_pythons_function_table_matches_the_headers_prototypes() -> None:
    declared = python_functions()
    assert "softdeca_avatar_set_parameter" in declared
    assert signature_problems(header_functions(), declared) == {}


def test_python_calls_no_function_outside_its_table() -> None:
    called = {
        m[1]
        for path in (ROOT / "training" / "softdeca_train").rglob("*.py")
        for m in re.finditer(r"\.(softdeca_\w+)\(", path.read_text(encoding="utf-8"))
    }
    header = header_functions()
    assert called & set(header), "no C ABI call found: the pattern is stale"
    assert sorted((called & set(header)) - set(native.SIGNATURES)) == []
