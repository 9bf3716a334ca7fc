"""The native library's layers (NATIVE_LAYERS): core/ below everything, the C ABI (api/) on
top, nothing below api/ including it, and every area including only areas of lower layers.
The import layer (plugin/import) below every host; the command line in by its documented way
(CLI_MAY_INCLUDE), its benchmarks (plugin/bench) by the same way and a few internals they
measure (BENCH_MAY_INCLUDE). The training package's layers: test_python_layering.py."""

from __future__ import annotations

import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "plugin" / "src"
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)


def local_includes(path: Path) -> list[str]:
    return INCLUDE.findall(path.read_text(encoding="utf-8"))


def sources(area: str | None = None) -> list[Path]:
    files = [p for p in SRC.rglob("*") if p.suffix in (".h", ".cpp")]
    return [p for p in files if area is None or p.relative_to(SRC).parts[0] == area]


def test_nothing_below_the_c_abi_includes_it() -> None:
    below = [p for p in sources() if p.relative_to(SRC).parts[0] != "api"]
    assert len(below) > 50
    offenders = [
        f"{p.relative_to(SRC)} includes {inc}"
        for p in below
        for inc in local_includes(p)
        if inc.startswith("api/")
    ]
    assert offenders == []


IMPORT = SRC.parent / "import"
CLI = SRC.parent / "cli"
BENCH = SRC.parent / "bench"


def files_of(folder: Path) -> list[Path]:
    return [p for p in folder.iterdir() if p.suffix in (".h", ".cpp")]


# What the import layer (plugin/import) may include: the library's lower areas it reads with
# (core's file opening and errors, the bundle's JSON parser and hash, the one rule for an
# avatar's values that the fit applies too), the public header for the names rule, and its own
# files; never the C ABI's internals or a host (the command line).
IMPORT_MAY_INCLUDE = (
    "core/",
    "bundle/json.h",
    "bundle/sha256.h",
    "fit/value_bounds.h",
    "softdeca/softdeca.h",
)


def test_the_import_layer_includes_no_host() -> None:
    files = files_of(IMPORT)
    own = {p.name for p in files}
    assert files
    offenders = [
        f"{p.name} includes {inc}"
        for p in files
        for inc in local_includes(p)
        if inc not in own and not inc.startswith(IMPORT_MAY_INCLUDE)
    ]
    assert offenders == []


def test_the_hosts_folders_share_no_file_name() -> None:
    """The import layer, the command line and its benchmarks include each other's headers by
    name alone (flat include folders), so a name must say which file it is."""
    folders = (IMPORT, CLI, BENCH)
    names = [{p.name for p in files_of(f)} for f in folders]
    assert all(names)
    for i, a in enumerate(folders):
        for j in range(i + 1, len(folders)):
            both = names[i] & names[j]
            assert not both, f"files in both {a.name} and {folders[j].name}: {both}"


# The command line's way into the library (docs/ARCHITECTURE.md, "Ways into the native
# library"): the C ABI for models, avatars and fits; the file and stream areas it is the tool
# for; the import layer; and the few internals its pictures use.
CLI_MAY_INCLUDE = (
    "softdeca/softdeca.h",
    "core/",
    "bundle/json.h",
    "recording/",
    "stream/",
    "live/",
    "fit/avatar_frame.h",
    "fit/limits.h",
    "geometry/surface_query.h",
)
# The bench-* commands (plugin/bench) come in as the command line does, built on its shared
# parts, and measure a few internals by name: a bundle's load and memory, and the core avatar
# the handle's template path is timed against. The physics' micro-benchmark
# (bench_physics.cpp) times the simulator itself.
BENCH_MAY_INCLUDE = (
    "runtime/model.h",
    "runtime/avatar.h",
    "bundle/bundle_files.h",
    "bundle/sha256.h",
)
PHYSICS_BENCH = "bench_physics.cpp"
PHYSICS_BENCH_MAY_INCLUDE = ("sim/",)


def include_offenders(
    files: list[Path], headers: set[str], allowed: tuple[str, ...]
) -> list[str]:
    return [
        f"{p.name} includes {inc}"
        for p in files
        for inc in local_includes(p)
        if inc not in headers and not inc.startswith(allowed)
    ]


def test_the_command_line_comes_in_by_its_documented_way() -> None:
    own = {p.name for p in files_of(CLI)}
    imported = {p.name for p in IMPORT.iterdir() if p.suffix == ".h"}
    files = files_of(CLI)
    assert len(files) > 20
    # never a benchmark's header: the command line lists the bench-* commands by their run_*
    assert include_offenders(files, own | imported, CLI_MAY_INCLUDE) == []
    # fitting and evaluating avatars: the C ABI's calls, never the runtime's classes
    for name in (
        "cmd_fit.cpp",
        "cmd_replay.cpp",
        "runtime_session.cpp",
        "replay_avatar.cpp",
    ):
        text = (CLI / name).read_text(encoding="utf-8")
        assert "runtime::" not in text and "fit::" not in text, name


