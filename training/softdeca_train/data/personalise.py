"""The augmentation σ of the sparse data (paper eq. 24): landmarks observed on another head,
personalised to the simulated head, then coordinate-wise Gaussian noise.

Personalisation is the same map as the runtime's retargeting (docs/ARCHITECTURE.md,
Conventions): the donor's landmark offsets from its own neutral, L'_t - L'_0, are carried
over by the similarity (s, R) that best maps the donor's neutral landmarks onto the simulated head's
neutral landmarks (Umeyama, least squares over all landmarks), and added to the simulated
head's neutral landmarks:

    σ(L'_t) = L_0 + s R (L'_t - L'_0) + ε,   ε ~ N(0, noise² I) per coordinate.

It is a deformation transfer at the landmark level: an expression's motion, rotated and
scaled to the new face. The donor is another sampled ICT identity making the same expression
(ARKit weights), so the data hold the same kind of mismatch as a user's face driving an avatar.
"""

from __future__ import annotations

import numpy as np

from softdeca_train.landmarks.registration import umeyama


def personalise(
    donor_neutral: np.ndarray, donor_frames: np.ndarray, target_neutral: np.ndarray
) -> np.ndarray:
    """(L, 3) donor neutral landmarks, (F, L, 3) donor frames, (L, 3) target neutral ->
    (F, L, 3) landmarks on the target head."""
    sim = umeyama(donor_neutral, target_neutral)
    offsets = np.asarray(donor_frames) - np.asarray(donor_neutral)[None]
    return np.asarray(target_neutral)[None] + sim.scale * offsets @ sim.rotation.T


def add_noise(landmarks: np.ndarray, sigma_m: float, seed: int) -> np.ndarray:
    if sigma_m == 0:
        return np.array(landmarks, dtype=np.float64)
    rng = np.random.default_rng(seed)
    return landmarks + rng.normal(0.0, sigma_m, np.shape(landmarks))
