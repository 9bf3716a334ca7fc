"""The streaming tools' commands: `virtual-device` (stream a take over UDP like a phone) and
`stream-golden` (the golden packets and recording of the streaming formats)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from softdeca_train.commands import Command


def _virtual_device_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("take", help="a Live Link Face CSV take or a .sdrec recording")
    p.add_argument("--host", default="127.0.0.1", help="receiver's numeric address (127.0.0.1)")
    p.add_argument(
        "--port",
        type=int,
        default=None,
        help="receiver's UDP port (default: 50110 ours, 11111 Live Link Face)",
    )
    p.add_argument("--format", choices=("softdeca", "livelinkface"), default="softdeca")
    p.add_argument(
        "--landmarks",
        choices=("softdeca149", "arkit68", "none"),
        default="softdeca149",
        help="landmark profile streamed in our protocol (from ARKit's reference face)",
    )
    p.add_argument("--speed", type=float, default=1.0, help="1 = the take's own rate")
    p.add_argument("--start", type=int, default=0, help="first frame of the take")
    p.add_argument("--count", type=int, default=None, help="frames to send (default: all)")
    p.add_argument("--fps", type=float, default=60.0, help="timecode rate of a CSV take")
    p.add_argument("--loss", type=float, default=0.0, help="probability a frame is dropped")
    p.add_argument("--duplicate", type=float, default=0.0, help="probability it is sent twice")
    p.add_argument(
        "--reorder",
        type=float,
        default=0.0,
        help="probability it is held back until after the next frame",
    )
    p.add_argument("--jitter-ms", type=float, default=0.0, help="uniform extra delay per frame")
    p.add_argument("--seed", type=int, default=0, help="seed of the impairments")
    p.add_argument("--session", type=int, default=None, help="session id (default: random)")
    p.add_argument("--log-json", default=None, help="write what went on the wire as JSON")


def _virtual_device_run(args: argparse.Namespace) -> int:
    from softdeca_train.streaming.impairments import Impairments
    from softdeca_train.streaming.virtual_device import VirtualDeviceConfig, run

    log = run(
        VirtualDeviceConfig(
            take=Path(args.take),
            host=args.host,
            port=args.port,
            format=args.format,
            landmarks=args.landmarks,
            speed=args.speed,
            start=args.start,
            count=args.count,
            timecode_rate=args.fps,
            session_id=args.session,
            progress=True,
            impairments=Impairments(
                loss=args.loss,
                duplicate=args.duplicate,
                reorder=args.reorder,
                jitter_ms=args.jitter_ms,
                seed=args.seed,
            ),
        )
    )
    print(
        f"sent {len(log.frames) - len(log.dropped)} of {len(log.frames)} frames "
        f"({len(log.datagrams)} datagrams; {len(log.dropped)} dropped, {log.duplicated} "
        f"duplicated, {log.held} held back; {log.requests_answered} requests answered)"
    )
    if args.log_json:
        Path(args.log_json).write_text(
            json.dumps(
                {
                    "session_id": log.session_id,
                    "datagrams": log.datagrams,
                    "dropped": log.dropped,
                    "duplicated": log.duplicated,
                    "held": log.held,
                    "frames": len(log.frames),
                    "requests_answered": log.requests_answered,
                }
            )
        )
    return 0


def _golden_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default="tests/golden/streaming", help="folder of the golden files")


def _golden_run(args: argparse.Namespace) -> int:
    from softdeca_train.streaming.golden import generate

    for path in generate(Path(args.out)):
        print(path)
    return 0


COMMANDS = [
    Command(
        "virtual-device",
        "Stream a take over UDP like a phone (our protocol or Live Link Face), with optional "
        "loss, duplication, reordering and jitter.",
        _virtual_device_args,
        _virtual_device_run,
    ),
    Command(
        "stream-golden",
        "Write the golden packets and recording of the streaming formats (tests/golden/streaming).",
        _golden_args,
        _golden_run,
    ),
]
