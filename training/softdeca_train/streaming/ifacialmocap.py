"""iFacialMocap's UDP text packets (docs/protocol.md): "name-value|...|=head#rx,ry,rz,px,py,pz|
rightEye#rx,ry,rz|leftEye#rx,ry,rz|", values 0-100, names with _L/_R, angles in degrees;
version 2 separates name and value with '&'. Twin of plugin/src/stream/ifacialmocap_packet.cpp."""

from __future__ import annotations

import math

import numpy as np

from softdeca_train.streaming.frame import BLENDSHAPE_COUNT, Frame, Pose, Tracking
from softdeca_train.streaming.protocol import DecodeError, DropReason
from softdeca_train.streaming.rotations import (
    quaternion_from_unity_euler_degrees,
    unity_euler_degrees_from_quaternion,
)
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

PORT = 49983
MAX_PACKET_BYTES = 8192
_UNCHANGED = {"jawLeft", "jawRight", "mouthLeft", "mouthRight"}


def wire_name(canonical: str) -> str:
    """iFacialMocap's spelling: eyeBlinkLeft -> eyeBlink_L; jawLeft and mouthLeft unchanged."""
    if canonical in _UNCHANGED:
        return canonical
    if canonical.endswith("Left"):
        return canonical[:-4] + "_L"
    if canonical.endswith("Right"):
        return canonical[:-5] + "_R"
    return canonical


_INDEX = {wire_name(n): i for i, n in enumerate(ARKIT_BLENDSHAPES)}


def _numbers(text: str, n: int) -> list[float]:
    parts = text.split(",")
    values = [float(p) for p in parts] if len(parts) == n else []
    if len(values) != n or not all(math.isfinite(v) and abs(v) < 1e6 for v in values):
        raise DecodeError(DropReason.BAD_VALUE, f"needs {n} numbers: {text!r}")
    return values


def decode_packet(data: bytes) -> tuple[Frame, np.ndarray]:
    """The frame and a (52,) bool mask of the weights the packet named."""
    if len(data) > MAX_PACKET_BYTES:
        raise DecodeError(DropReason.OVERSIZED, "packet over 8192 bytes")
    if not data:
        raise DecodeError(DropReason.UNDERSIZED, "empty datagram")
    if b"\x00" in data:
        raise DecodeError(DropReason.BAD_MAGIC, "binary data is no iFacialMocap text")
    text = data.decode("latin-1")
    frame = Frame()
    present = np.zeros(BLENDSHAPE_COUNT, dtype=bool)
    for raw in text.split("|"):
        fld = raw[1:] if raw.startswith("=") else raw
        if not fld:
            continue
        if "#" in fld:
            name, _, values = fld.partition("#")
            try:
                if name == "head":
                    v = _numbers(values, 6)
                    frame.head = Pose(
                        np.array([v[3], v[4], -v[5]], dtype=np.float32),
                        quaternion_from_unity_euler_degrees(*v[:3]),
                    )
                elif name in ("leftEye", "rightEye"):
                    v = _numbers(values, 3)
                    if frame.left_eye is None:
                        frame.left_eye, frame.right_eye = Pose(), Pose()
                    eye = frame.left_eye if name == "leftEye" else frame.right_eye
                    assert eye is not None
                    eye.rotation = quaternion_from_unity_euler_degrees(*v)
            except ValueError as e:
                raise DecodeError(DropReason.BAD_VALUE, str(e)) from e
            continue
        sep = fld.find("&")
        if sep < 0:
            sep = fld.find("-")
        if sep <= 0:
            continue  # an unnamed field
        name, value = fld[:sep], fld[sep + 1 :]
        if name != "trackingStatus" and name not in _INDEX:
            continue
        try:
            number = float(value.strip(" "))
        except ValueError as e:
            raise DecodeError(DropReason.BAD_VALUE, f"{name} is no number") from e
        if not math.isfinite(number) or abs(number) >= 1e6:
            raise DecodeError(DropReason.BAD_VALUE, f"{name} out of range")
        if name == "trackingStatus":
            frame.tracking = Tracking.TRACKED if number > 0 else Tracking.LOST
            continue
        frame.weights[_INDEX[name]] = np.float32(min(1.0, max(0.0, number / 100.0)))
        present[_INDEX[name]] = True
    if not present.any():
        raise DecodeError(DropReason.BAD_MAGIC, "no iFacialMocap blendshape in the datagram")
    return frame, present


def encode_packet(frame: Frame, separator: str = "-") -> bytes:
    """Weights rounded to integers 0-100; '-' (version 1) or '&' (version 2)."""
    if separator not in "-&" or len(separator) != 1:
        raise ValueError("iFacialMocap separates with '-' or '&'")
    parts = [
        f"{wire_name(n)}{separator}{math.floor(min(1.0, max(0.0, float(w))) * 100.0 + 0.5)}"
        for n, w in zip(ARKIT_BLENDSHAPES, np.asarray(frame.weights, dtype=np.float32), strict=True)
    ]
    head = frame.head or Pose()
    hx, hy, hz = unity_euler_degrees_from_quaternion(head.rotation)
    px, py, pz = (float(c) for c in head.position)
    parts.append(f"=head#{hx:.6f},{hy:.6f},{hz:.6f},{px:.6f},{py:.6f},{-pz:.6f}")
    for name, eye in (("rightEye", frame.right_eye), ("leftEye", frame.left_eye)):
        ex, ey, ez = unity_euler_degrees_from_quaternion((eye or Pose()).rotation)
        parts.append(f"{name}#{ex:.6f},{ey:.6f},{ez:.6f}")
    return ("|".join(parts) + "|").encode()
