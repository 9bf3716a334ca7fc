"""The newcomer's tour in docs/ARCHITECTURE.md matches the folders: its table of the native
library's areas names every folder of plugin/src and no other, and its table of the training
package names every package of softdeca_train and no other."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "ARCHITECTURE.md"


def table_folders(text: str, header: str) -> set[str]:
    """The `name/` entries of the first column of the table whose header row starts so."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(header))
    names: set[str] = set()
    for line in lines[start + 2 :]:
        if not line.startswith("|"):
            break
        first = line.split("|")[1]
        names |= set(re.findall(r"`([\w]+)/`", first))
    return names


def folders(parent: Path, package: bool = False) -> set[str]:
    return {
        p.name
        for p in parent.iterdir()
        if p.is_dir()
        and p.name != "__pycache__"
        and (not package or (p / "__init__.py").is_file())
    }


def test_the_native_areas_table_lists_every_folder_of_plugin_src() -> None:
    text = DOC.read_text(encoding="utf-8")
    assert table_folders(text, "| folder | what |") == folders(ROOT / "plugin" / "src")


def test_the_package_table_lists_every_package_of_the_training_package() -> None:
    text = DOC.read_text(encoding="utf-8")
    listed = table_folders(text, "| package | what | commands |")
    assert listed == folders(ROOT / "training" / "softdeca_train", package=True)


def test_the_tables_are_read_as_written() -> None:
    sample = "intro\n| folder | what |\n| --- | --- |\n| `a/`, `b/` | x `c/` |\n| `d/` | y |\ntext `e/`"
    assert table_folders(sample, "| folder | what |") == {"a", "b", "d"}
