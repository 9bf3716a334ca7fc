"""Euler angles of third-party formats <-> quaternions (x, y, z, w); the same conventions as
plugin/src/stream/rotation.cpp (docs/protocol.md states them)."""

from __future__ import annotations

import math

import numpy as np


def _compose_yxz(yaw: float, pitch: float, roll: float) -> tuple[float, float, float, float]:
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    return (
        cy * sp * cr + sy * cp * sr,
        sy * cp * cr - cy * sp * sr,
        cy * cp * sr - sy * sp * cr,
        cy * cp * cr + sy * sp * sr,
    )


def _decompose_yxz(x: float, y: float, z: float, w: float) -> tuple[float, float, float]:
    r12 = 2 * (y * z - w * x)
    pitch = math.asin(min(1.0, max(-1.0, -r12)))
    yaw = math.atan2(2 * (x * z + w * y), 1 - 2 * (x * x + y * y))
    roll = math.atan2(2 * (x * y + w * z), 1 - 2 * (x * x + z * z))
    return yaw, pitch, roll


def quaternion_from_yaw_pitch_roll(yaw: float, pitch: float, roll: float) -> np.ndarray:
    """Live Link Face: yaw about +Y, pitch about +X, roll about +Z (radians), R = Ry Rx Rz."""
    return np.array(_compose_yxz(yaw, pitch, roll), dtype=np.float32)


def yaw_pitch_roll_from_quaternion(q: np.ndarray) -> tuple[float, float, float]:
    return _decompose_yxz(*(float(c) for c in q))


def quaternion_from_unity_euler_degrees(x: float, y: float, z: float) -> np.ndarray:
    """iFacialMocap: Unity's Quaternion.Euler(x, y, z) in degrees, mirrored into ARKit's
    right-handed frame (z negated)."""
    qx, qy, qz, qw = _compose_yxz(math.radians(y), math.radians(x), math.radians(z))
    return np.array((-qx, -qy, qz, qw), dtype=np.float32)


def unity_euler_degrees_from_quaternion(q: np.ndarray) -> tuple[float, float, float]:
    yaw, pitch, roll = _decompose_yxz(-float(q[0]), -float(q[1]), float(q[2]), float(q[3]))
    return math.degrees(pitch), math.degrees(yaw), math.degrees(roll)
