"""The Unity package's files that are generated, and its checks.

meta   write a .meta next to every file and folder of unity_package/ (not Documentation~),
       with a GUID derived from the package name and the path: the same on every run and
       machine, so references between assets stay valid. The importer follows the file kind.
scenes write the samples' scenes (one object holding the sample's script, by its GUID).
check  every file and folder has its .meta with the derived GUID (stable across runs), GUIDs
       are unique, asmdef references resolve, package.json is valid.
pack   stage the package with native binaries under Plugins/ (their importer settings in the
       .meta) and write a UPM tarball (`package/` prefix, as `npm pack` lays it out).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import re
import shutil
import sys
import tarfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "unity_package"
UNDOCUMENTED = {"Documentation~"}  # Unity never imports it: no metas
# Assemblies of Unity and its packages that asmdefs may name (by the package that provides them).
UNITY_ASSEMBLIES = {
    "Unity.Collections": "com.unity.collections",
    "Unity.XR.ARFoundation": "com.unity.xr.arfoundation",
    "Unity.XR.ARSubsystems": "com.unity.xr.arfoundation",
    "Unity.XR.ARKit": "com.unity.xr.arkit",
    "UnityEngine.TestRunner": "com.unity.test-framework",
    "UnityEditor.TestRunner": "com.unity.test-framework",
}


@dataclass(frozen=True)
class Plugin:
    """Importer settings of one native binary under Plugins/."""

    path: str  # relative to the package
    platform: str  # Unity's platform name
    cpu: str
    editor_os: str | None  # the editor that loads it, or None


PLUGINS = [
    Plugin("Plugins/Linux/x86_64/libsoftdeca.so", "Linux64", "x86_64", "Linux"),
    Plugin("Plugins/Linux/x86_64/libonnxruntime.so.1", "Linux64", "x86_64", "Linux"),
    Plugin("Plugins/Windows/x86_64/softdeca.dll", "Win64", "x86_64", "Windows"),
    Plugin("Plugins/Windows/x86_64/onnxruntime.dll", "Win64", "x86_64", "Windows"),
    Plugin("Plugins/macOS/softdeca.bundle", "OSXUniversal", "AnyCPU", "OSX"),
    Plugin("Plugins/iOS/libsoftdeca.a", "iOS", "AnyCPU", None),
    Plugin("Plugins/Android/arm64-v8a/libsoftdeca.so", "Android", "ARM64", None),
    Plugin("Plugins/Android/arm64-v8a/libonnxruntime.so", "Android", "ARM64", None),
]


def guid(relative: str) -> str:
    return hashlib.md5(f"com.softdeca.facial-animation/{relative}".encode()).hexdigest()


def meta_text(relative: str, is_dir: bool) -> str:
    head = f"fileFormatVersion: 2\nguid: {guid(relative)}\n"
    if is_dir:
        return (
            head
            + "folderAsset: yes\nDefaultImporter:\n  externalObjects: {}\n  userData: \n"
        )
    plugin = next((p for p in PLUGINS if p.path == relative), None)
    if plugin is not None:
        return head + plugin_importer(plugin)
    suffix = Path(relative).suffix
    if suffix == ".cs":
        return head + (
            "MonoImporter:\n  externalObjects: {}\n  serializedVersion: 2\n  defaultReferences: []\n"
            "  executionOrder: 0\n  icon: {instanceID: 0}\n  userData: \n"
        )
    if suffix == ".asmdef":
        return (
            head + "AssemblyDefinitionImporter:\n  externalObjects: {}\n  userData: \n"
        )
    if relative == "package.json":
        return head + "PackageManifestImporter:\n  externalObjects: {}\n  userData: \n"
    if suffix in (".md", ".txt", ".json"):
        return head + "TextScriptImporter:\n  externalObjects: {}\n  userData: \n"
    return head + "DefaultImporter:\n  externalObjects: {}\n  userData: \n"


def plugin_importer(p: Plugin) -> str:
    """A PluginImporter enabled for its platform (and its editor), excluded from the others."""
    lines = [
        "PluginImporter:",
        "  externalObjects: {}",
        "  serializedVersion: 2",
        "  iconMap: {}",
        "  executionOrder: {}",
        "  defineConstraints: []",
        "  isPreloaded: 0",
        "  isOverridable: 0",
        "  isExplicitlyReferenced: 0",
        "  validateReferences: 1",
        "  platformData:",
        "  - first:",
        "      Any: ",
        "    second:",
        "      enabled: 0",
        "      settings: {}",
        "  - first:",
        "      Editor: Editor",
        "    second:",
        f"      enabled: {1 if p.editor_os else 0}",
        "      settings:",
        f"        CPU: {p.cpu if p.editor_os else 'AnyCPU'}",
        f"        OS: {p.editor_os or 'AnyOS'}",
        "  - first:",
        f"      {'Standalone' if p.platform in ('Linux64', 'Win64', 'OSXUniversal') else p.platform}: {p.platform}",
        "    second:",
        "      enabled: 1",
        "      settings:",
        f"        CPU: {p.cpu}",
    ]
    if p.platform == "iOS":
        lines.append("        AddToEmbeddedBinaries: false")
    return "\n".join(lines) + "\n  userData: \n"


def plugin_entries() -> list[tuple[str, bool]]:
    """The native binaries under Plugins/ and their folders: their .meta files (importer settings)
    are committed; the binaries are build outputs placed there when the package is packed."""
    out: dict[str, bool] = {}
    for p in PLUGINS:
        parts = p.path.split("/")
        for i in range(1, len(parts)):
            out["/".join(parts[:i])] = True
        out[p.path] = False
    return sorted(out.items())


def package_entries(root: Path) -> list[tuple[str, bool]]:
    """(relative path, is folder) of everything that needs a .meta: the package's files and
    folders, and the Plugins/ layout whether or not its binaries are there."""
    out = dict(plugin_entries())
    for path in sorted(root.rglob("*")):
        rel = path.relative_to(root)
        if (
            rel.parts[0] in UNDOCUMENTED
            or path.suffix == ".meta"
            or path.name.startswith(".")
        ):
            continue
        if path.name.endswith(
            "~"
        ):  # Samples~ itself: Unity ignores it; its contents are imported on demand
            continue
        out[rel.as_posix()] = path.is_dir()
    return sorted(out.items())


def write_metas(root: Path) -> int:
    n = 0
    for rel, is_dir in package_entries(root):
        if is_dir:
            (root / rel).mkdir(parents=True, exist_ok=True)
        (root / f"{rel}.meta").write_text(meta_text(rel, is_dir))
        n += 1
    return n


SCENES = {
    "Samples~/LiveARKit/LiveARKit.unity": "Samples~/LiveARKit/LiveARKitSample.cs",
    "Samples~/NetworkReceiver/NetworkReceiver.unity": "Samples~/NetworkReceiver/NetworkReceiverSample.cs",
    "Samples~/RecordingReplay/RecordingReplay.unity": "Samples~/RecordingReplay/RecordingReplaySample.cs",
}


def scene_text(script: str) -> str:
    """A scene with a camera and one object holding the sample's script."""
    name = Path(script).stem
    return f"""%YAML 1.1
%TAG !u! tag:unity3d.com,2011:
--- !u!1 &100
GameObject:
  m_ObjectHideFlags: 0
  serializedVersion: 6
  m_Component:
  - component: {{fileID: 101}}
  - component: {{fileID: 102}}
  m_Layer: 0
  m_Name: Main Camera
  m_TagString: MainCamera
  m_IsActive: 1
--- !u!4 &101
Transform:
  m_ObjectHideFlags: 0
  m_GameObject: {{fileID: 100}}
  m_LocalRotation: {{x: 0, y: 1, z: 0, w: 0}}
  m_LocalPosition: {{x: 0, y: 0, z: 0.5}}
  m_LocalScale: {{x: 1, y: 1, z: 1}}
  m_Children: []
  m_Father: {{fileID: 0}}
--- !u!20 &102
Camera:
  m_ObjectHideFlags: 0
  m_GameObject: {{fileID: 100}}
  m_Enabled: 1
  near clip plane: 0.01
  far clip plane: 100
  field of view: 30
--- !u!1 &200
GameObject:
  m_ObjectHideFlags: 0
  serializedVersion: 6
  m_Component:
  - component: {{fileID: 201}}
  - component: {{fileID: 202}}
  m_Layer: 0
  m_Name: {name}
  m_IsActive: 1
--- !u!4 &201
Transform:
  m_ObjectHideFlags: 0
  m_GameObject: {{fileID: 200}}
  m_LocalRotation: {{x: 0, y: 0, z: 0, w: 1}}
  m_LocalPosition: {{x: 0, y: 0, z: 0}}
  m_LocalScale: {{x: 1, y: 1, z: 1}}
  m_Children: []
  m_Father: {{fileID: 0}}
--- !u!114 &202
MonoBehaviour:
  m_ObjectHideFlags: 0
  m_GameObject: {{fileID: 200}}
  m_Enabled: 1
  m_Script: {{fileID: 11500000, guid: {guid(script)}, type: 3}}
  m_Name:
"""


