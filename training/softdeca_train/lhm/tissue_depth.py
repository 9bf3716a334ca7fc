"""Soft-tissue thickness prior: where the skull wrap lies beneath the skin.

The paper regresses skin-to-skull distances from CT data we do not have. Instead we place the
skull wrap by published forensic soft-tissue depth tables at craniometric landmarks,
interpolated over the head: grand means of adult facial soft tissue depths after

    C. N. Stephan and E. K. Simpson, "Facial soft tissue depths in craniofacial identification
    (part I): An analytical review of the published adult data", J. Forensic Sci. 53(6),
    1257-1272, 2008 (the "T-Table"), and
    S. De Greef et al., "Large-scale in-vivo Caucasian facial soft tissue thickness database
    for craniofacial reconstruction", Forensic Sci. Int. 159S, S126-S146, 2006,

rounded to 0.5 mm (the tables' between-study spread is larger than that). Scalp and neck depths
are not craniometric: scalp thickness over the vault is taken as 6 mm, and the neck's "skull"
is a core around the cervical spine (no table; a 30 mm stand-in, documented as such).

Landmarks are located on any head in ICT topology from ICT's 68 Multi-PIE landmark vertices
(identity-independent vertex indices), so the prior follows each identity."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# name -> depth in mm (T-Table / De Greef grand means, rounded).
DEPTH_MM: dict[str, float] = {
    "glabella": 5.5,
    "nasion": 6.5,
    "rhinion": 3.0,
    "mid_philtrum": 11.5,
    "labrale_superius": 12.0,
    "labrale_inferius": 13.0,
    "mentolabial_sulcus": 11.0,
    "pogonion": 11.0,
    "menton": 7.0,
    "frontal_eminence": 5.0,
    "supraorbital": 6.0,
    "infraorbital": 6.5,
    "zygomatic": 7.0,
    "lateral_orbit": 8.0,
    "supra_m2": 24.0,
    "occlusal_line": 19.0,
    "sub_m2": 18.0,
    "mid_ramus": 17.5,
    "gonion": 16.0,
    "temporal": 11.0,
    "vertex": 6.0,
    "opisthocranion": 6.0,
    "parietal": 6.0,
    "neck": 30.0,
}


@dataclass(frozen=True)
class DepthAnchor:
    name: str
    position: np.ndarray  # (3,) metres, on the skin
    depth: float  # metres


def _closest_vertex(verts: np.ndarray, point: np.ndarray) -> int:
    return int(np.argmin(np.linalg.norm(verts - point, axis=1)))


def depth_anchors(skin: np.ndarray, lm68: np.ndarray) -> list[DepthAnchor]:
    """Craniometric landmarks on a head in ICT topology (skin = S vertices, metres)."""
    L = skin[lm68]
    up = np.array([0.0, 1.0, 0.0])
    fwd = np.array([0.0, 0.0, 1.0])
    face_h = np.linalg.norm(L[27] - L[8])  # nasion to menton, scales the rules below
    anchors: dict[str, np.ndarray] = {
        "nasion": L[27],
        "glabella": L[27] + 0.13 * face_h * up,
        "rhinion": 0.5 * (L[28] + L[29]),
        "mid_philtrum": 0.5 * (L[33] + L[51]),
        "labrale_superius": L[51],
        "labrale_inferius": L[57],
        "mentolabial_sulcus": L[57] + 0.35 * (L[8] - L[57]),
        "pogonion": L[57] + 0.7 * (L[8] - L[57]) + 0.05 * face_h * fwd,
        "menton": L[8] - 0.06 * face_h * up - 0.05 * face_h * fwd,
    }
    for side, (brow, eye_lo, eye_out, jaw_hi, jaw_ramus, jaw_angle, mouth) in {
        "right": (19, (40, 41), 36, 0, 2, 4, 48),
        "left": (24, (46, 47), 45, 16, 14, 12, 54),
    }.items():
        cheek = 0.5 * (L[mouth] + L[jaw_angle - 1 if side == "right" else jaw_angle + 1])
        anchors |= {
            f"supraorbital_{side}": L[brow],
            f"frontal_eminence_{side}": L[brow] + 0.3 * face_h * up,
            f"infraorbital_{side}": L[list(eye_lo)].mean(0) - 0.1 * face_h * up,
            f"lateral_orbit_{side}": L[eye_out] + 0.5 * (L[jaw_hi] - L[eye_out]) * 0.4,
            f"zygomatic_{side}": L[jaw_hi]
            + 0.5 * (L[jaw_hi + (1 if side == "right" else -1)] - L[jaw_hi]),
            f"temporal_{side}": L[jaw_hi] + 0.2 * face_h * up,
            f"mid_ramus_{side}": L[jaw_ramus],
            f"gonion_{side}": L[jaw_angle],
            f"occlusal_line_{side}": cheek,
            f"supra_m2_{side}": cheek + 0.12 * face_h * up,
            f"sub_m2_{side}": cheek - 0.12 * face_h * up,
        }
    # Vault and neck: extreme points of the skin (identity-dependent, topology-independent).
    top = skin[np.argmax(skin[:, 1])]
    back = skin[np.argmin(skin[:, 2] + 10.0 * np.abs(skin[:, 1] - L[27][1]))]
    anchors |= {"vertex": top, "opisthocranion": back}
    for side, sx in (("right", -1.0), ("left", 1.0)):
        anchors[f"parietal_{side}"] = skin[np.argmax(sx * skin[:, 0] + 2.0 * skin[:, 1])]
    neck_y = L[8][1] - 0.6 * face_h
    for k, ang in enumerate(np.linspace(0, 2 * np.pi, 6, endpoint=False)):
        direction = np.array([np.sin(ang), 0.0, np.cos(ang)])
        ring = np.abs(skin[:, 1] - neck_y) < 0.01
        idx = np.flatnonzero(ring)[np.argmax(skin[ring] @ direction)]
        anchors[f"neck_{k}"] = skin[idx]
    out = []
    for name, pos in anchors.items():
        base = name.rsplit("_", 1)[0] if name.rsplit("_", 1)[-1] in ("left", "right") else name
        base = "neck" if base.startswith("neck") else base
        out.append(DepthAnchor(name, skin[_closest_vertex(skin, pos)], DEPTH_MM[base] * 1e-3))
    return out


def interpolate_depth(
    anchors: list[DepthAnchor], center: np.ndarray, dirs: np.ndarray, sigma_deg: float = 14.0
) -> np.ndarray:
    """Depth per wrap direction: Gaussian-weighted average of the anchors over the angle
    between directions (smooth, bounded by the table's extremes)."""
    a_dir = np.array([a.position - center for a in anchors])
    a_dir /= np.linalg.norm(a_dir, axis=1, keepdims=True)
    depth = np.array([a.depth for a in anchors])
    ang = np.arccos(np.clip(dirs @ a_dir.T, -1.0, 1.0))
    w = np.exp(-0.5 * (ang / np.radians(sigma_deg)) ** 2) + 1e-12
    return (w * depth).sum(axis=1) / w.sum(axis=1)