def test_the_benchmarks_come_in_by_the_command_lines_way() -> None:
    files = files_of(BENCH)
    commands = [p for p in files if p.name != PHYSICS_BENCH]
    assert len(commands) > 10 and len(commands) < len(files)
    headers = {p.name for p in files_of(BENCH) + files_of(CLI)}
    headers |= {p.name for p in IMPORT.iterdir() if p.suffix == ".h"}
    allowed = CLI_MAY_INCLUDE + BENCH_MAY_INCLUDE
    assert include_offenders(commands, headers, allowed) == []
    physics = [p for p in files if p.name == PHYSICS_BENCH]
    assert include_offenders(physics, set(), PHYSICS_BENCH_MAY_INCLUDE) == []
    # bench-runtime times avatars as hosts make them: through the C ABI only
    text = (BENCH / "cmd_bench_runtime.cpp").read_text(encoding="utf-8")
    assert "runtime::" not in text and "fit::" not in text


def test_the_c_abi_has_one_avatar_whatever_its_mesh() -> None:
    """One avatar type behind the handle, one creation and one per-frame path: runtime_api.cpp
    never asks which kind of mesh an avatar has (a template-topology mesh is the identity fit,
    runtime/fitted_avatar.h)."""
    handles = (SRC / "api" / "runtime_handles.h").read_text(encoding="utf-8")
    body = re.search(r"struct softdeca_avatar \{(.*?)\};", handles, re.DOTALL)
    assert body, "runtime_handles.h defines no softdeca_avatar"
    members = [
        line for line in body.group(1).splitlines() if line.strip().endswith(";")
    ]
    assert len(members) == 1, members
    api = (SRC / "api" / "runtime_api.cpp").read_text(encoding="utf-8")
    decisions = [
        line.strip()
        for line in api.splitlines()
        if re.search(r"\b(if|while|switch)\s*\(| \? ", line)
    ]
    assert decisions, "no decision found: the search is broken"
    on_kind = [d for d in decisions if re.search(r"fit|identity|kind|template", d)]
    assert on_kind == [], on_kind


def test_every_avatar_runs_one_frame_path() -> None:
    """FittedAvatar's frames and maps are one path for every mesh: each applies the avatar's
    transfer (runtime/fit_transfer.h) and none asks which kind of mesh it has."""
    text = (SRC / "runtime" / "fitted_avatar.cpp").read_text(encoding="utf-8")
    # each definition from its first line to the closing brace at the start of a line
    definitions = re.findall(
        r"^[^\s/][^\n]*? FittedAvatar::(\w+)\((.*?)^\}", text, re.DOTALL | re.MULTILINE
    )
    per_call = {
        name: body
        for name, body in definitions
        if name.startswith(("evaluate_", "set_parameter_"))
    }
    assert len(per_call) == 6, sorted(per_call)
    deciding = [
        name
        for name, body in per_call.items()
        if re.search(r"\b(if|while|switch)\s*\(| \? ", body)
    ]
    assert deciding == [], deciding
    header = (SRC / "runtime" / "fitted_avatar.h").read_text(encoding="utf-8")
    assert not re.search(r"\bbool\s+\w*identity", header), "a flag for the identity fit"


def test_core_depends_on_nothing_but_the_public_header() -> None:
    core = sources("core")
    assert core
    for p in core:
        for inc in local_includes(p):
            assert inc.startswith("core/") or inc == "softdeca/softdeca.h", (
                f"{p.name}: {inc}"
            )


# The native areas (folders of plugin/src), bottom up. An area includes only areas of lower
# layers; areas of one layer are independent of each other.
NATIVE_LAYERS: tuple[tuple[str, ...], ...] = (
    # the error type, files, CPU features
    ("core",),
    # the per-frame CPU kernels and their buffers; frames and wire formats of face streams
    ("kernels", "stream"),
    # mesh maths: normals, similarity fits, the sparse LDL^T, nearest points, surface queries
    ("geometry",),
    # the physics simulator; reading and checking bundles; recording files of face streams
    ("sim", "bundle", "recording"),
    # what prepare reads: an avatar's parameter values and the physics at rest; the live
    # receiver that records what it delivers
    ("prepare", "live"),
    # fitting a user's head to the template
    ("fit",),
    # evaluating an avatar's frames
    ("runtime",),
    # the C ABI
    ("api",),
)


