"""The frames of a Live Link Face take that `simulate` runs: the streaming side's CSV reader
(columns by name, face-lost rows skipped and counted), then a start / count / stride window."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softdeca_train.streaming import takes as recorded


@dataclass(frozen=True)
class TakeWindow:
    path: Path
    weights: np.ndarray  # (F, 52) float32, canonical ARKit order
    frames: np.ndarray  # (F,) index of each chosen frame among the take's tracked frames
    times: np.ndarray  # (F,) capture time in seconds
    tracked: int  # tracked frames in the whole take
    face_lost_rows: int  # rows skipped because the app had lost the face
    malformed_rows: int


def read_take(path: Path, start: int = 0, frames: int | None = None, stride: int = 1) -> TakeWindow:
    """Frames start, start + stride, ... (at most `frames` of them) of the tracked frames."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"take not found: {path}")
    if start < 0 or stride < 1 or (frames is not None and frames < 1):
        raise ValueError("need --start >= 0, --stride >= 1 and --frames >= 1")
    csv = recorded.read_take(path)  # a Live Link Face CSV or an LLV recording
    if not csv.frames:
        raise ValueError(f"{path}: no tracked frames ({csv.face_lost_rows} face-lost rows)")
    if start >= len(csv.frames):
        raise ValueError(f"--start {start} is past the take's {len(csv.frames)} tracked frames")
    idx = np.arange(start, len(csv.frames), stride)
    if frames is not None:
        idx = idx[:frames]
    return TakeWindow(
        path=path,
        weights=np.stack([csv.frames[i].weights for i in idx]).astype(np.float32),
        frames=idx,
        times=np.array([csv.frames[i].capture_time for i in idx]),
        tracked=len(csv.frames),
        face_lost_rows=csv.face_lost_rows,
        malformed_rows=csv.malformed_rows,
    )
