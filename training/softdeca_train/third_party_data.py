"""The third-party data the project reads (ICT-FaceKit's FaceXModel, ARKit's reference shapes,
Live Link Face takes), put into one data folder and verified file by file.

Each file listed in third_party_data.txt comes either from a local mirror folder (the same
layout as the data folder; ICT-FaceKit may be the archive ICT-FaceKit-FaceXModel.tar.xz) or
from its public origin at a pinned commit over HTTPS. Either way its sha256 must match the
list before it takes its place: downloads go to `<name>.part` (resumed with an HTTP range
request when one is left over), files are renamed into place only once verified, so a reader
never sees a half-written or unverified file.

    python -m softdeca_train.third_party_data [--data DIR] [--mirror DIR | --no-mirror]
"""

from __future__ import annotations

import argparse
import fcntl
import hashlib
import http.client
import json
import os
import shutil
import sys
import tarfile
import time
import urllib.error
import urllib.request
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from softdeca_train.paths import REPO_ROOT, data_dir

LIST = Path(__file__).with_name("third_party_data.txt")
UPSTREAM = "https://raw.githubusercontent.com"  # serves <owner>/<repo>/<commit>/<path>
CHUNK = 1 << 20
VERIFIED = ".verified.json"  # path -> [size, mtime_ns, sha256] of files already checked


class DataError(RuntimeError):
    """A data file could not be obtained or did not match its checksum."""


@dataclass(frozen=True)
class DataFile:
    path: str  # relative to the data folder (and to a mirror)
    sha256: str
    repo: str  # origin: GitHub owner/name
    commit: str
    origin_path: str  # path in that repository at that commit

    def url(self, base: str) -> str:
        return f"{base.rstrip('/')}/{self.repo}/{self.commit}/{self.origin_path}"


def read_list(path: Path = LIST) -> list[DataFile]:
    """The committed list: `sha256 path repo commit origin-path` per line, # comments."""
    files = []
    for n, line in enumerate(path.read_text().splitlines(), 1):
        if not line.strip() or line.startswith("#"):
            continue
        fields = line.split()
        if len(fields) != 5 or len(fields[0]) != 64:
            raise DataError(f"{path}:{n}: expected 'sha256 path repo commit origin-path'")
        files.append(DataFile(fields[1], fields[0], *fields[2:]))
    return files


def default_mirror() -> Path | None:
    """$SOFTDECA_DATA_MIRROR (empty: none), else ../shared beside the repository if present."""
    env = os.environ.get("SOFTDECA_DATA_MIRROR")
    if env is not None:
        return Path(env) if env else None
    shared = REPO_ROOT.parent / "shared"
    return shared if shared.is_dir() else None


class Progress:
    """One status line on a terminal (rewritten in place); a line per file otherwise."""

    def __init__(self, stream=sys.stderr) -> None:
        self.stream = stream
        self.tty = stream.isatty()
        self.last = 0.0

    def update(self, text: str, final: bool = False) -> None:
        now = time.monotonic()
        if self.tty and (final or now - self.last > 0.2):
            self.stream.write(f"\r\033[K[data] {text}" + ("\n" if final else ""))
            self.stream.flush()
            self.last = now
        elif not self.tty and final:
            print(f"[data] {text}", file=self.stream, flush=True)


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while block := f.read(CHUNK):
            h.update(block)
    return h.hexdigest()


def _mb(n: int) -> str:
    return f"{n / 1e6:.1f} MB"


def _place(part: Path, target: Path, f: DataFile, source: str) -> None:
    """Rename a finished temporary file into place if its checksum matches, else remove it."""
    got = _sha256(part)
    if got != f.sha256:
        part.unlink()
        raise DataError(
            f"checksum mismatch for {f.path} from {source}: expected sha256 {f.sha256}, "
            f"got {got}; the file was not used"
        )
    os.replace(part, target)