def write_scenes(root: Path) -> None:
    for scene, script in SCENES.items():
        (root / scene).write_text(scene_text(script))


def check(root: Path) -> list[str]:
    problems: list[str] = []
    seen: dict[str, str] = {}
    entries = package_entries(root)
    for rel, is_dir in entries:
        meta = root / f"{rel}.meta"
        if not meta.is_file():
            problems.append(f"{rel}: no .meta")
            continue
        m = re.search(r"^guid: ([0-9a-f]{32})$", meta.read_text(), re.MULTILINE)
        if not m:
            problems.append(f"{rel}.meta: no guid")
            continue
        if m.group(1) != guid(rel):
            problems.append(
                f"{rel}.meta: guid {m.group(1)} is not the derived {guid(rel)} (run `package.py meta`)"
            )
        if m.group(1) in seen:
            problems.append(f"{rel}.meta: guid also used by {seen[m.group(1)]}")
        seen[m.group(1)] = rel
        if meta.read_text() != meta_text(rel, is_dir):
            problems.append(f"{rel}.meta: differs from what `package.py meta` writes")
    known = {rel for rel, _ in entries}
    for meta in root.rglob("*.meta"):
        rel = meta.relative_to(root).as_posix()[: -len(".meta")]
        if rel not in known and not rel.endswith("~"):
            problems.append(f"{rel}.meta: no such file or folder")
    problems += check_manifest(root)
    problems += check_asmdefs(root)
    for scene, script in SCENES.items():
        if (root / scene).is_file() and (root / scene).read_text() != scene_text(
            script
        ):
            problems.append(f"{scene}: differs from what `package.py scenes` writes")
    return problems


