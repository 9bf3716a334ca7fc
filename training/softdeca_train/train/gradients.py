"""Per-face deformation gradients of training frames (Sumner and Popovic), the targets a
model's gradient stage is started from (train/trainable.py, train/local_fit.py)."""

from __future__ import annotations

import torch

# |G - I| bound of the per-face gradients taken from data (init_from_data, local_fit.py): a few
# sliver faces reach 30 and would own the leading modes.
GRADIENT_CLAMP = 0.3


def frame_gradients(s: torch.Tensor, t: torch.Tensor, triangles: torch.Tensor) -> torch.Tensor:
    """Per frame and face the 3x3 G with G [e1, e2, n](S) = [e1, e2, n](T), n the normal
    scaled by 1/sqrt(|e1 x e2|) (Sumner and Popovic): (B, F, 3, 3)."""

    def frames(x: torch.Tensor) -> torch.Tensor:
        x = x.double()
        e1 = x[:, triangles[:, 1]] - x[:, triangles[:, 0]]
        e2 = x[:, triangles[:, 2]] - x[:, triangles[:, 0]]
        n = torch.linalg.cross(e1, e2)
        n = n / torch.sqrt(n.norm(dim=-1, keepdim=True).clamp_min(1e-20))
        return torch.stack([e1, e2, n], dim=-1)  # columns

    vs, vt = frames(s), frames(t)
    return torch.linalg.solve(vs.transpose(-1, -2), vt.transpose(-1, -2)).transpose(-1, -2).float()
