"""ctypes binding of the runtime's C ABI (plugin/include/softdeca/softdeca.h): what Unity's
P/Invoke layer does, from Python, for the parity tests, the benchmarks and the replay tools.
Every call checks its status and raises NativeError with the library's message.

Kept whole: the ctypes mirror of the C ABI, its structs and its function table, read
as one against the header (tests/python/test_abi_mirrors.py)."""

from __future__ import annotations

import ctypes as C
import json
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from softdeca_train.paths import REPO_ROOT

SOFTDECA_OK = 0
ABI_VERSION = 5  # SOFTDECA_ABI_VERSION of the header these structs mirror
# softdeca_precision; "default" leaves each model's storage to the library
PRECISIONS = {"default": 0, "half": 1, "float": 2, "int8": 3}
STATUS_NAMES = {
    0: "ok",
    1: "invalid argument",
    2: "non-finite input",
    3: "buffer too small",
    4: "i/o error",
    5: "format error",
    6: "internal error",
    7: "busy",
    8: "not ready",
}


class NativeError(RuntimeError):
    def __init__(self, status: int, message: str) -> None:
        super().__init__(f"[{STATUS_NAMES.get(status, status)}] {message}")
        self.status = status
        self.message = message


class ModelOptions(C.Structure):
    _fields_ = [
        ("struct_size", C.c_uint32),
        ("prepare_threads", C.c_uint32),
        ("memory_budget_mib", C.c_uint32),
    ]


class ModelInfo(C.Structure):
    _fields_ = [
        (n, C.c_uint32)
        for n in (
            "struct_size",
            "format_version",
            "head_vertex_count",
            "skin_vertex_count",
            "skin_triangle_count",
            "latent_size",
            "identity_size",
            "blendshape_count",
            "parameter_count",
            "landmark_count",
            "arkit_vertex_count",
        )
    ]
    _fields_ += [(n, C.c_int32) for n in ("has_softdeca", "has_sparse", "untrained")]
    _fields_ += [("dynamics_frame_rate_hz", C.c_float)]


class ParameterInfo(C.Structure):
    """softdeca_parameter_info (shared with the simulator's compiled-in list)."""

    _fields_ = [
        ("struct_size", C.c_uint32),
        ("name", C.c_char_p),
        ("unit", C.c_char_p),
        ("domain", C.c_char_p),
        ("description", C.c_char_p),
        ("default_value", C.c_double),
        ("minimum", C.c_double),
        ("maximum", C.c_double),
        ("log_scale", C.c_int32),
    ]


class AvatarMesh(C.Structure):
    _fields_ = [
        ("struct_size", C.c_uint32),
        ("neutral", C.POINTER(C.c_float)),
        ("vertex_count", C.c_uint32),
        ("triangles", C.POINTER(C.c_int32)),
        ("triangle_count", C.c_uint32),
        ("blendshapes", C.POINTER(C.c_float)),
        ("blendshape_count", C.c_uint32),
        ("landmarks", C.POINTER(C.c_float)),
        ("landmark_count", C.c_uint32),
    ]


class AvatarDesc(C.Structure):
    _fields_ = [
        ("struct_size", C.c_uint32),
        ("mesh", C.POINTER(AvatarMesh)),
        ("fit", C.c_void_p),
        ("threads", C.c_uint32),
        ("precision", C.c_int32),
        ("sparse_precision", C.c_int32),
    ]


class FitOptions(C.Structure):
    _fields_ = [
        ("struct_size", C.c_uint32),
        ("metres_per_unit", C.c_double),
        ("iterations", C.c_uint32),
        ("reserved", C.c_uint32),
    ]


class Output(C.Structure):
    _fields_ = [
        ("struct_size", C.c_uint32),
        ("vertices", C.POINTER(C.c_float)),
        ("vertex_capacity", C.c_uint32),
        ("normals", C.POINTER(C.c_float)),
        ("normal_capacity", C.c_uint32),
    ]


