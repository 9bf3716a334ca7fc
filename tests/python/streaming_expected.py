"""Reader of the golden files' expected values (tests/golden/streaming/README.md)."""

from __future__ import annotations

from pathlib import Path

GOLDEN = Path(__file__).resolve().parents[1] / "golden" / "streaming"
TEXT_KEYS = {
    "format",
    "kind",
    "drop_reason",
    "device_id",
    "subject",
    "profile_name",
    "device",
    "source",
    "clock",
    "units",
}


def read_expected(path: Path) -> dict[str, dict[str, list[str] | str]]:
    """Sections ("" before the first [name]) of key -> values (text keys: the rest of the line)."""
    sections: dict[str, dict[str, list[str] | str]] = {"": {}}
    current = sections[""]
    for line in path.read_text().splitlines():
        if not line or line.startswith("#"):
            continue
        if line.startswith("[") and line.endswith("]"):
            current = sections.setdefault(line[1:-1], {})
            continue
        key, _, rest = line.partition(" ")
        current[key] = rest if key in TEXT_KEYS else rest.split()
    return sections
