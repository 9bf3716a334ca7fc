"""The Unity package's native binaries as `make unity-package` stages them (Linux part).

plugin/platforms/stage-unity-binaries.sh copies the release build's libsoftdeca.so and ONNX
Runtime's library into Plugins/Linux/x86_64/; the library must load from there alone (RUNPATH
$ORIGIN, not the build tree), and the packed tarball must have Unity's layout (`package/` at the
top, package.json, the binaries with their importer .meta files).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BUILD = REPO / "build" / "release"
ORT = REPO / ".deps" / "onnxruntime"
STAGE = REPO / "plugin" / "platforms" / "stage-unity-binaries.sh"
PACKAGE_TOOL = REPO / "tests" / "unity" / "package.py"
PLUGINS = Path("Plugins/Linux/x86_64")


@pytest.fixture(scope="module")
def staged(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if not (BUILD / "build.ninja").exists():
        pytest.fail(f"no release build in {BUILD}: run `make build`")
    out = tmp_path_factory.mktemp("unity-binaries")
    run = subprocess.run(
        [str(STAGE), "linux", str(BUILD), str(ORT), str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    return out


def test_stages_the_library_and_onnxruntime_side_by_side(staged: Path) -> None:
    names = sorted(p.name for p in (staged / PLUGINS).iterdir())
    assert names[0] == "libonnxruntime.so.1", names
    assert names[1:] == ["libsoftdeca.so"], names
    dynamic = subprocess.run(
        ["readelf", "-d", str(staged / PLUGINS / "libsoftdeca.so")],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    runpaths = [
        line for line in dynamic.splitlines() if "RUNPATH" in line or "RPATH" in line
    ]
    assert runpaths and all("[$ORIGIN]" in line for line in runpaths), runpaths


def test_staged_library_loads_from_its_folder_alone(staged: Path) -> None:
    """A fresh interpreter with no library path loads it and calls into ONNX Runtime's side."""
    lib = staged / PLUGINS / "libsoftdeca.so"
    code = (
        "import ctypes, sys\n"
        f"lib = ctypes.CDLL({str(lib)!r})\n"
        "lib.softdeca_version.restype = ctypes.c_char_p\n"
        "print(lib.softdeca_version().decode())\n"
        "maps = open('/proc/self/maps').read()\n"
        "ort = [l.split()[-1] for l in maps.splitlines() if 'libonnxruntime' in l]\n"
        "print(ort[0])\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
    run = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env=env,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    version, ort_path = run.stdout.split()
    assert version.count(".") == 2
    assert Path(ort_path).parent == staged / PLUGINS


def test_tarball_has_unity_layout(staged: Path, tmp_path: Path) -> None:
    if not PACKAGE_TOOL.exists():
        pytest.skip(
            f"{PACKAGE_TOOL.relative_to(REPO)} (the package's pack tool) is not in this checkout"
        )
    tgz = tmp_path / "package.tgz"
    run = subprocess.run(
        [
            sys.executable,
            str(PACKAGE_TOOL),
            "pack",
            "--binaries",
            str(staged),
            "--out",
            str(tgz),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    with tarfile.open(tgz) as tar:
        names = set(tar.getnames())
    assert all(n.startswith("package/") for n in names), sorted(names)[:5]
    assert "package/package.json" in names
    for lib in ("libsoftdeca.so", "libonnxruntime.so.1"):
        assert f"package/{PLUGINS}/{lib}" in names
        assert f"package/{PLUGINS}/{lib}.meta" in names