class Stats(C.Structure):
    _fields_ = [
        ("struct_size", C.c_uint32),
        ("threads", C.c_uint32),
        ("frames", C.c_uint64),
        ("preparations", C.c_uint64),
        ("generation", C.c_uint64),
        *[
            (n, C.c_double)
            for n in (
                "frame_ms",
                "encoder_ms",
                "blend_ms",
                "hyper_ms",
                "solve_ms",
                "dynamics_ms",
                "output_ms",
                "normals_ms",
                "prepare_ms",
                "prepare_networks_ms",
                "factorisation_ms",
            )
        ],
        ("memory_bytes", C.c_uint64),
        ("prepare_physics_ms", C.c_double),
        ("physics_iterations", C.c_uint32),
        ("reserved", C.c_uint32),
        ("frame_bytes", C.c_uint64),
    ]


# Every C ABI function this binding calls, as the header declares it: (restype, argtypes), with
# every pointer a c_void_p (handles, arrays, structs) or c_char_p (strings). Set on the library
# at load, so ctypes converts and checks each argument instead of guessing (a double passed
# where no argtypes are declared would go through as an int).
# tests/python/test_abi_mirrors.py holds this table to plugin/include/softdeca/softdeca.h.
_STATUS, _PTR, _STR, _U32, _I32 = C.c_int32, C.c_void_p, C.c_char_p, C.c_uint32, C.c_int32
SIGNATURES: dict[str, tuple[type | None, tuple[type, ...]]] = {
    "softdeca_abi_version": (C.c_uint32, ()),
    "softdeca_version": (_STR, ()),
    "softdeca_last_error": (_STR, ()),
    "softdeca_blendshape_find_index": (_STATUS, (_STR, _PTR)),
    "softdeca_model_load": (_STATUS, (_STR, _PTR, _PTR)),
    "softdeca_model_load_memory": (_STATUS, (_PTR, _U32, _PTR, _PTR)),
    "softdeca_model_destroy": (None, (_PTR,)),
    "softdeca_model_get_info": (_STATUS, (_PTR, _PTR)),
    "softdeca_model_get_parameter_info": (_STATUS, (_PTR, _U32, _PTR)),
    "softdeca_model_find_parameter": (_STATUS, (_PTR, _STR, _PTR)),
    "softdeca_model_get_landmark_vertices": (_STATUS, (_PTR, _PTR, _U32)),
    "softdeca_model_get_skin_triangles": (_STATUS, (_PTR, _PTR, _U32)),
    "softdeca_model_evaluate_landmarks": (_STATUS, (_PTR, _PTR, _U32, _PTR, _U32)),
    "softdeca_avatar_create": (_STATUS, (_PTR, _PTR, _PTR)),
    "softdeca_avatar_destroy": (None, (_PTR,)),
    "softdeca_avatar_set_parameter": (_STATUS, (_PTR, _U32, C.c_double)),
    "softdeca_avatar_set_parameter_faces": (_STATUS, (_PTR, _U32, _PTR, _U32)),
    "softdeca_avatar_set_parameter_vertices": (_STATUS, (_PTR, _U32, _PTR, _U32)),
    "softdeca_avatar_get_identity": (_STATUS, (_PTR, _PTR, _U32)),
    "softdeca_avatar_set_identity": (_STATUS, (_PTR, _PTR, _U32)),
    "softdeca_avatar_prepare": (_STATUS, (_PTR,)),
    "softdeca_avatar_evaluate_weights": (_STATUS, (_PTR, _PTR, _U32, _PTR)),
    "softdeca_avatar_evaluate_weights_batch": (_STATUS, (_PTR, _U32, _PTR, _U32, _PTR, _PTR)),
    "softdeca_avatar_evaluate_surface": (_STATUS, (_PTR, _PTR, _U32, _PTR, _U32, _PTR)),
    "softdeca_avatar_evaluate_linear": (_STATUS, (_PTR, _PTR, _U32, _PTR)),
    "softdeca_avatar_calibrate_landmarks": (_STATUS, (_PTR, _PTR, _U32)),
    "softdeca_avatar_evaluate_landmarks": (_STATUS, (_PTR, _PTR, _U32, _PTR)),
    "softdeca_avatar_set_dynamics": (_STATUS, (_PTR, _I32)),
    "softdeca_avatar_reset_dynamics": (_STATUS, (_PTR,)),
    "softdeca_avatar_get_stats": (_STATUS, (_PTR, _PTR)),
    "softdeca_avatar_fit_create": (_STATUS, (_PTR, _PTR, _PTR, _PTR)),
    "softdeca_avatar_fit_destroy": (None, (_PTR,)),
    "softdeca_avatar_fit_save": (_STATUS, (_PTR, _STR)),
    "softdeca_avatar_fit_load": (_STATUS, (_PTR, _STR, _PTR)),
    "softdeca_avatar_fit_get_report": (_STATUS, (_PTR, _PTR, _U32, _PTR)),
    "softdeca_avatar_fit_get_registered": (_STATUS, (_PTR, _PTR, _U32, _PTR)),
}


