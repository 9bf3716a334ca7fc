"""Where the streaming tests find the native `softdeca` CLI and the Live Link Face takes."""

from __future__ import annotations

import os
from pathlib import Path

from softdeca_train.paths import default_takes_path

REPO = Path(__file__).resolve().parents[2]
CLI = os.environ.get(
    "SOFTDECA_CLI", str(REPO / "build" / "release" / "plugin" / "cli" / "softdeca")
)
TAKES = default_takes_path()

if not Path(CLI).is_file():
    raise FileNotFoundError(
        f"{CLI} is missing: run `make build` (make test does) or set SOFTDECA_CLI"
    )