def _receive(
    response: http.client.HTTPResponse, part: Path, f: DataFile, have: int, progress: Progress
) -> int:
    """Append a response body to `part` after its first `have` bytes (0: start over); returns
    the size reached. An interrupted transfer leaves `part` for the next run to resume."""
    length = response.headers.get("Content-Length")
    total = have + int(length) if length else None
    done = have
    with open(part, "ab" if have else "wb") as out:
        try:
            while block := response.read(CHUNK):
                out.write(block)
                done += len(block)
                share = f" {100 * done / total:.0f} %" if total else ""
                progress.update(f"{f.path}: {_mb(done)}{share}")
        except (OSError, http.client.HTTPException) as e:
            raise DataError(f"download of {f.path} interrupted: {e!r}") from e
    if total is not None and done < total:  # the connection closed early
        raise DataError(f"download of {f.path} interrupted after {done} of {total} bytes")
    return done


def download(f: DataFile, target: Path, base: str, progress: Progress, timeout: float = 60) -> None:
    """Fetch one file over HTTP(S) into `target`, resuming a left-over `.part` when the server
    honours range requests and starting over when it does not or the result does not verify."""
    url = f.url(base)
    part = target.with_name(target.name + ".part")
    for attempt in range(2):
        have = part.stat().st_size if part.exists() else 0
        request = urllib.request.Request(url, headers={"Range": f"bytes={have}-"} if have else {})
        try:
            response = urllib.request.urlopen(request, timeout=timeout)
        except urllib.error.HTTPError as e:
            if e.code == 416 and have:  # the left-over is not a prefix we can extend
                part.unlink()
                continue
            raise DataError(f"cannot download {f.path}: HTTP {e.code} from {url}") from e
        except (urllib.error.URLError, OSError) as e:
            raise DataError(f"cannot download {f.path} from {url}: {e}") from e
        with response:
            resumed = have > 0 and response.status == 206
            done = _receive(response, part, f, have if resumed else 0, progress)
        try:
            _place(part, target, f, url)
        except DataError:
            if resumed and attempt == 0:  # the left-over may belong to other bytes: start over
                continue
            raise
        progress.update(f"{f.path}: {_mb(done)}" + (" (resumed)" if resumed else ""), True)
        return
    raise DataError(f"cannot download {f.path} from {url}")


def _mirror_archives(mirror: Path, folder: str) -> list[Path]:
    return sorted((mirror / folder).glob("*.tar*")) if (mirror / folder).is_dir() else []


def copy_from_mirror(
    files: Iterable[DataFile], data: Path, mirror: Path, progress: Progress
) -> None:
    """Copy files from a mirror folder: a plain file at the same relative path, or a member of
    an archive in the same top-level folder (its member names relative to that folder)."""
    pending: dict[str, DataFile] = {}
    for f in files:
        src = mirror / f.path
        if src.is_file():
            part = _part_for(data / f.path)
            with open(src, "rb") as i, open(part, "wb") as o:
                shutil.copyfileobj(i, o, CHUNK)
            _place(part, data / f.path, f, str(src))
        else:
            pending[f.path] = f
    by_folder: dict[str, list[DataFile]] = {}
    for f in pending.values():
        by_folder.setdefault(f.path.split("/", 1)[0], []).append(f)
    for folder, wanted in by_folder.items():
        names = {f.path.split("/", 1)[1]: f for f in wanted}
        for archive in _mirror_archives(mirror, folder):
            with tarfile.open(archive) as tar:
                for member in tar:
                    f = names.get(member.name.removeprefix("./"))
                    if f is None or not member.isfile():
                        continue
                    part = _part_for(data / f.path)
                    src = tar.extractfile(member)
                    assert src is not None  # a regular file member always has data
                    with src, open(part, "wb") as o:
                        shutil.copyfileobj(src, o, CHUNK)
                    _place(part, data / f.path, f, f"{archive}:{member.name}")
                    del names[member.name.removeprefix("./")]
                    progress.update(f"{folder}: {len(wanted) - len(names)}/{len(wanted)} files")
        if names:
            missing = ", ".join(sorted(names)[:3])
            raise DataError(
                f"the mirror {mirror} lacks {len(names)} file(s) of {folder}/ ({missing} ...), "
                f"neither as files nor in an archive {mirror / folder}/*.tar*"
            )


