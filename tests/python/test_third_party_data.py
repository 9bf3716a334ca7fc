"""Fetching the third-party data: from a mirror folder (plain files and an archive), and over
HTTP from a server on 127.0.0.1 serving a small mirror made here: checksums, resumed and
restarted partial downloads, and no half-written or unverified file ever in place."""

from __future__ import annotations

import hashlib
import io
import tarfile
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest
from softdeca_train.third_party_data import (
    DataError,
    DataFile,
    Progress,
    fetch,
    read_list,
)

REPO, COMMIT = "someone/somedata", "0123456789abcdef0123456789abcdef01234567"
CONTENT = {
    "takes/one.csv": b"Timecode,BlendShapeCount\n" + b"00:00:01:02.003,61\n" * 4000,
    "takes/LICENSE": b"MIT License\n",
    "shapes/ref.zip": bytes(range(256)) * 300,
    "head/Model/neutral.obj": b"v 0 0 0\n" * 9000,
}
ORIGIN = {p: f"upstream/{p.replace('/', '_')}" for p in CONTENT}  # origin paths differ


def entries() -> list[DataFile]:
    return [
        DataFile(p, hashlib.sha256(b).hexdigest(), REPO, COMMIT, ORIGIN[p])
        for p, b in CONTENT.items()
    ]


@dataclass
class Behaviour:
    """What the test server does: serve ranges or ignore them, cut a body short, corrupt it."""

    honour_ranges: bool = True
    cut_after: dict[str, int] = field(
        default_factory=dict
    )  # origin path -> bytes, once
    corrupt: set[str] = field(default_factory=set)
    requests: list[tuple[str, str | None]] = field(default_factory=list)
    sent: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)


