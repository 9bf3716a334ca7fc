"""fTetWild's fill of one closed surface, in a process of its own with fixed random seeds.

`python -m softdeca_train.lhm.tetfill SURFACE.npz TETS.npz` reads `vertices`, `faces`,
`edge_length` and `envelope` and writes `vertices` and `tets`. `run_fill` starts it with the
build's `softdeca_fixed_seed` library preloaded (plugin/python/fixed_seed.cpp): fTetWild seeds
its generator from std::random_device, and a fresh process with the draws fixed makes the same
mesh from the same input on every run and machine."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

SEED_LIBRARY = "libsoftdeca_fixed_seed.so"


def seed_library() -> Path:
    """The preload library, built next to the softdeca_native extension."""
    import softdeca_native  # compiled with the plugin; only its folder is needed here

    path = Path(softdeca_native.__file__).parent / SEED_LIBRARY
    if not path.exists():
        raise RuntimeError(
            f"{path} is missing: build the native targets (`make build`); the tet fill needs it "
            "to be reproducible"
        )
    return path


def run_fill(
    surface: np.ndarray, faces: np.ndarray, edge_length: float, envelope: float
) -> tuple[np.ndarray, np.ndarray]:
    """fTetWild's tets inside `surface` (as fTetWild orients them), from a child process."""
    env = dict(os.environ)
    if sys.platform.startswith("linux"):
        env["LD_PRELOAD"] = str(seed_library())
    else:  # the preload interposes GNU libstdc++'s random_device: Linux builds only
        warnings.warn(
            "the tet fill's seeds are fixed on Linux only: meshes made here are not reproducible",
            stacklevel=2,
        )
    env["PYTHONPATH"] = os.pathsep.join([str(Path(__file__).parents[2]), *sys.path])
    # fTetWild writes a scratch file into the working directory: give it a folder of its own.
    with tempfile.TemporaryDirectory() as scratch:
        src, dst = Path(scratch) / "surface.npz", Path(scratch) / "tets.npz"
        np.savez(src, vertices=surface, faces=faces, edge_length=edge_length, envelope=envelope)
        cmd = [sys.executable, "-m", "softdeca_train.lhm.tetfill", str(src), str(dst)]
        done = subprocess.run(cmd, cwd=scratch, env=env, capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"the tet fill failed ({done.returncode}):\n{done.stderr[-2000:]}")
        with np.load(dst) as z:
            return np.asarray(z["vertices"], np.float64), np.asarray(z["tets"], np.int32)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m softdeca_train.lhm.tetfill",
        description="fTetWild's fill of a closed surface (the layered head model's tissue). "
        "Run through softdeca_train.lhm.conforming, which preloads the fixed-seed library.",
    )
    ap.add_argument("surface", type=Path, help="npz with vertices, faces, edge_length, envelope")
    ap.add_argument("out", type=Path, help="npz to write with vertices and tets")
    args = ap.parse_args(argv)
    import pytetwild  # only the fill's own process loads TetWild

    with np.load(args.surface) as z:
        v, t = pytetwild.tetrahedralize(
            np.asarray(z["vertices"], np.float64),
            np.asarray(z["faces"], np.int32),
            edge_length_fac=float(z["edge_length"]),
            epsilon=float(z["envelope"]),
            num_threads=1,
            quiet=True,
        )
    np.savez(args.out, vertices=np.asarray(v, np.float64), tets=np.asarray(t, np.int32))
    return 0


if __name__ == "__main__":
    sys.exit(main())