def library_path() -> Path:
    """$SOFTDECA_LIBRARY, else the release build's libsoftdeca.so."""
    env = os.environ.get("SOFTDECA_LIBRARY")
    return Path(env) if env else REPO_ROOT / "build" / "release" / "plugin" / "libsoftdeca.so"


_lib: C.CDLL | None = None


def lib() -> C.CDLL:
    global _lib
    if _lib is None:
        path = library_path()
        if not path.is_file():
            raise FileNotFoundError(f"{path} not found: run `make build`")
        loaded = C.CDLL(str(path))
        for name, (restype, argtypes) in SIGNATURES.items():
            function = getattr(loaded, name)
            function.restype, function.argtypes = restype, argtypes
        found = loaded.softdeca_abi_version()
        if found != ABI_VERSION:
            raise RuntimeError(
                f"{path} has C ABI version {found}; this binding needs {ABI_VERSION}"
            )
        _lib = loaded
    return _lib


def check(status: int) -> None:
    if status != SOFTDECA_OK:
        raise NativeError(status, lib().softdeca_last_error().decode())


def blendshape_index(name: str) -> int:
    """The canonical index (0..51) of the ARKit shape a rig's name denotes, or -1: the library's
    one rule for rigs' names (softdeca_blendshape_find_index; "eyeBlink_L",
    "AK_07_EyeBlinkLeft")."""
    index = C.c_int32(-1)
    check(lib().softdeca_blendshape_find_index(name.encode(), C.byref(index)))
    return index.value


def _f32(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float32)


def _ptr(a: np.ndarray | None, ctype: type = C.c_float) -> C._Pointer | None:  # type: ignore[name-defined]
    return None if a is None else a.ctypes.data_as(C.POINTER(ctype))


