"""No function over MAX_LINES lines in the C++ and Python sources unless a comment just above it
says why it must be one (a line starting `Kept whole:`). Long functions are split into named
steps; the few that read better whole say so where they are defined. Likewise no source file
over MAX_FILE_LINES lines unless its opening comment says why it is one file (`Kept whole:`).

Run as a script to list every long function: `python tests/python/test_function_length.py`."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MAX_LINES = 120
MAX_FILE_LINES = 500
FILE_SUFFIXES = (".py", ".cpp", ".h", ".cs", ".swift", ".c")
MARKER = re.compile(r"^\s*(//|#)\s*Kept whole:", re.IGNORECASE)
CPP_SUFFIXES = (".cpp", ".h", ".hpp", ".cc", ".mm")

# Long functions let through without a `Kept whole:` reason (none: every long function says
# why). The test fails when an entry is no longer long, so the list never hides anything.
ALLOWED: set[str] = set()

CONTROL = re.compile(
    r"\b(if|for|while|switch|catch|do|else|return|sizeof|alignof|decltype)\s*$"
)
CONTAINER = re.compile(r"\b(namespace|class|struct|union|enum)\b|extern\s+\"C\"")


@dataclass(frozen=True)
class Function:
    path: str
    name: str
    line: int
    length: int
    explained: bool

    @property
    def key(self) -> str:
        return f"{self.path}:{self.name}"


def tracked(suffixes: tuple[str, ...]) -> list[Path]:
    out = subprocess.run(
        ["git", "ls-files", "-co", "--exclude-standard"],
        cwd=ROOT,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    files = [ROOT / line for line in out.splitlines() if line.endswith(suffixes)]
    return [p for p in files if p.is_file()]


def explained(lines: list[str], first: int) -> bool:
    """A `Kept whole:` comment in the comment block (or decorators) right above line `first`."""
    i = first - 1
    while i >= 0 and i >= first - 12:
        text = lines[i].strip()
        if MARKER.match(lines[i]):
            return True
        if not (text.startswith(("//", "#", "@", "template")) or text == ""):
            return False
        i -= 1
    return False


def strip_cpp(text: str) -> str:
    """The source with comments, strings and character literals blanked (newlines kept)."""
    out: list[str] = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "R" and text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + (m.group(1) if m else "") + '"', i)
            j = n if end < 0 else end + len(m.group(1) if m else "") + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (min(j + 1, n) - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def cpp_functions(path: Path, root: Path = ROOT) -> list[Function]:
    raw = path.read_text(encoding="utf-8", errors="replace")
    lines = raw.splitlines()
    code = strip_cpp(raw)
    rel = path.relative_to(root).as_posix()
    found: list[Function] = []
    # Each open brace: "container" (namespace, class, ...), "function" or "other".
    stack: list[tuple[str, int, str, int]] = []  # kind, open line, name, head line
    head_start = 0  # offset where the current declaration head begins
    line = 1
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c in ";":
            head_start = i + 1
        elif c == "{":
            head = code[head_start:i]
            kind, name = "other", ""
            inside_function = any(k == "function" for k, *_ in stack)
            flat = re.sub(
                r"\s+", " ", re.sub(r"^\s*#.*$", "", head, flags=re.MULTILINE)
            ).strip()
            if not inside_function and (not stack or stack[-1][0] == "container"):
                if (
                    CONTAINER.search(flat)
                    and "(" not in flat.split("{")[0].split(":")[0]
                ):
                    kind = "container"
                else:
                    m = re.search(r"([~\w:]+|operator\s*\S+)\s*\((?:.*)\)[^()]*$", flat)
                    call = flat[: m.start()] if m else ""
                    if m and not CONTROL.search(call) and "=" not in flat.split("(")[0]:
                        kind, name = "function", m.group(1).split("::")[-1]
            first = code.count("\n", 0, head_start + len(head) - len(head.lstrip())) + 1
            stack.append((kind, line, name, first))
            head_start = i + 1
        elif c == "}":
            if stack:
                kind, _, name, first = stack.pop()
                if kind == "function":
                    found.append(
                        Function(
                            rel,
                            name,
                            first,
                            line - first + 1,
                            explained(lines, first - 1),
                        )
                    )
            head_start = i + 1
    return found


def py_functions(path: Path) -> list[Function]:
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    rel = path.relative_to(ROOT).as_posix()
    out: list[Function] = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            first = min([node.lineno] + [d.lineno for d in node.decorator_list])
            length = (node.end_lineno or node.lineno) - node.lineno + 1
            out.append(
                Function(
                    rel, node.name, node.lineno, length, explained(lines, first - 1)
                )
            )
    return out


def all_functions() -> list[Function]:
    return [f for p in tracked(CPP_SUFFIXES) for f in cpp_functions(p)] + [
        f for p in tracked((".py",)) for f in py_functions(p)
    ]


def long_functions() -> list[Function]:
    return sorted(
        (f for f in all_functions() if f.length > MAX_LINES),
        key=lambda f: -f.length,
    )


def test_the_scanner_finds_functions_and_their_length(tmp_path: Path) -> None:
    src = tmp_path / "x.cpp"
    body = "\n".join(f"  int v{i} = {i};" for i in range(5))
    src.write_text(
        "namespace a {\nstruct S {\n  int f() const {\n    return 1;\n  }\n};\n"
        f"// Kept whole: a table.\nint g(int x)\n{{\n{body}\n  if (x) {{ return 2; }}\n"
        '  const char* s = "}";\n  return 0;\n}\n}  // namespace a\n'
    )
    functions = cpp_functions(src, tmp_path)
    assert [(f.name, f.length, f.explained) for f in functions] == [
        ("f", 3, False),
        ("g", 11, True),
    ]


def test_no_long_function_without_a_reason() -> None:
    functions = all_functions()
    assert len(functions) > 500  # the scanner sees the code base
    offenders = [
        f"{f.path}:{f.line} {f.name} ({f.length} lines)"
        for f in long_functions()
        if not f.explained and f.key not in ALLOWED
    ]
    assert offenders == [], "split these into named steps, or say why one is kept whole"


def test_the_allow_list_holds_only_long_functions() -> None:
    long = {f.key for f in long_functions()}
    assert sorted(ALLOWED - long) == [], "no longer long: remove from ALLOWED"


def file_explained(path: Path) -> bool:
    """A `Kept whole:` line in the file's opening comment (its first 40 lines)."""
    head = path.read_text(encoding="utf-8", errors="replace").splitlines()[:40]
    return any(re.search(r"(//|#|\*|^)\s*Kept whole:", line) for line in head)


def long_files() -> list[tuple[str, int]]:
    out = []
    for p in tracked(FILE_SUFFIXES):
        n = len(p.read_text(encoding="utf-8", errors="replace").splitlines())
        if n > MAX_FILE_LINES and not file_explained(p):
            out.append((p.relative_to(ROOT).as_posix(), n))
    return out


def test_no_long_file_without_a_reason() -> None:
    assert len(tracked(FILE_SUFFIXES)) > 300
    assert long_files() == [], (
        "split these, or say in the opening comment why one is one file"
    )


def test_a_long_file_is_found_and_its_reason_read(tmp_path: Path) -> None:
    long = tmp_path / "long.py"
    long.write_text('"""A module."""\n' + "x = 1\n" * (MAX_FILE_LINES + 1))
    assert not file_explained(long)
    long.write_text('"""A module.\n\nKept whole: one table."""\n' + "x = 1\n" * 600)
    assert file_explained(long)


if __name__ == "__main__":
    for f in long_functions():
        note = (
            "kept whole"
            if f.explained
            else ("allowed" if f.key in ALLOWED else "TOO LONG")
        )
        print(f"{f.length:5d}  {f.path}:{f.line}  {f.name}  [{note}]")
    sys.exit(0)
