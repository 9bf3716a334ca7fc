"""Sharded, self-describing dataset storage.

A dataset is a folder with `manifest.json` and `shard-<kind>-<index>.npz` files. Shard k of a
kind always holds the same instance ids (fixed by the generator's plan), is written to a
temporary name and renamed when complete, and is listed in the manifest with its checksum
only after that. So a killed generator loses at most the shards in flight, never leaves a
corrupt shard that counts, and a restart regenerates exactly the missing shards: no instance
is lost or duplicated."""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

FORMAT = "softdeca-dataset"
FORMAT_VERSION = 1


def shard_name(kind: str, index: int) -> str:
    return f"shard-{kind}-{index:05d}.npz"


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def write_shard(folder: Path, kind: str, index: int, arrays: dict[str, np.ndarray]) -> dict:
    """Write one shard atomically; returns its manifest entry."""
    final = folder / shard_name(kind, index)
    tmp = folder / (final.name + f".tmp{os.getpid()}")
    with tmp.open("wb") as f:
        np.savez(f, **arrays)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, final)
    n = len(next(iter(arrays.values())))
    return {
        "file": final.name,
        "kind": kind,
        "index": index,
        "instances": int(n),
        "bytes": final.stat().st_size,
        "sha256": _sha256(final),
    }


@dataclass
class Manifest:
    """The dataset's description; `shards` lists only complete, verified shards."""

    path: Path
    doc: dict

    @classmethod
    def open(cls, folder: Path, header: dict) -> Manifest:
        """Open or create; an existing dataset must have been made with the same header."""
        path = folder / "manifest.json"
        if path.is_file():
            doc = json.loads(path.read_text())
            if doc.get("format") != FORMAT or doc.get("format_version") != FORMAT_VERSION:
                raise ValueError(f"{path}: not a {FORMAT} v{FORMAT_VERSION} dataset")
            if doc["header"] != json.loads(json.dumps(header)):
                raise ValueError(
                    f"{folder} was generated with another configuration; "
                    "use a new folder or the same settings to resume"
                )
            return cls(path, doc)
        doc = {
            "format": FORMAT,
            "format_version": FORMAT_VERSION,
            "header": header,
            "shards": [],
            "stats": {},
        }
        m = cls(path, doc)
        m.save()
        return m

    def save(self) -> None:
        tmp = self.path.with_suffix(".json.tmp")
        tmp.write_text(json.dumps(self.doc, indent=1) + "\n")
        os.replace(tmp, self.path)

    def done(self, kind: str) -> set[int]:
        """Indices of complete shards of `kind` (listed and present with the right size)."""
        folder = self.path.parent
        return {
            s["index"]
            for s in self.doc["shards"]
            if s["kind"] == kind
            and (folder / s["file"]).is_file()
            and (folder / s["file"]).stat().st_size == s["bytes"]
        }

    def add(self, entry: dict) -> None:
        self.doc["shards"] = [s for s in self.doc["shards"] if s["file"] != entry["file"]]
        self.doc["shards"].append(entry)
        self.doc["shards"].sort(key=lambda s: (s["kind"], s["index"]))
        self.save()


def verify(folder: Path) -> list[str]:
    """Problems with a dataset folder (empty: all listed shards present and intact)."""
    m = json.loads((folder / "manifest.json").read_text())
    out = []
    for s in m["shards"]:
        p = folder / s["file"]
        if not p.is_file():
            out.append(f"{s['file']}: missing")
        elif _sha256(p) != s["sha256"]:
            out.append(f"{s['file']}: checksum mismatch")
    return out


def iter_shards(
    folder: Path, kind: str, split: str | None = None
) -> Iterator[dict[str, np.ndarray]]:
    """Stream the listed shards of a kind, one at a time (never the whole dataset in memory).
    With `split`, only instances of that split ("train" or "test")."""
    m = json.loads((Path(folder) / "manifest.json").read_text())
    for s in m["shards"]:
        if s["kind"] != kind:
            continue
        with np.load(Path(folder) / s["file"]) as z:
            arrays = {k: z[k] for k in z.files}
        if split is not None:
            keep = arrays["split"] == (1 if split == "test" else 0)
            if not keep.any():
                continue
            # Per-instance arrays are filtered; 0-d ones (the shard's `meta`) kept as they are.
            arrays = {k: v[keep] if v.ndim else v for k, v in arrays.items()}
        yield arrays
