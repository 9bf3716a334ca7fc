"""Headless rendering helpers: sizes, non-blank output, the view convention, clipping, tiling."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from PIL import Image
from softdeca_train import render as R

# An octahedron of radius 5 cm centred at the origin.
OCTA_V = 0.05 * np.array(
    [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float
)
OCTA_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                   [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])  # fmt: skip
SMALL = R.RenderSettings(size=(160, 120))


def _foreground(img: np.ndarray) -> np.ndarray:
    return np.abs(img.astype(int) - 255).sum(axis=2) > 30


def test_render_writes_png_of_the_requested_size(tmp_path):
    path = tmp_path / "octa.png"
    img = R.render(
        [R.MeshLayer(OCTA_V, OCTA_F)], "three_quarter", path=path, settings=SMALL
    )
    assert img.shape == (120, 160, 3) and img.dtype == np.uint8
    with Image.open(path) as png:
        assert png.size == (160, 120)
    fg = _foreground(img)
    assert (
        0.05 < fg.mean() < 0.9
    )  # something is drawn, and it is framed inside the image
    assert img[fg].std() > 5  # shaded, not a flat silhouette


def test_front_view_puts_the_subjects_left_on_the_viewers_right():
    # +x is the subject's own left; seen from the front it appears on the image's right.
    left = R.PointLayer(np.array([[0.04, 0.0, 0.0]]), color="red", radius=0.01)
    right = R.PointLayer(np.array([[-0.04, 0.0, 0.0]]), color="blue", radius=0.01)
    img = R.render([left, right], "front", settings=SMALL).astype(int)
    red = (img[..., 0] > 150) & (img[..., 2] < 100)
    blue = (img[..., 2] > 150) & (img[..., 0] < 100)
    assert red.any() and blue.any()
    assert np.nonzero(red)[1].mean() > 80 > np.nonzero(blue)[1].mean()


def test_clip_plane_removes_the_half_its_normal_points_into():
    full = _foreground(R.render([R.MeshLayer(OCTA_V, OCTA_F)], "front", settings=SMALL))
    clip = R.ClipPlane(origin=(0.0, 0.0, 0.0), normal=(1.0, 0.0, 0.0))
    focus = R.Focus.of([R.MeshLayer(OCTA_V, OCTA_F)])
    cut = _foreground(
        R.render(
            [R.MeshLayer(OCTA_V, OCTA_F, clip=clip)],
            "front",
            settings=SMALL,
            focus=focus,
        )
    )
    assert cut.sum() < 0.6 * full.sum()
    assert cut[:, 85:].sum() == 0  # the +x half (image right) is gone
    assert cut[:, :75].sum() > 0


def test_lines_and_opacity_render():
    pts = np.array([[-0.05, 0, 0], [0.05, 0, 0], [0, 0.05, 0]])
    img = R.render(
        [
            R.MeshLayer(OCTA_V, OCTA_F, opacity=0.3),
            R.LineLayer(pts, np.array([[0, 1], [1, 2]]), color="black", width=3),
        ],
        "front",
        settings=SMALL,
    )
    assert (img.sum(axis=2) < 100).any()  # black line pixels


def test_tile_lays_out_labelled_grid(tmp_path):
    a = np.full((50, 60, 3), 200, np.uint8)
    b = np.zeros((40, 60, 3), np.uint8)
    settings = R.TileSettings(
        columns=2, label_height=20, padding=5, extra_labels=["note"]
    )
    out = R.tile([a, b, a], ["a", "b", "c"], tmp_path / "t.png", settings)
    # 2 columns of width 60, 2 rows of 50 + 20 label, padding 5, one footer line.
    assert out.shape[1] == 2 * 60 + 3 * 5
    assert out.shape[0] == 2 * 70 + 3 * 5 + settings.font_size + 6
    assert (tmp_path / "t.png").is_file()
    with pytest.raises(ValueError, match="labels"):
        R.tile([a, b], ["only one"])
    # A label wider than its cell wraps onto more lines: the label band grows, nothing
    # overlaps the next cell.
    long = "linear blendshapes - scream - expressions, h+2.5σ, level 3"
    wrapped = R.tile([a, b], [long, "b"], None, R.TileSettings(columns=2, padding=5))
    single = R.tile([a, b], ["a", "b"], None, R.TileSettings(columns=2, padding=5))
    assert wrapped.shape[0] > single.shape[0] and wrapped.shape[1] == single.shape[1]


def test_labels_keep_their_own_line_breaks_when_wrapped(tmp_path):
    font = R._font(14)
    wrapped = R._wrap(
        "SoftDECA, frame 409\nred: 0.5 mm from linear blendshapes", font, 150
    )
    assert wrapped.startswith("SoftDECA, frame 409\nred:")
    assert all(font.getlength(line) <= 150 for line in wrapped.split("\n"))
    R.tile([np.zeros((8, 8, 3), np.uint8)], ["a\nb c"], tmp_path / "t.png")


def test_bad_input_gives_clear_errors():
    with pytest.raises(ValueError, match="triangle index"):
        R.render([R.MeshLayer(OCTA_V, OCTA_F + 10)], settings=SMALL)
    with pytest.raises(ValueError, match="unknown view"):
        R.render([R.MeshLayer(OCTA_V, OCTA_F)], "sideways", settings=SMALL)
    with pytest.raises(ValueError, match="empty"):
        R.render([R.PointLayer(np.zeros((0, 3)))], settings=SMALL)
    with pytest.raises(ValueError, match="opacity"):
        R.render([R.MeshLayer(OCTA_V, OCTA_F, opacity=2.0)], settings=SMALL)


def test_rendering_then_a_torch_optimizer_in_one_process(tmp_path) -> None:
    """Rendering (Mesa's llvmpipe brings the system's libLLVM) and then making a torch
    optimizer (torch imports triton, which carries its own LLVM) in one process: this used to
    die with SIGSEGV while loading triton. In a subprocess, so a regression fails this test
    instead of killing the test session."""
    script = (
        "import numpy as np, torch\n"
        "from softdeca_train import render\n"
        "layer = render.MeshLayer(np.eye(3), np.array([[0, 1, 2]]))\n"
        "render.render([layer])\n"
        "torch.optim.Adam([torch.zeros(1, requires_grad=True)])\n"
        "print('ok')\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script],
        check=False,
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr[-2000:]