class NativeModel:
    """softdeca_model: a loaded bundle."""

    def __init__(self, path: str | os.PathLike[str] | bytes, prepare_threads: int = 1) -> None:
        self.handle = C.c_void_p()
        opts = ModelOptions(C.sizeof(ModelOptions), prepare_threads)
        if isinstance(path, bytes):
            self._data = path
            check(
                lib().softdeca_model_load_memory(
                    C.c_char_p(path), C.c_uint32(len(path)), C.byref(opts), C.byref(self.handle)
                )
            )
        else:
            check(
                lib().softdeca_model_load(str(path).encode(), C.byref(opts), C.byref(self.handle))
            )
        info = ModelInfo()
        info.struct_size = C.sizeof(ModelInfo)
        check(lib().softdeca_model_get_info(self.handle, C.byref(info)))
        self.info = info

    def close(self) -> None:
        if self.handle:
            lib().softdeca_model_destroy(self.handle)
            self.handle = C.c_void_p()

    def __del__(self) -> None:
        if getattr(self, "handle", None):
            lib().softdeca_model_destroy(self.handle)

    def parameter(self, index: int) -> ParameterInfo:
        p = ParameterInfo()
        p.struct_size = C.sizeof(ParameterInfo)
        check(lib().softdeca_model_get_parameter_info(self.handle, C.c_uint32(index), C.byref(p)))
        return p

    def find_parameter(self, name: str) -> int:
        i = C.c_uint32()
        check(lib().softdeca_model_find_parameter(self.handle, name.encode(), C.byref(i)))
        return i.value

    def landmark_vertices(self) -> np.ndarray:
        out = np.zeros(self.info.landmark_count, dtype=np.int32)
        check(
            lib().softdeca_model_get_landmark_vertices(
                self.handle, _ptr(out, C.c_int32), C.c_uint32(len(out))
            )
        )
        return out

    def skin_triangles(self) -> np.ndarray:
        out = np.zeros((self.info.skin_triangle_count, 3), dtype=np.int32)
        check(
            lib().softdeca_model_get_skin_triangles(
                self.handle, _ptr(out, C.c_int32), C.c_uint32(len(out))
            )
        )
        return out

    def evaluate_landmarks(self, vertices: np.ndarray) -> np.ndarray:
        v = _f32(vertices)
        out = np.zeros((self.info.landmark_count, 3), dtype=np.float32)
        check(
            lib().softdeca_model_evaluate_landmarks(
                self.handle, _ptr(v), len(v), _ptr(out), C.c_uint32(len(out))
            )
        )
        return out


class AvatarArrays:
    """A user's avatar mesh kept alive for the C ABI: neutral (N, 3), triangles (T, 3), the 52
    ARKit shapes as deltas (52, N, 3; zeros where the rig lacks one), optional landmarks."""

    def __init__(
        self,
        neutral: np.ndarray,
        triangles: np.ndarray,
        deltas: np.ndarray,
        landmarks: np.ndarray | None = None,
    ) -> None:
        self.neutral = _f32(neutral)
        self.triangles = np.ascontiguousarray(triangles, dtype=np.int32)
        self.deltas = _f32(deltas)
        self.landmarks = None if landmarks is None else _f32(landmarks)
        self.abi = AvatarMesh(
            C.sizeof(AvatarMesh),
            _ptr(self.neutral),
            len(self.neutral),
            _ptr(self.triangles, C.c_int32),
            len(self.triangles),
            _ptr(self.deltas),
            len(self.deltas),
            _ptr(self.landmarks),
            0 if self.landmarks is None else len(self.landmarks),
        )


class NativeFit:
    """softdeca_avatar_fit: a user's avatar fitted to a model's template."""

    def __init__(self, handle: C.c_void_p) -> None:
        self.handle = handle

    @classmethod
    def create(
        cls,
        model: NativeModel,
        mesh: AvatarArrays,
        metres_per_unit: float = 0.0,
        iterations: int = 0,
    ) -> NativeFit:
        opts = FitOptions(C.sizeof(FitOptions), metres_per_unit, iterations, 0)
        handle = C.c_void_p()
        check(
            lib().softdeca_avatar_fit_create(
                model.handle, C.byref(mesh.abi), C.byref(opts), C.byref(handle)
            )
        )
        return cls(handle)

    @classmethod
    def load(cls, model: NativeModel, path: str | os.PathLike[str]) -> NativeFit:
        handle = C.c_void_p()
        check(lib().softdeca_avatar_fit_load(model.handle, str(path).encode(), C.byref(handle)))
        return cls(handle)

    def save(self, path: str | os.PathLike[str]) -> None:
        check(lib().softdeca_avatar_fit_save(self.handle, str(path).encode()))

    def report(self) -> dict:
        length = C.c_uint32()
        lib().softdeca_avatar_fit_get_report(self.handle, None, 0, C.byref(length))
        buf = C.create_string_buffer(length.value + 1)
        check(lib().softdeca_avatar_fit_get_report(self.handle, buf, len(buf), C.byref(length)))
        return json.loads(buf.value.decode())

    def registered(self, skin_vertices: int) -> np.ndarray:
        """The registered template skin in the avatar's units and axes."""
        out = np.zeros((skin_vertices, 3), dtype=np.float32)
        check(
            lib().softdeca_avatar_fit_get_registered(
                self.handle, _ptr(out), C.c_uint32(len(out)), None
            )
        )
        return out

    def close(self) -> None:
        if self.handle:
            lib().softdeca_avatar_fit_destroy(self.handle)
            self.handle = C.c_void_p()

    def __del__(self) -> None:
        if getattr(self, "handle", None):
            lib().softdeca_avatar_fit_destroy(self.handle)


