"""Hostile avatar files for `softdeca fit` and `softdeca replay --avatar` (docs/security.md,
"Avatars and fits"): every attack a folder of small files built on the runtime tests' synthetic
head, which fits the runtime tests' bundle as it is (the control attacks), so that a refusal
is the attack's and not the fit's. A manifest, corpus.json, lists each attack with what the
command is given; tests/python/test_hostile_avatars.py runs them and `softdeca
bench-reliability --import-corpus` measures the memory of each import.

Attacks that name a file outside their avatar's folder place a secret file there, whose bytes
must never be read; FIFOs are made where a file should be (nobody writes to them).

Kept whole: the corpus is one list: each attack beside the file it writes."""

from __future__ import annotations

import json
import os
import stat
import struct
import zlib
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from softdeca_train.gltf_writer import GltfWriter
from softdeca_train.host.files import write_rig
from softdeca_train.mesh_files import write_obj
from softdeca_train.models.synthetic import synthetic_head
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

# Bytes no output may ever hold: every secret file starts with them.
SECRET = b"SOFTDECA-SECRET-7f3a: never read through an avatar\n"
# The arguments every run of an attack is given besides its own: the synthetic head is in metres.
BASE_ARGS = ("--metres-per-unit", "1")


@dataclass
class Attack:
    name: str
    command: (
        str  # "fit" (then also replay, which fits first) or "replay" (the avatar only replay opens)
    )
    avatar: str  # MESH / --avatar, relative to the corpus folder
    args: list[str] = field(default_factory=list)  # instead of BASE_ARGS where set
    input_bytes: int = 0  # bytes of the files the attack hands over (not its secret)
    secret: str = ""  # a file outside the avatar's folder, relative to the corpus folder
    control: bool = False  # the unchanged avatar: fits and replays


@dataclass
class Head:
    vertices: np.ndarray  # N x 3 float32, metres
    triangles: np.ndarray  # T x 3 uint32
    deltas: np.ndarray  # 52 x N x 3 float32
    user_vertices: np.ndarray
    user_deltas: np.ndarray


def load_head() -> Head:
    h = synthetic_head()
    return Head(
        np.asarray(h.neutral, np.float32),
        np.asarray(h.head_triangles, np.uint32),
        np.asarray(h.blendshapes, np.float32),
        np.asarray(h.user_neutral, np.float32),
        np.asarray(h.user_deltas, np.float32),
    )


# ---- glTF 2.0 -----------------------------------------------------------------------------


class Gltf(GltfWriter):
    """The writer with whole meshes as the attacks start from them."""

    def mesh(self, name: str, vertices: np.ndarray, triangles: np.ndarray, shapes: dict) -> int:
        """A mesh with its morph targets (named in extras.targetNames), used by a new node of
        the scene; returns the mesh's index."""
        position = self.vec3(vertices)
        targets = [{"POSITION": self.vec3(d)} for d in shapes.values()]
        primitive = {"attributes": {"POSITION": position}, "indices": self.indices(triangles)}
        primitive["mode"] = 4
        if targets:
            primitive["targets"] = targets
        return self.add_mesh(
            {"name": name, "primitives": [primitive], "extras": {"targetNames": list(shapes)}}
        )


def head_gltf(
    head: Head, vertices: np.ndarray | None = None, deltas: np.ndarray | None = None
) -> Gltf:
    """The head (or its triangles over other vertices and shapes) as a glTF mesh."""
    v = head.vertices if vertices is None else vertices
    d = head.deltas if deltas is None else deltas
    g = Gltf()
    g.mesh("Head", v, head.triangles, dict(zip(ARKIT_BLENDSHAPES, d, strict=True)))
    return g


# ---- FBX ----------------------------------------------------------------------------------


def _fbx_string(text: bytes) -> bytes:
    return b"S" + struct.pack("<I", len(text)) + text