def _part_for(target: Path) -> Path:
    target.parent.mkdir(parents=True, exist_ok=True)
    return target.with_name(f"{target.name}.{os.getpid()}.part")


class _Verified:
    """Remembers files already hashed (by size and mtime) so that a second run is quick."""

    def __init__(self, data: Path) -> None:
        self.path = data / VERIFIED
        try:
            self.known: dict[str, list] = json.loads(self.path.read_text())
        except (OSError, ValueError):
            self.known = {}

    def ok(self, f: DataFile, target: Path) -> bool:
        if not target.is_file():
            return False
        st = target.stat()
        if self.known.get(f.path) == [st.st_size, st.st_mtime_ns, f.sha256]:
            return True
        if _sha256(target) != f.sha256:
            return False
        self.remember(f, target)
        return True

    def remember(self, f: DataFile, target: Path) -> None:
        st = target.stat()
        self.known[f.path] = [st.st_size, st.st_mtime_ns, f.sha256]

    def save(self) -> None:
        tmp = self.path.with_name(f"{VERIFIED}.{os.getpid()}")
        tmp.write_text(json.dumps(self.known, indent=0, sort_keys=True))
        os.replace(tmp, self.path)


def fetch(
    files: list[DataFile],
    data: Path,
    mirror: Path | None = None,
    base_url: str = UPSTREAM,
    progress: Progress | None = None,
) -> int:
    """Make every file of `files` present and verified under `data`; returns how many were
    fetched. One process at a time per data folder (a lock file)."""
    progress = progress or Progress()
    data = Path(os.path.realpath(data))  # .cache may be a symlink to a folder not made yet
    data.mkdir(parents=True, exist_ok=True)
    with open(data / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        verified = _Verified(data)
        todo = [f for f in files if not verified.ok(f, data / f.path)]
        for f in todo:
            if (data / f.path).exists():
                progress.update(f"{f.path} does not match its checksum: fetching it again", True)
        if todo and mirror is not None:
            progress.update(f"copying {len(todo)} file(s) from the mirror {mirror}", True)
            copy_from_mirror(todo, data, mirror, progress)
        elif todo:
            progress.update(f"downloading {len(todo)} file(s) from {base_url}", True)
            for f in todo:
                (data / f.path).parent.mkdir(parents=True, exist_ok=True)
                download(f, data / f.path, base_url, progress)
        for f in todo:
            verified.remember(f, data / f.path)
        verified.save()
    progress.update(f"{len(files)} files verified in {data} ({len(todo)} fetched)", True)
    return len(todo)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m softdeca_train.third_party_data",
        description="Fetch and verify the third-party data (ICT-FaceKit, ARKit reference "
        "shapes, Live Link Face takes) into the data folder; see THIRD_PARTY.md.",
    )
    ap.add_argument(
        "--data",
        type=Path,
        default=None,
        help="data folder (default: $SOFTDECA_DATA or .cache/data)",
    )
    src = ap.add_mutually_exclusive_group()
    src.add_argument(
        "--mirror",
        type=Path,
        default=None,
        help="local mirror folder to copy from instead of downloading "
        "(default: $SOFTDECA_DATA_MIRROR, else ../shared beside the repository if it exists)",
    )
    src.add_argument("--no-mirror", action="store_true", help="download even if a mirror exists")
    ap.add_argument(
        "--url",
        default=os.environ.get("SOFTDECA_DATA_URL", UPSTREAM),
        help="base URL serving <owner>/<repo>/<commit>/<path> (default: $SOFTDECA_DATA_URL or "
        f"{UPSTREAM})",
    )
    args = ap.parse_args(argv)
    mirror = None if args.no_mirror else (args.mirror or default_mirror())
    if mirror is not None and not mirror.is_dir():
        print(f"[data] error: the mirror {mirror} is not a folder", file=sys.stderr)
        return 1
    try:
        fetch(read_list(), args.data or data_dir(), mirror, args.url)
    except DataError as e:
        print(f"\n[data] error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
