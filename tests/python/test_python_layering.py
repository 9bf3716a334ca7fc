"""The training package's layers (PYTHON_LAYERS): no import cycle, areas importing only
downwards, and imports at module top but for a few explained ones. The native library's layers:
test_layering.py."""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

# The Python package's layers, bottom up. An area (a sub-package, or a module at the package's
# top) imports only areas of lower layers; areas of one layer are independent of each other.
PACKAGE = Path(__file__).resolve().parents[2] / "training" / "softdeca_train"
PYTHON_LAYERS: tuple[tuple[str, ...], ...] = (
    # helpers with no dependency inside the package: file locations, command declarations,
    # benchmark figures, geometry, mesh and glTF files, pictures
    ("paths", "commands", "bench", "geometry", "mesh_files", "gltf_writer", "render"),
    # the definitions the plugin shares (plugin/data) and the third-party data
    ("face_names", "parameters", "contact_rules", "third_party_data"),
    # the head template and its regions; the landmarks on it; the layered head model
    ("template",),
    ("landmarks",),
    # sample avatars: the template and ARKit's face in the conventions users' avatars come in
    ("sample_avatars",),
    ("lhm",),
    # face streams (live formats, recordings) in the template's terms
    ("streaming",),
    # the physics on a layered head model
    ("sim",),
    # training data simulated with it
    ("data",),
    # the bundle's networks and what the runtime needs of a head at rest
    ("models",),
    # the gallery of controls, measured on the physics and on bundles
    ("controls",),
    # training bundles; the host side of the native library (its ctypes binding, previews)
    ("train", "host"),
    # the command line over every stage
    ("cli",),
    ("__main__",),
)
# Command-line modules import their stage's modules inside each command, so that `--help`
# stays fast (softdeca_train/commands.py).
CLI_MODULES = ("cli", "stress_cli", "__main__")
# In-function imports of the package's own modules outside the command lines: only where a
# module must load without the compiled softdeca_native (or another heavy optional module).
MAX_LOCAL_OWN_IMPORTS = 20


@dataclass(frozen=True)
class PyImport:
    module: str  # the importing module
    target: str  # the imported module of the package
    line: int
    local: bool  # inside a function


def python_modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _imported_names(
    module: str, is_package: bool, node: ast.Import | ast.ImportFrom
) -> list[str]:
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    base = node.module or ""
    if node.level:
        parts = module.split(".")
        if not is_package:
            parts = parts[:-1]
        parts = parts[: len(parts) - (node.level - 1)]
        base = ".".join([*parts, *([node.module] if node.module else [])])
    return [f"{base}.{a.name}" for a in node.names]


def python_imports(modules: dict[str, Path]) -> list[PyImport]:
    """Every import of a module of the package, wherever it stands (module level, functions,
    TYPE_CHECKING blocks); importing a.b.c also runs the packages a.b and a, unless the
    importer lies inside them."""

    def known(name: str) -> str | None:
        parts = name.split(".")
        for n in range(len(parts), 0, -1):
            if ".".join(parts[:n]) in modules:
                return ".".join(parts[:n])
        return None

    out = []
    for module, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        in_function = {
            id(n)
            for f in ast.walk(tree)
            if isinstance(f, ast.FunctionDef | ast.AsyncFunctionDef)
            for n in ast.walk(f)
        }
        for node in ast.walk(tree):
            if not isinstance(node, ast.Import | ast.ImportFrom):
                continue
            for name in _imported_names(module, path.name == "__init__.py", node):
                target = known(name)
                if target is None or not name.startswith(PACKAGE.name):
                    continue
                parts = target.split(".")
                for n in range(len(parts), 1, -1):
                    parent = ".".join(parts[:n])
                    if parent != module and not module.startswith(parent + "."):
                        out.append(
                            PyImport(
                                module, parent, node.lineno, id(node) in in_function
                            )
                        )
    return out


def area(module: str) -> str:
    return module.split(".")[1] if "." in module else ""


def test_python_modules_import_no_cycle() -> None:
    modules = python_modules()
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for i in python_imports(modules):
        graph[i.module].add(i.target)
    assert sum(map(len, graph.values())) > 300
    cycles = strongly_connected(graph)
    assert cycles == [], (
        "modules that import each other (through any import):\n"
        + "\n".join(" <-> ".join(sorted(c)) for c in cycles)
    )


def strongly_connected(graph: dict[str, set[str]]) -> list[set[str]]:
    """Tarjan's components of more than one node (iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out = []
    for root, targets in graph.items():
        if root in index:
            continue
        work = [(root, iter(sorted(targets)))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, edges = work[-1]
            step = next(edges, None)
            if step is not None:
                if step not in index:
                    index[step] = low[step] = len(index)
                    stack.append(step)
                    on_stack.add(step)
                    work.append((step, iter(sorted(graph[step]))))
                elif step in on_stack:
                    low[node] = min(low[node], index[step])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.add(member)
                    if member == node:
                        break
                if len(component) > 1:
                    out.append(component)
    return out


def test_python_areas_import_only_downwards() -> None:
    layer = {a: k for k, areas in enumerate(PYTHON_LAYERS) for a in areas}
    modules = python_modules()
    unplaced = sorted({area(m) for m in modules if area(m)} - set(layer))
    assert unplaced == [], f"areas without a layer in PYTHON_LAYERS: {unplaced}"
    offenders = sorted(
        {
            f"{i.module}:{i.line} imports {i.target}"
            for i in python_imports(modules)
            if area(i.module)
            and area(i.target)
            and area(i.module) != area(i.target)
            and layer[area(i.target)] >= layer[area(i.module)]
        }
    )
    assert offenders == [], (
        "imports of an area of the same or a higher layer:\n" + "\n".join(offenders)
    )


def test_python_imports_inside_functions_are_few_and_explained() -> None:
    modules = python_modules()
    outside_cli = {
        m: p for m, p in modules.items() if m.split(".")[-1] not in CLI_MODULES
    }
    local_own = sorted(
        {(i.module, i.line) for i in python_imports(outside_cli) if i.local},
    )
    listing = "\n".join(f"  {m}:{line}" for m, line in local_own)
    print(
        f"{len(local_own)} in-function imports of the package's own modules:\n{listing}"
    )
    assert len(local_own) <= MAX_LOCAL_OWN_IMPORTS, listing
    unexplained = []
    for module, path in outside_cli.items():
        lines = path.read_text(encoding="utf-8").splitlines()
        for node, run_start in local_import_runs(ast.parse("\n".join(lines))):
            run = lines[run_start - 2 : node.end_lineno]
            if not any("#" in line for line in run):
                unexplained.append(f"{module}:{node.lineno}")
    assert unexplained == [], (
        "imports inside functions without a comment saying why (a heavy or optional "
        "dependency):\n" + "\n".join(unexplained)
    )


def local_import_runs(
    tree: ast.Module,
) -> list[tuple[ast.Import | ast.ImportFrom, int]]:
    """Each import inside a function with the first line of the run of imports it stands in
    (the comment that explains the run goes on the line above it or on one of its lines)."""
    out = []
    for f in ast.walk(tree):
        if not isinstance(f, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        for block in ast.walk(f):
            body = getattr(block, "body", None)
            if not isinstance(body, list) or (
                block is not f and isinstance(block, ast.FunctionDef)
            ):
                continue
            start = None
            for stmt in body:
                if isinstance(stmt, ast.Import | ast.ImportFrom):
                    start = stmt.lineno if start is None else start
                    out.append((stmt, start))
                else:
                    start = None
    return out