def _fbx_array(code: bytes, fmt: str, values: np.ndarray, compressed: bool = False) -> bytes:
    raw = np.ascontiguousarray(values, fmt).tobytes()
    data = zlib.compress(raw) if compressed else raw
    return code + struct.pack("<III", len(values), int(compressed), len(data)) + data


def _fbx_put(out: bytearray, name: bytes, props: list[bytes], children: list) -> None:
    """One node of a binary FBX 7.4 file at the end of `out` (offsets are absolute)."""
    start = len(out)
    out += b"\0" * 13 + name + b"".join(props)
    for child in children:
        _fbx_put(out, *child)
    if children:
        out += b"\0" * 13
    struct.pack_into("<IIIB", out, start, len(out), len(props), sum(map(len, props)), len(name))


def fbx_binary(nodes: list) -> bytearray:
    out = bytearray(b"Kaydara FBX Binary  \0\x1a\0" + struct.pack("<I", 7400))
    for node in nodes:
        _fbx_put(out, *node)
    return out + b"\0" * 13


def _fbx_header() -> tuple:
    version = (b"FBXVersion", [b"I" + struct.pack("<i", 7400)], [])
    return (b"FBXHeaderExtension", [], [version])


def fbx_mesh(vertices: np.ndarray, triangles: np.ndarray, compressed_vertices: bytes = b"") -> list:
    """A Mesh geometry under a Model, connected to the scene's root; `compressed_vertices`
    replaces the Vertices array property."""
    polygons = np.asarray(triangles, np.int32).copy()
    polygons[:, 2] = ~polygons[:, 2]  # a polygon's last corner, negated
    points = compressed_vertices or _fbx_array(
        b"d", "<f8", np.asarray(vertices, np.float64).ravel()
    )
    geometry = (
        b"Geometry",
        [b"L" + struct.pack("<q", 2), _fbx_string(b"Head\0\x01Geometry"), _fbx_string(b"Mesh")],
        [
            (b"Vertices", [points], []),
            (b"PolygonVertexIndex", [_fbx_array(b"i", "<i4", polygons.ravel())], []),
        ],
    )
    model = (
        b"Model",
        [b"L" + struct.pack("<q", 1), _fbx_string(b"Head\0\x01Model"), _fbx_string(b"Mesh")],
        [(b"Version", [b"I" + struct.pack("<i", 232)], [])],  # assimp skips a Model without one
    )

    def connect(child: int, parent: int) -> tuple:
        return (
            b"C",
            [_fbx_string(b"OO"), b"L" + struct.pack("<q", child), b"L" + struct.pack("<q", parent)],
            [],
        )

    return [
        _fbx_header(),
        (b"Objects", [], [geometry, model]),
        (b"Connections", [], [connect(1, 0), connect(2, 1)]),
    ]


def fbx_binary_nested(depth: int) -> bytes:
    """Nodes nested `depth` deep under the header (written without recursion)."""
    out = fbx_binary([_fbx_header()])[:-13]
    base, record = len(out), 14  # 13 header bytes and the one-letter name
    inner_end = base + record * depth
    chain = bytearray(record * depth + 13 * (depth - 1))
    for k in range(depth):
        end = inner_end + 13 * (depth - 1 - k)
        struct.pack_into("<IIIBc", chain, record * k, end, 0, 0, 1, b"N")
    return bytes(out + chain + b"\0" * 13)


def fbx_ascii_nested(depth: int) -> bytes:
    head = b"; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXVersion: 7400\n}\nObjects:  {\n"
    return head + b"N: {\n" * depth + b"}\n" * depth + b"}\n"