def check_manifest(root: Path) -> list[str]:
    try:
        manifest = json.loads((root / "package.json").read_text())
    except (OSError, json.JSONDecodeError) as e:
        return [f"package.json: {e}"]
    problems = []
    if not re.fullmatch(
        r"com\.[a-z0-9-]+(\.[a-z0-9-]+)+", str(manifest.get("name", ""))
    ):
        problems.append(
            "package.json: name must be reverse-domain lower case (com.company.package)"
        )
    if not re.fullmatch(
        r"\d+\.\d+\.\d+(-[0-9A-Za-z.-]+)?", str(manifest.get("version", ""))
    ):
        problems.append("package.json: version must be semantic (MAJOR.MINOR.PATCH)")
    if not re.fullmatch(r"\d{4}\.\d+", str(manifest.get("unity", ""))):
        problems.append("package.json: unity must be YEAR.MINOR")
    for key in ("displayName", "description"):
        if not manifest.get(key):
            problems.append(f"package.json: {key} is missing")
    for dep, version in manifest.get("dependencies", {}).items():
        if not re.fullmatch(r"\d+\.\d+\.\d+(-[0-9A-Za-z.-]+)?", str(version)):
            problems.append(f"package.json: dependency {dep} has version {version!r}")
    for sample in manifest.get("samples", []):
        if not (root / sample.get("path", "")).is_dir():
            problems.append(
                f"package.json: sample path {sample.get('path')!r} is not a folder"
            )
    return problems


