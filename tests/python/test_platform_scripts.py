"""The arm64 platforms' build scripts, checked as far as a Linux x86-64 machine allows.

Android arm64-v8a and iOS arm64 cannot be built here (no Android NDK, no Xcode); what can be
checked is that their scripts name files and targets that exist, and that the NEON kernels are
compiled by them: every `*_neon.cpp` is picked up by the library's source glob on every
platform, and its code is enabled by the macros both the NDK's and Apple's clang define for
arm64 (`make test-arm64` compiles it with clang for aarch64 as well).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PLATFORMS = REPO / "plugin" / "platforms"
SCRIPTS = [
    PLATFORMS / "android" / "build.sh",
    PLATFORMS / "ios" / "build.sh",
    PLATFORMS / "linux-arm64" / "setup-cross.sh",
]
REPO_PATH = re.compile(r"(?<![\w./$-])((?:plugin|cmake|training|tests)/[\w./-]*\w)")
NEON_GUARD = "defined(__aarch64__) && defined(__ARM_NEON)"


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.parent.name)
def test_scripts_name_files_that_exist(script: Path) -> None:
    text = script.read_text()
    named = set(REPO_PATH.findall(text))
    missing = sorted(p for p in named if not (REPO / p).exists())
    assert not missing, f"{script.relative_to(REPO)} names {missing}"
    assert (
        'source "$(dirname "$0")/../common.sh"' in text or "setup-cross" in script.name
    )


def test_the_scripts_build_targets_of_the_cmake_tree() -> None:
    cmake = (REPO / "plugin" / "CMakeLists.txt").read_text()
    android = (PLATFORMS / "android" / "build.sh").read_text()
    ios = (PLATFORMS / "ios" / "build.sh").read_text()
    assert "add_library(softdeca SHARED" in cmake
    assert "add_library(softdeca_core STATIC" in cmake
    assert "--target softdeca " in android and "-DANDROID_ABI=arm64-v8a" in android
    assert "--target softdeca_core" in ios and "-DCMAKE_OSX_ARCHITECTURES=arm64" in ios


def test_every_platform_compiles_the_neon_sources() -> None:
    cmake = (REPO / "plugin" / "CMakeLists.txt").read_text()
    assert (
        'GLOB_RECURSE SOFTDECA_SOURCES CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp"'
        in cmake
    )
    # The only filters are the platform files' suffixes: no NEON source is left out anywhere.
    filters = re.findall(
        r"list\(FILTER SOFTDECA_SOURCES EXCLUDE REGEX \"([^\"]+)\"\)", cmake
    )
    assert filters == ["_posix\\\\.cpp$", "_windows\\\\.cpp$"], filters
    sources = sorted((REPO / "plugin" / "src").rglob("*_neon.cpp"))
    assert sources, "no NEON sources"
    for source in sources:
        header = source.with_suffix(".h")
        assert header.exists(), f"{source.name} has no header"
        assert NEON_GUARD in header.read_text(), (
            f"{header.name}: not enabled by the arm64 macros"
        )
        assert "#ifdef SOFTDECA_NEON" in source.read_text()
    ldlt = REPO / "plugin" / "src" / "geometry" / "sparse_ldlt_neon.h"
    assert NEON_GUARD in ldlt.read_text()


def test_x86_intrinsics_are_included_only_on_x86() -> None:
    for source in (REPO / "plugin" / "src").rglob("*.[ch]*"):
        lines = source.read_text().splitlines()
        for i, line in enumerate(lines):
            if re.match(
                r"#include <(immintrin|xmmintrin|emmintrin|x86intrin)\.h>", line
            ):
                guard = "\n".join(lines[max(0, i - 3) : i])
                assert "__x86_64__" in guard, (
                    f"{source.relative_to(REPO)}:{i + 1} unguarded"
                )