class NativeAvatar:
    """softdeca_avatar: one head and its per-frame state."""

    def __init__(
        self,
        model: NativeModel,
        neutral: np.ndarray,
        triangles: np.ndarray,
        blendshapes: np.ndarray | None = None,
        threads: int = 1,
        precision: str = "default",
        sparse_precision: str = "default",
    ) -> None:
        self.model = model
        self.vh = model.info.head_vertex_count
        n = _f32(neutral)
        t = np.ascontiguousarray(triangles, dtype=np.int32)
        b = None if blendshapes is None else _f32(blendshapes)
        mesh = AvatarMesh(
            C.sizeof(AvatarMesh),
            _ptr(n),
            len(n),
            _ptr(t, C.c_int32),
            len(t),
            _ptr(b),
            0 if b is None else len(b),
            None,
            0,
        )
        self.handle = C.c_void_p()
        self._create(mesh, None, threads, precision, sparse_precision)
        self._buffers(self.vh)

    def _create(
        self,
        mesh: AvatarMesh,
        fit: C.c_void_p | None,
        threads: int,
        precision: str,
        sparse_precision: str,
    ) -> None:
        """softdeca_avatar_create: the template path (no fit) or the mesh on its fit;
        `precision` is SoftDECA's storage, `sparse_precision` SparseSoftDECA's (PRECISIONS)."""
        desc = AvatarDesc(
            C.sizeof(AvatarDesc),
            C.pointer(mesh),
            fit,
            threads,
            PRECISIONS[precision],
            PRECISIONS[sparse_precision],
        )
        check(lib().softdeca_avatar_create(self.model.handle, C.byref(desc), C.byref(self.handle)))

    @classmethod
    def fitted(
        cls,
        model: NativeModel,
        fit: NativeFit,
        mesh: AvatarArrays,
        threads: int = 1,
        precision: str = "default",
        sparse_precision: str = "default",
    ) -> NativeAvatar:
        """An avatar on the user's own mesh: outputs hold the mesh's own vertices."""
        self = cls.__new__(cls)
        self.model, self.fit, self.mesh = model, fit, mesh
        self.handle = C.c_void_p()
        self._create(mesh.abi, fit.handle, threads, precision, sparse_precision)
        self.vh = len(mesh.neutral)
        self._buffers(self.vh)
        return self

    def _buffers(self, n: int) -> None:
        self.vertices = np.zeros((n, 3), dtype=np.float32)
        self.normals = np.zeros((n, 3), dtype=np.float32)
        self._out = Output(C.sizeof(Output), _ptr(self.vertices), n, _ptr(self.normals), n)

    def close(self) -> None:
        if self.handle:
            lib().softdeca_avatar_destroy(self.handle)
            self.handle = C.c_void_p()

    def __del__(self) -> None:
        if getattr(self, "handle", None):
            lib().softdeca_avatar_destroy(self.handle)

    # ---- parameters -----------------------------------------------------------------------
    def set_parameter(self, name: str, value: float) -> None:
        i = self.model.find_parameter(name)
        check(lib().softdeca_avatar_set_parameter(self.handle, C.c_uint32(i), C.c_double(value)))

    def set_parameter_faces(self, name: str, values: np.ndarray) -> None:
        v = _f32(values)
        i = self.model.find_parameter(name)
        check(lib().softdeca_avatar_set_parameter_faces(self.handle, i, _ptr(v), len(v)))

    def set_parameter_vertices(self, name: str, values: np.ndarray) -> None:
        v = _f32(values)
        i = self.model.find_parameter(name)
        check(lib().softdeca_avatar_set_parameter_vertices(self.handle, i, _ptr(v), len(v)))

    def identity(self) -> np.ndarray:
        out = np.zeros(self.model.info.identity_size, dtype=np.float32)
        check(lib().softdeca_avatar_get_identity(self.handle, _ptr(out), len(out)))
        return out

    def set_identity(self, h: np.ndarray) -> None:
        v = _f32(h)
        check(lib().softdeca_avatar_set_identity(self.handle, _ptr(v), len(v)))

    def prepare(self) -> None:
        check(lib().softdeca_avatar_prepare(self.handle))

    def set_dynamics(self, on: bool) -> None:
        check(lib().softdeca_avatar_set_dynamics(self.handle, C.c_int32(int(on))))

    def reset_dynamics(self) -> None:
        check(lib().softdeca_avatar_reset_dynamics(self.handle))

    # ---- frames: each returns (vertices, normals), copies of the output buffers -----------
    def _result(self) -> tuple[np.ndarray, np.ndarray]:
        return self.vertices.copy(), self.normals.copy()

    def evaluate_weights(self, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        w = _f32(weights)
        check(
            lib().softdeca_avatar_evaluate_weights(self.handle, _ptr(w), len(w), C.byref(self._out))
        )
        return self._result()

    def evaluate_surface(
        self, weights: np.ndarray, surface: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        w, s = _f32(weights), _f32(surface)
        check(
            lib().softdeca_avatar_evaluate_surface(
                self.handle, _ptr(w), len(w), _ptr(s), len(s), C.byref(self._out)
            )
        )
        return self._result()

    def calibrate_landmarks(self, points: np.ndarray) -> None:
        p = _f32(points)
        check(lib().softdeca_avatar_calibrate_landmarks(self.handle, _ptr(p), len(p)))

    def evaluate_landmarks(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p = _f32(points)
        check(
            lib().softdeca_avatar_evaluate_landmarks(
                self.handle, _ptr(p), len(p), C.byref(self._out)
            )
        )
        return self._result()

    def evaluate_linear(self, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        w = _f32(weights)
        check(
            lib().softdeca_avatar_evaluate_linear(self.handle, _ptr(w), len(w), C.byref(self._out))
        )
        return self._result()

    def stats(self) -> Stats:
        s = Stats()
        s.struct_size = C.sizeof(Stats)
        check(lib().softdeca_avatar_get_stats(self.handle, C.byref(s)))
        return s


def evaluate_weights_batch(avatars: Sequence[NativeAvatar], weights: np.ndarray) -> list[int]:
    """softdeca_avatar_evaluate_weights_batch: one SoftDECA frame for each avatar, weights
    (len(avatars), 52), into each avatar's own buffers (its `vertices` and `normals`), the
    frame networks run once for the batch. Returns each avatar's status, as its own
    evaluate_weights would have it (SOFTDECA_OK: its frame is in its buffers)."""
    n = len(avatars)
    w = _f32(np.asarray(weights, dtype=np.float32).reshape(n, 52))
    handles = (C.c_void_p * n)(*[a.handle for a in avatars])
    outputs = (Output * n)(*[a._out for a in avatars])
    statuses = (C.c_int32 * n)()
    check(lib().softdeca_avatar_evaluate_weights_batch(handles, n, _ptr(w), 52, outputs, statuses))
    return list(statuses)