def check_asmdefs(root: Path) -> list[str]:
    problems = []
    asmdefs = {}
    for path in root.rglob("*.asmdef"):
        try:
            asmdefs[path] = json.loads(path.read_text())
        except json.JSONDecodeError as e:
            problems.append(f"{path.relative_to(root)}: {e}")
    names = {a.get("name") for a in asmdefs.values()}
    if len(names) != len(asmdefs):
        problems.append("two asmdefs share a name")
    for path, a in asmdefs.items():
        rel = path.relative_to(root)
        for ref in a.get("references", []):
            if ref not in names and ref not in UNITY_ASSEMBLIES:
                problems.append(
                    f"{rel}: reference {ref!r} is neither a package assembly nor a known Unity one"
                )
        for vd in a.get("versionDefines", []):
            if vd.get("name") not in set(UNITY_ASSEMBLIES.values()):
                problems.append(
                    f"{rel}: versionDefine on unknown package {vd.get('name')!r}"
                )
    return problems


def pack(root: Path, binaries: Path, out: Path) -> Path:
    """Copies the package, adds the binaries found under binaries/<Plugins path>, writes metas, tars."""
    stage = out.parent / "unity-package-stage"
    shutil.rmtree(stage, ignore_errors=True)
    shutil.copytree(root, stage)
    added = []
    for p in PLUGINS:
        src = binaries / p.path
        if src.exists():
            dst = stage / p.path
            dst.parent.mkdir(parents=True, exist_ok=True)
            (shutil.copytree if src.is_dir() else shutil.copy2)(src, dst)
            added.append(p.path)
    if not added:
        raise SystemExit(f"pack: no native binary under {binaries}/Plugins")
    write_metas(stage)
    problems = check(stage)
    if problems:
        raise SystemExit("pack: " + "; ".join(problems))
    out.parent.mkdir(parents=True, exist_ok=True)
    with tarfile.open(out, "w:gz") as tar:
        for path in sorted(stage.rglob("*")):
            if path.is_file():
                info = tar.gettarinfo(
                    str(path), "package/" + path.relative_to(stage).as_posix()
                )
                info.uid = info.gid = 0
                info.uname = info.gname = ""
                info.mtime = 0
                with path.open("rb") as f:
                    tar.addfile(info, f)
    print(f"{out}: {', '.join(added)}")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = ap.add_subparsers(dest="command", required=True)
    sub.add_parser("meta", help="write every .meta (deterministic GUIDs)")
    sub.add_parser("scenes", help="write the samples' scenes")
    sub.add_parser(
        "check", help="check metas, GUIDs, asmdef references and package.json"
    )
    p = sub.add_parser("pack", help="write a UPM tarball with native binaries")
    p.add_argument(
        "--binaries",
        type=Path,
        required=True,
        help="folder holding Plugins/<platform>/... binaries",
    )
    p.add_argument("--out", type=Path, required=True, help="the .tgz to write")
    args = ap.parse_args(argv)
    if args.command == "meta":
        print(f"wrote {write_metas(PACKAGE)} .meta files")
    elif args.command == "scenes":
        write_scenes(PACKAGE)
    elif args.command == "check":
        problems = check(PACKAGE)
        for line in problems:
            print(line, file=sys.stderr)
        n = len(package_entries(PACKAGE))
        print(
            f"unity package check: {n} files and folders, "
            + ("OK" if not problems else f"{len(problems)} problems")
        )
        return 1 if problems else 0
    else:
        pack(PACKAGE, args.binaries, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