def fbx_zlib_bomb(head: Head, inflated_bytes: int) -> bytes:
    """The head's mesh whose Vertices array, compressed, inflates to about `inflated_bytes` of
    zeros (and says it holds that many doubles: whole vertices, or assimp skips the mesh)."""
    count = inflated_bytes // 24 * 3
    inflated_bytes = 8 * count
    z = zlib.compressobj(1)  # zeros compress about 230:1 even so, and in a fraction of the time
    chunk = bytes(64 << 20)
    data = b"".join(z.compress(chunk) for _ in range(inflated_bytes // len(chunk)))
    data += z.compress(bytes(inflated_bytes % len(chunk))) + z.flush()
    vertices = b"d" + struct.pack("<III", count, 1, len(data)) + data
    return bytes(fbx_binary(fbx_mesh(head.vertices, head.triangles, vertices)))


# ---- The attacks ---------------------------------------------------------------------------


def _fifo(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    os.mkfifo(path)
    return path


def _write(path: Path, data: bytes) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data)
    return path


def _secret_buffer(g: Gltf) -> bytes:
    """The avatar's own buffer, then the secret: a reader that follows the link reads a
    valid buffer."""
    return bytes(g.bin) + SECRET


def _gltf_uri(head: Head, at: Path, uri: str, outside: Path | None) -> str:
    """The head as .gltf at `at` whose buffer is at `uri`; `outside`, where given, gets the
    real buffer and the secret (where a reader that followed the URI would find it)."""
    g = head_gltf(head)
    if outside is not None:
        _write(outside, _secret_buffer(g))
    _write(at, g.gltf(uri))
    return str(outside) if outside else ""


def _head_folder(head: Head, folder: Path, shapes: bool = True) -> None:
    write_obj(folder / "neutral.obj", head.vertices, head.triangles)
    if shapes:
        for name, d in zip(ARKIT_BLENDSHAPES, head.deltas, strict=True):
            if np.any(d != 0):
                write_obj(folder / "blendshapes" / f"{name}.obj", head.vertices + d)


def folder_bytes(folder: Path) -> int:
    """The bytes of the regular files in `folder` and below, links not followed."""
    total = 0
    for root, _, files in os.walk(folder):
        for f in files:
            st = os.lstat(Path(root) / f)
            total += st.st_size if stat.S_ISREG(st.st_mode) else 0
    return total


class Writer:
    """Writes attacks into `out`, one folder each, and lists them."""

    def __init__(self, out: Path, head: Head) -> None:
        self.out, self.head, self.attacks = out, head, []

    def add(self, name: str, avatar: Path, command: str = "fit", secret: str = "", **kw) -> None:
        """`avatar` is handed over with its folder (a file's folder, or the avatar folder)."""
        self.attacks.append(
            Attack(
                name,
                command,
                str(avatar.relative_to(self.out)),
                input_bytes=folder_bytes(avatar if avatar.is_dir() else avatar.parent),
                secret=str(Path(secret).relative_to(self.out)) if secret else "",
                **kw,
            )
        )

    def dir(self, name: str) -> Path:
        folder = self.out / name
        folder.mkdir(parents=True)
        return folder


def _controls(w: Writer) -> None:
    d = w.dir("control_glb")
    w.add("control_glb", _write(d / "avatar.glb", head_gltf(w.head).glb()), control=True)
    d = w.dir("control_gltf")
    g = head_gltf(w.head)
    _write(d / "avatar.bin", bytes(g.bin))
    w.add("control_gltf", _write(d / "avatar.gltf", g.gltf("avatar.bin")), control=True)
    d = w.dir("control_folder")
    _head_folder(w.head, d / "avatar")
    w.add("control_folder", d / "avatar", control=True)


def _buffer_uris(w: Writer) -> None:
    """The head's buffer named in ways that lead out of the avatar's folder or to a file that
    is not one."""
    h = w.head
    d = w.dir("gltf_uri_escape")
    secret = _gltf_uri(
        h, d / "x" / "y" / "avatar.gltf", "../../outside/buf.bin", d / "outside" / "buf.bin"
    )
    w.add("gltf_uri_escape", d / "x" / "y" / "avatar.gltf", secret=secret)
    d = w.dir("gltf_uri_absolute")
    secret = _gltf_uri(
        h, d / "avatar" / "avatar.gltf", str((d / "buf.bin").resolve()), d / "buf.bin"
    )
    w.add("gltf_uri_absolute", d / "avatar" / "avatar.gltf", secret=secret)
    d = w.dir("gltf_uri_file_scheme")
    uri = (d / "buf.bin").resolve().as_uri()
    secret = _gltf_uri(h, d / "avatar" / "avatar.gltf", uri, d / "buf.bin")
    w.add("gltf_uri_file_scheme", d / "avatar" / "avatar.gltf", secret=secret)
    d = w.dir("gltf_uri_percent_encoded")
    secret = _gltf_uri(
        h, d / "x" / "avatar.gltf", "..%2Foutside%2Fbuf.bin", d / "outside" / "buf.bin"
    )
    w.add("gltf_uri_percent_encoded", d / "x" / "avatar.gltf", secret=secret)
    for name, uri in (
        ("gltf_uri_dev_zero", "/dev/zero"),
        ("gltf_uri_proc_self_mem", "/proc/self/mem"),
    ):
        d = w.dir(name)
        _gltf_uri(h, d / "avatar.gltf", uri, None)
        w.add(name, d / "avatar.gltf")
    d = w.dir("gltf_uri_fifo")
    _fifo(d / "buf.bin")
    _gltf_uri(h, d / "avatar.gltf", "buf.bin", None)
    w.add("gltf_uri_fifo", d / "avatar.gltf")

    # A second mesh whose vertices are the bytes of a file four folders up.
    d = w.dir("gltf_second_mesh_passwd")
    passwd = _write(
        d / "passwd", (SECRET + b"root:x:0:0:root:/root:/bin/sh\n").ljust(12 * 16, b"#")
    )
    g = head_gltf(h)
    g.doc["buffers"].append({"uri": "../../../../passwd", "byteLength": passwd.stat().st_size})
    stolen = g.accessor(g.buffer_view(1, 0, 12 * 16), 16, "VEC3")
    fan = np.array([[0, k, k + 1] for k in range(1, 15)], np.uint32)
    g.mesh("Jaw", np.zeros((16, 3), np.float32), fan, {"jawOpen": np.zeros((16, 3), np.float32)})
    g.doc["meshes"][-1]["primitives"][0]["attributes"]["POSITION"] = stolen
    avatar = _write(d / "a" / "b" / "c" / "d" / "avatar.glb", g.glb())
    w.add("gltf_second_mesh_passwd", avatar, secret=str(passwd))


def _names_and_folders(w: Writer) -> None:
    """FIFOs, devices and links where the command line or an avatar folder expects a file."""
    h = w.head
    for name, names in (("names_fifo", "names.txt"), ("names_dev_zero", "/dev/zero")):
        d = w.dir(name)
        avatar = _write(d / "avatar.glb", head_gltf(h).glb())
        if names == "names.txt":
            _fifo(d / names)
            names = str(Path(name) / names)
        w.add(name, avatar, args=["--names", names, *BASE_ARGS])

    d = w.dir("folder_neutral_fifo")
    _head_folder(h, d / "avatar")
    (d / "avatar" / "neutral.obj").unlink()
    _fifo(d / "avatar" / "neutral.obj")
    w.add("folder_neutral_fifo", d / "avatar")

    d = w.dir("folder_user_face_fifo")  # the template's topology: replay opens it without a fit
    write_rig(d / "avatar", h.vertices, h.deltas, h.triangles)
    _fifo(d / "avatar" / "user_face" / "neutral.obj")
    w.add("folder_user_face_fifo", d / "avatar", command="replay")

    d = w.dir("fit_json_names_fifo")  # a fit folder whose report names a FIFO as its names file
    avatar = _write(d / "avatar.glb", head_gltf(h).glb())
    _write(d / "fit" / "avatar.fit", b"not read: the names file comes first")
    source = {
        "path": str(avatar.resolve()),
        "path_from_fit": "../avatar.glb",
        "names_file": str(_fifo(d / "names.txt").resolve()),
        "mesh_sha256": "0" * 64,
    }
    _write(d / "fit" / "fit.json", json.dumps({"source": source}).encode())
    w.add("fit_json_names_fifo", d / "fit", command="replay")

    d = w.dir("folder_neutral_link")
    _head_folder(h, d / "avatar")
    (d / "avatar" / "neutral.obj").unlink()
    outside = d / "outside" / "neutral.obj"
    write_obj(outside, h.vertices, h.triangles)
    outside.write_bytes(b"# " + SECRET + outside.read_bytes())
    (d / "avatar" / "neutral.obj").symlink_to("../outside/neutral.obj")
    w.add("folder_neutral_link", d / "avatar", secret=str(outside))

    d = w.dir("folder_blendshapes_link")
    _head_folder(h, d / "avatar", shapes=False)
    _head_folder(h, d / "outside")
    (d / "outside" / "neutral.obj").unlink()
    jaw = d / "outside" / "blendshapes" / "jawOpen.obj"
    jaw.write_bytes(b"# " + SECRET + jaw.read_bytes())
    (d / "avatar" / "blendshapes").symlink_to("../outside/blendshapes", target_is_directory=True)
    w.add("folder_blendshapes_link", d / "avatar", secret=str(jaw))


def _structure(w: Writer) -> None:
    """Nesting, sharing and counts that cost a naive reader far more than the file's size."""
    h = w.head
    d = w.dir("gltf_nodes_nested_100k")
    g = head_gltf(h)
    depth = 100_000
    g.doc["nodes"] = [{"children": [k + 1]} for k in range(depth - 1)] + [{"mesh": 0}]
    g.doc["scenes"][0]["nodes"] = [0]
    w.add("gltf_nodes_nested_100k", _write(d / "avatar.glb", g.glb()))

    d = w.dir("gltf_json_nested_1m")
    deep = b'{"asset":{"version":"2.0"},"extras":' + b"[" * 1_000_000 + b"]" * 1_000_000 + b"}"
    w.add("gltf_json_nested_1m", _write(d / "avatar.gltf", deep))
    d = w.dir("fbx_binary_nested_100k")
    w.add("fbx_binary_nested_100k", _write(d / "avatar.fbx", fbx_binary_nested(100_000)))
    d = w.dir("fbx_ascii_nested_100k")
    w.add("fbx_ascii_nested_100k", _write(d / "avatar.fbx", fbx_ascii_nested(100_000)))

    # Every node of a level is a child of both nodes of the level above: 2^40 paths.
    d = w.dir("gltf_diamond_nodes")
    g = head_gltf(h)
    levels = 40
    g.doc["nodes"] = [
        {"children": [2 * level + 2, 2 * level + 3]} if level < levels - 1 else {"mesh": 0}
        for level in range(levels)
        for _ in range(2)
    ]
    g.doc["scenes"][0]["nodes"] = [0, 1]
    w.add("gltf_diamond_nodes", _write(d / "avatar.glb", g.glb()))

    # A mesh of 30,000 vertices used by 300 nodes: 9 million vertices placed.
    d = w.dir("gltf_mesh_instanced_300")
    side = 173
    grid = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2)
    vertices = np.c_[grid * 0.001, np.zeros(len(grid))].astype(np.float32)
    k = np.arange(side - 1)
    corner = (k[:, None] * side + k[None, :]).ravel()
    triangles = np.r_[
        np.c_[corner, corner + 1, corner + side],
        np.c_[corner + 1, corner + side + 1, corner + side],
    ]
    moved = np.zeros_like(vertices)
    moved[: side // 2, 1] = 0.001
    g = Gltf()
    g.mesh(
        "Grid", vertices, triangles, {"eyeBlinkLeft": moved, "eyeBlinkRight": moved[::-1].copy()}
    )
    g.doc["nodes"] = [{"mesh": 0, "translation": [0.01 * n, 0, 0]} for n in range(300)]
    g.doc["scenes"][0]["nodes"] = list(range(300))
    w.add("gltf_mesh_instanced_300", _write(d / "avatar.glb", g.glb()))

    # 5,000 morph targets sharing one accessor.
    d = w.dir("gltf_morph_targets_5000")
    g = head_gltf(h)
    primitive = g.doc["meshes"][0]["primitives"][0]
    primitive["targets"] = [primitive["targets"][0]] * 5000
    g.doc["meshes"][0]["extras"]["targetNames"] = [ARKIT_BLENDSHAPES[k % 52] for k in range(5000)]
    w.add("gltf_morph_targets_5000", _write(d / "avatar.glb", g.glb()))


def _bytes_and_values(w: Writer, fan_mib: int, bomb_mib: int) -> None:
    """Offsets, lengths and values out of range; contents other than the name says."""
    h = w.head
    for name, offset in (
        ("gltf_accessor_offset_2e64_65536", 2**64 - 65536),
        ("gltf_accessor_offset_2e64_4", 2**64 - 4),
    ):
        d = w.dir(name)
        g = head_gltf(h)
        g.doc["accessors"][0]["byteOffset"] = offset
        w.add(name, _write(d / "avatar.glb", g.glb()))
    d = w.dir("glb_json_length_0xfffffff0")
    glb = b"glTF" + struct.pack("<II", 2, 24) + struct.pack("<I", 0xFFFFFFF0) + b"JSON" + b"{}  "
    w.add("glb_json_length_0xfffffff0", _write(d / "avatar.glb", glb))
    d = w.dir("gltf_byte_stride_4")
    g = head_gltf(h)
    g.doc["bufferViews"][0]["byteStride"] = 4
    w.add("gltf_byte_stride_4", _write(d / "avatar.glb", g.glb()))

    obj = b"v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\n"
    for name, text in (
        ("glb_holds_obj", obj + b"f 1 2 3\n"),
        ("glb_holds_ply", b"ply\nformat ascii 1.0\nend_header\n"),
    ):
        d = w.dir(name)
        w.add(name, _write(d / "avatar.glb", text))

    d = w.dir("gltf_shape_delta_3e38")
    deltas = h.deltas.copy()
    deltas[ARKIT_BLENDSHAPES.index("jawOpen"), 0] = (0, 3e38, 0)
    w.add("gltf_shape_delta_3e38", _write(d / "avatar.glb", head_gltf(h, deltas=deltas).glb()))
    d = w.dir("gltf_vertex_1e30")
    vertices = h.vertices.copy()
    vertices[0] = (0, 0, 1e30)
    w.add("gltf_vertex_1e30", _write(d / "avatar.glb", head_gltf(h, vertices).glb()))
    d = w.dir("metres_per_unit_1e-300")
    w.add(
        "metres_per_unit_1e-300",
        _write(d / "avatar.glb", head_gltf(h).glb()),
        args=["--metres-per-unit", "1e-300"],
    )

    # One polygon of ~fan_mib MiB of 2-byte indices: more triangles than an avatar may have.
    d = w.dir("obj_face_fan")
    fan = b"v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nf " + b"1 2 3 " * (fan_mib * (1 << 20) // 6) + b"\n"
    _write(d / "avatar" / "neutral.obj", fan)
    w.add("obj_face_fan", d / "avatar")
    if bomb_mib:
        d = w.dir("fbx_zlib_bomb")
        w.add("fbx_zlib_bomb", _write(d / "avatar.fbx", fbx_zlib_bomb(h, bomb_mib << 20)))


def _leb128(value: int) -> bytes:
    out = bytearray()
    while True:
        byte, value = value & 0x7F, value >> 7
        out.append(byte | (0x80 if value else 0))
        if not value:
            return bytes(out)


def draco_header(edgebreaker: bool, vertices: int, faces: int) -> bytes:
    """The start of a Draco 2.2 triangle-mesh stream declaring these counts (then garbage): a
    decoder that sizes its tables by them before checking them allocates what they say."""
    head = b"DRACO" + bytes([2, 2, 1, 1 if edgebreaker else 0]) + struct.pack("<H", 0)
    counts = (
        bytes([0]) + _leb128(vertices) + _leb128(faces)
        if edgebreaker
        else _leb128(faces) + _leb128(vertices)
    )
    return head + counts + b"\x5a" * 64


def _compressed(w: Writer) -> None:
    """Compressed and implicit data that declares far more than the file holds."""
    h = w.head
    for name, edgebreaker, vertices, faces in (
        ("gltf_draco_points_2e32", False, 0xFFFFFFF0, 1),
        ("gltf_draco_edgebreaker_faces_2e30", True, 3, 0x3FFFFFFF),
    ):
        d = w.dir(name)
        g = head_gltf(h)
        stream = g.view(draco_header(edgebreaker, vertices, faces))
        position = len(g.doc["accessors"])
        g.doc["accessors"] += [
            {"componentType": 5126, "count": 3, "type": "VEC3"},
            {"componentType": 5125, "count": 3, "type": "SCALAR"},
        ]
        draco = {"bufferView": stream, "attributes": {"POSITION": 0}}
        g.doc["meshes"].append(
            {
                "name": "Teeth",
                "primitives": [
                    {
                        "attributes": {"POSITION": position},
                        "indices": position + 1,
                        "extensions": {"KHR_draco_mesh_compression": draco},
                    }
                ],
            }
        )
        g.doc["nodes"].append({"name": "Teeth", "mesh": len(g.doc["meshes"]) - 1})
        g.doc["scenes"][0]["nodes"].append(len(g.doc["nodes"]) - 1)
        g.doc["extensionsUsed"] = g.doc["extensionsRequired"] = ["KHR_draco_mesh_compression"]
        w.add(name, _write(d / "avatar.glb", g.glb()))

    # Accessors without a bufferView are zeros (glTF 2.0), so a file of a few hundred bytes
    # declares a 4M-vertex mesh with 1,024 morph targets: 49 GB of zeros.
    d = w.dir("gltf_implicit_zeros_49gb")
    g = Gltf()
    g.doc["accessors"] = [
        {"componentType": 5126, "count": 4_000_000, "type": "VEC3"},
        {"componentType": 5125, "count": 3, "type": "SCALAR"},
    ]
    primitive = {
        "attributes": {"POSITION": 0},
        "indices": 1,
        "targets": [{"POSITION": 0}] * 1024,
    }
    g.doc["meshes"] = [
        {
            "name": "Head",
            "primitives": [primitive],
            "extras": {"targetNames": [ARKIT_BLENDSHAPES[k % 52] for k in range(1024)]},
        }
    ]
    g.doc["nodes"] = [{"name": "Head", "mesh": 0}]
    g.doc["scenes"][0]["nodes"] = [0]
    w.add("gltf_implicit_zeros_49gb", _write(d / "avatar.glb", g.glb()))


GROUPS: list[Callable[[Writer], None]] = [
    _controls,
    _buffer_uris,
    _names_and_folders,
    _structure,
    _compressed,
]


def write_corpus(out: Path, fan_mib: int = 30, bomb_mib: int = 1024) -> list[Attack]:
    """Every attack under `out` (which must not exist) and out/corpus.json. `fan_mib`: the
    size of the OBJ face fan (30 MiB: just over the triangle limit); `bomb_mib`: what the FBX
    zlib bomb inflates to (0: no bomb; it takes seconds to write)."""
    out.mkdir(parents=True)
    w = Writer(out, load_head())
    for group in GROUPS:
        group(w)
    _bytes_and_values(w, fan_mib, bomb_mib)
    (out / "corpus.json").write_text(
        json.dumps(
            {"base_args": list(BASE_ARGS), "attacks": [asdict(a) for a in w.attacks]}, indent=1
        )
    )
    return w.attacks


def read_corpus(out: Path) -> list[Attack]:
    return [Attack(**a) for a in json.loads((out / "corpus.json").read_text())["attacks"]]