def test_native_areas_include_only_downwards() -> None:
    layer = {a: k for k, areas in enumerate(NATIVE_LAYERS) for a in areas}
    areas = sorted({p.relative_to(SRC).parts[0] for p in sources()})
    unplaced = sorted(set(areas) - set(layer))
    assert unplaced == [], f"areas without a layer in NATIVE_LAYERS: {unplaced}"
    offenders = [
        f"{p.relative_to(SRC)} includes {inc}"
        for p in sources()
        for inc in local_includes(p)
        if (target := inc.split("/")[0]) in layer
        and target != (area := p.relative_to(SRC).parts[0])
        and layer[target] >= layer[area]
    ]
    assert offenders == [], "includes of an area of the same or a higher layer"


# One namespace per area (docs/ARCHITECTURE.md, "Native code"): the code of plugin/src/<area>
# opens only softdeca::<area> and namespaces nested in it, but for two documented exceptions
# (AREA_NAMESPACE_EXCEPTIONS): core/ is `softdeca` itself, the vocabulary (Error, require, the
# file helpers, the CPU's features) that every area finds unqualified from inside softdeca::;
# api/'s exported functions are extern "C" at global scope, as the C header declares them, so its
# files may keep their file-local helpers beside them in an anonymous namespace.
AREA_NAMESPACE_EXCEPTIONS = {"core": ("softdeca",), "api": ("",)}
_CPP_TOKEN = re.compile(
    r"//[^\n]*|/\*.*?\*/|\"(?:\\.|[^\"\\\n])*\"|'(?:\\.|[^'\\\n])*'"
    r"|\bnamespace\b\s*([\w:]*)\s*([{=])|[{}]",
    re.DOTALL,
)


def opened_namespaces(text: str) -> list[tuple[str, int]]:
    """The full name and line of every namespace a C++ file opens; an anonymous namespace is
    named by the one it stands in ("" at global scope). Comments, strings and aliases
    (`namespace x = y;`) are skipped."""
    # per open brace: a namespace's full name, None for any other brace
    stack: list[str | None] = []
    out = []
    for m in _CPP_TOKEN.finditer(text):
        token = m.group(0)
        if token[0] in "/\"'" or m.group(2) == "=":
            continue
        if token == "{":
            stack.append(None)
        elif token == "}":
            stack.pop()
        else:
            outer = next((s for s in reversed(stack) if s is not None), "")
            full = "::".join(x for x in (outer, m.group(1)) if x)
            out.append((full, text.count("\n", 0, m.start()) + 1))
            stack.append(full)
    assert stack == [], "unbalanced braces: the scan is broken"
    return out


def namespace_offenders(area: str, name: str, text: str) -> list[str]:
    own = f"softdeca::{area}"
    allowed = AREA_NAMESPACE_EXCEPTIONS.get(area, ())
    return [
        f"{area}/{name}:{line} opens namespace {full or '(global anonymous)'}"
        for full, line in opened_namespaces(text)
        if full != own and not full.startswith(own + "::") and full not in allowed
    ]


def test_each_native_area_has_its_own_namespace() -> None:
    files = sources()
    opened = sum(len(opened_namespaces(p.read_text(encoding="utf-8"))) for p in files)
    assert opened > 300, "few namespaces found: the scan is broken"
    offenders = [
        o
        for p in files
        for o in namespace_offenders(
            p.relative_to(SRC).parts[0], p.name, p.read_text(encoding="utf-8")
        )
    ]
    assert offenders == [], "\n".join(offenders)
    # the check finds an area in another's namespace, and one nested in its own is fine
    sample = (
        "namespace softdeca::runtime {\nnamespace {\nint f() { return 1; }\n}\n}\n"
        "// namespace softdeca::bundle {\nnamespace softdeca::bundle::onnx { }\n"
        'const char* s = "namespace softdeca::prepare {";\nnamespace fs = std::filesystem;\n'
    )
    assert namespace_offenders("bundle", "x.h", sample) == [
        "bundle/x.h:1 opens namespace softdeca::runtime",
        "bundle/x.h:2 opens namespace softdeca::runtime",
    ]
    assert namespace_offenders("runtime", "x.h", sample) == [
        "runtime/x.h:7 opens namespace softdeca::bundle::onnx"
    ]
    assert namespace_offenders("core", "x.h", "namespace softdeca { }") == []
    assert namespace_offenders("stream", "x.h", "namespace softdeca { }") != []
    assert namespace_offenders("api", "x.cpp", "namespace { }") == []
    assert namespace_offenders("fit", "x.cpp", "namespace { }") != []