class Server:
    def __init__(self, behaviour: Behaviour) -> None:
        files = {f"/{REPO}/{COMMIT}/{ORIGIN[p]}": b for p, b in CONTENT.items()}

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                rng = self.headers.get("Range")
                behaviour.requests.append((self.path, rng))
                body = files.get(self.path)
                if body is None:
                    self.send_error(404)
                    return
                origin = self.path.split(f"/{COMMIT}/", 1)[1]
                if origin in behaviour.corrupt:
                    body = body[:-1] + bytes([body[-1] ^ 1])
                start = 0
                if rng and behaviour.honour_ranges:
                    start = int(rng.removeprefix("bytes=").rstrip("-"))
                    if start >= len(body):
                        self.send_error(416)
                        return
                    self.send_response(206)
                    self.send_header(
                        "Content-Range", f"bytes {start}-{len(body) - 1}/{len(body)}"
                    )
                else:
                    self.send_response(200)
                self.send_header("Content-Length", str(len(body) - start))
                self.end_headers()
                payload = body[start:]
                cut = behaviour.cut_after.pop(origin, None)
                if cut is not None:  # announce everything, send part, hang up
                    payload = payload[:cut]
                    self.close_connection = True
                # Counted before writing: the client may have read it all and moved on
                # before this thread runs again.
                with behaviour.lock:
                    behaviour.sent += len(payload)
                self.wfile.write(payload)

            def log_message(self, *args: object) -> None:
                pass

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}"
        threading.Thread(target=self.httpd.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()


@pytest.fixture
def behaviour() -> Behaviour:
    return Behaviour()


@pytest.fixture
def server(behaviour: Behaviour) -> Iterator[Server]:
    s = Server(behaviour)
    yield s
    s.close()


QUIET = Progress(io.StringIO())


def leftovers(data: Path) -> list[str]:
    return sorted(str(p.relative_to(data)) for p in data.rglob("*.part"))


def leave_part(data: Path, path: str, content: bytes) -> None:
    """A `.part` file as an earlier, interrupted run would have left it."""
    part = data / f"{path}.part"
    part.parent.mkdir(parents=True)
    part.write_bytes(content)


def assert_complete(data: Path) -> None:
    for p, b in CONTENT.items():
        assert (data / p).read_bytes() == b, p
    assert leftovers(data) == []


def test_downloads_every_file_from_the_server(
    tmp_path: Path, server: Server, behaviour: Behaviour
) -> None:
    assert fetch(entries(), tmp_path, None, server.url, QUIET) == len(CONTENT)
    assert_complete(tmp_path)
    assert sorted(p for p, _ in behaviour.requests) == sorted(
        f"/{REPO}/{COMMIT}/{o}" for o in ORIGIN.values()
    )
    # A second run finds everything verified and asks the server for nothing.
    behaviour.requests.clear()
    assert fetch(entries(), tmp_path, None, server.url, QUIET) == 0
    assert behaviour.requests == []


def test_a_checksum_mismatch_names_the_file_and_leaves_nothing(
    tmp_path: Path, server: Server, behaviour: Behaviour
) -> None:
    behaviour.corrupt.add(ORIGIN["shapes/ref.zip"])
    with pytest.raises(
        DataError, match=r"checksum mismatch for shapes/ref.zip from http"
    ):
        fetch(entries(), tmp_path, None, server.url, QUIET)
    assert not (tmp_path / "shapes/ref.zip").exists()
    assert leftovers(tmp_path) == []


def test_an_interrupted_download_is_resumed_with_a_range_request(
    tmp_path: Path, server: Server, behaviour: Behaviour
) -> None:
    origin = ORIGIN["takes/one.csv"]
    size = len(CONTENT["takes/one.csv"])
    behaviour.cut_after[origin] = 20_000
    with pytest.raises(DataError, match="download of takes/one.csv interrupted"):
        fetch(entries(), tmp_path, None, server.url, QUIET)
    # Nothing half-written is in place; the partial bytes wait in a .part file.
    assert not (tmp_path / "takes/one.csv").exists()
    assert (tmp_path / "takes/one.csv.part").stat().st_size == 20_000
    behaviour.requests.clear()
    behaviour.sent = 0
    fetch(entries(), tmp_path, None, server.url, QUIET)
    assert_complete(tmp_path)
    asked = [r for path, r in behaviour.requests if path.endswith(origin)]
    assert asked == ["bytes=20000-"]
    others = sum(len(b) for p, b in CONTENT.items() if p != "takes/one.csv")
    assert behaviour.sent == others + size - 20_000


def test_a_partial_file_restarts_when_the_server_ignores_ranges(
    tmp_path: Path, server: Server, behaviour: Behaviour
) -> None:
    behaviour.honour_ranges = False
    leave_part(tmp_path, "takes/one.csv", CONTENT["takes/one.csv"][:5000])
    fetch(entries(), tmp_path, None, server.url, QUIET)
    assert_complete(tmp_path)


def test_a_partial_file_of_other_bytes_restarts_after_the_mismatch(
    tmp_path: Path, server: Server, behaviour: Behaviour
) -> None:
    leave_part(
        tmp_path, "head/Model/neutral.obj", b"garbage from an older version\n" * 10
    )
    fetch(entries(), tmp_path, None, server.url, QUIET)
    assert_complete(tmp_path)
    asked = [
        r for p, r in behaviour.requests if p.endswith(ORIGIN["head/Model/neutral.obj"])
    ]
    assert asked == ["bytes=300-", None]  # resumed, did not verify, fetched whole


def test_a_partial_file_longer_than_the_original_restarts(
    tmp_path: Path, server: Server
) -> None:
    leave_part(tmp_path, "takes/LICENSE", b"x" * 100)
    fetch(entries(), tmp_path, None, server.url, QUIET)
    assert_complete(tmp_path)


def test_an_altered_file_in_place_is_fetched_again(
    tmp_path: Path, server: Server
) -> None:
    fetch(entries(), tmp_path, None, server.url, QUIET)
    (tmp_path / "takes/one.csv").write_bytes(b"edited")
    assert fetch(entries(), tmp_path, None, server.url, QUIET) == 1
    assert_complete(tmp_path)


def test_a_server_error_names_the_file(tmp_path: Path, server: Server) -> None:
    missing = DataFile("takes/two.csv", "0" * 64, REPO, COMMIT, "not/there.csv")
    with pytest.raises(DataError, match=r"cannot download takes/two.csv: HTTP 404"):
        fetch([missing], tmp_path, None, server.url, QUIET)


def make_mirror(root: Path) -> Path:
    """The mirror layout: plain files, except head/ as an archive of its files."""
    mirror = root / "mirror"
    for p, b in CONTENT.items():
        if not p.startswith("head/"):
            (mirror / p).parent.mkdir(parents=True, exist_ok=True)
            (mirror / p).write_bytes(b)
    (mirror / "head").mkdir()
    with tarfile.open(mirror / "head" / "Head-Model.tar.xz", "w:xz") as tar:
        for p, b in CONTENT.items():
            if p.startswith("head/"):
                info = tarfile.TarInfo(p.removeprefix("head/"))
                info.size = len(b)
                tar.addfile(info, io.BytesIO(b))
    return mirror


def test_copies_from_a_mirror_folder_and_its_archives(tmp_path: Path) -> None:
    mirror = make_mirror(tmp_path)
    data = tmp_path / "data"
    assert fetch(entries(), data, mirror, "http://127.0.0.1:9/unused", QUIET) == len(
        CONTENT
    )
    assert_complete(data)


def test_a_mirror_with_other_bytes_or_missing_files_is_refused(tmp_path: Path) -> None:
    mirror = make_mirror(tmp_path)
    (mirror / "takes/one.csv").write_bytes(b"not the take")
    with pytest.raises(
        DataError, match=r"checksum mismatch for takes/one.csv from .*mirror"
    ):
        fetch(entries(), tmp_path / "data", mirror, "", QUIET)
    assert not (tmp_path / "data/takes/one.csv").exists()
    (mirror / "head/Head-Model.tar.xz").unlink()
    (mirror / "takes/one.csv").write_bytes(CONTENT["takes/one.csv"])
    with pytest.raises(
        DataError, match=r"lacks 1 file\(s\) of head/ \(Model/neutral.obj"
    ):
        fetch(entries(), tmp_path / "data", mirror, "", QUIET)
    assert leftovers(tmp_path / "data") == []


def test_the_committed_list_covers_what_the_project_reads() -> None:
    files = read_list()
    paths = [f.path for f in files]
    assert len(paths) == len(set(paths))
    for needed in (
        "ict-facekit/FaceXModel/generic_neutral_mesh.obj",
        "ict-facekit/FaceXModel/vertex_indices.json",
        "ict-facekit/FaceXModel/identity099.obj",
        "ict-facekit/FaceXModel/jawOpen.obj",
        "arkit-reference/ARKit_reference_blendshapes.zip",
        "arkit-reference/ARKit_landmarks68.txt",
        "recordings/livelinkface-alexdjulin/S07-001.csv",
        "recordings/livelinkface-alexdjulin/alex_rom_3.csv",
        "recordings/livelinkface-sentien/recording.csv",
        "recordings/livelinkface-llv/dao.gesichter",
    ):
        assert needed in paths
    recordings = {p.rsplit("/", 1)[0] for p in paths if p.startswith("recordings/")}
    for top in ("ict-facekit", "arkit-reference", *recordings):
        assert f"{top}/LICENSE" in paths  # each source's license travels with its data
    assert all(len(f.commit) == 40 for f in files)
