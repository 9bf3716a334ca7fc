"""The native library's layers: core/ below everything, the C ABI (api/) on top, nothing below
api/ including it, and the streaming areas (stream/, recording/, live/) in one order."""

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


def test_core_depends_on_nothing_but_the_public_header() -> None:
    core = sources("core")
    assert core
    for p in core:
        for inc in local_includes(p):
            assert inc.startswith("core/") or inc == "softdeca/softdeca.h", (
                f"{p.name}: {inc}"
            )


# The streaming areas in their order, bottom up: frames and wire formats, the recording files
# built on them, the live receiver that records what it delivers. None includes one above it.
STREAMING_ORDER = ("stream", "recording", "live")


def test_streaming_areas_include_only_downwards() -> None:
    for below, area in enumerate(STREAMING_ORDER):
        files = sources(area)
        assert files, area
        above = STREAMING_ORDER[below + 1 :]
        offenders = [
            f"{p.relative_to(SRC)} includes {inc}"
            for p in files
            for inc in local_includes(p)
            if inc.split("/")[0] in above
        ]
        assert offenders == [], f"{area}/ includes an area above it"
