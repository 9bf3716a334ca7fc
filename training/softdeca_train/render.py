"""Headless renders of meshes, point sets and polylines (pyvista/VTK offscreen, EGL), and tiling
of several renders into one labelled PNG. Shared by every step that writes pictures.

Coordinates are the product's frame (docs/ARCHITECTURE.md, Conventions): metres, +Y up,
+Z out of the face, +X the subject's own left. Named views look at the subject from that
frame's directions, so "front" shows the face and "side" the subject's left profile.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

# VTK picks its window class when it is imported; without a display only EGL (or OSMesa)
# works. The Makefile exports this too; setting it here keeps plain `python -m` runs working.
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

Color = str | tuple[float, float, float]


def _pyvista():  # -> the pyvista module
    """pyvista, imported only after triton (when installed). Rendering loads Mesa's llvmpipe,
    which brings the system's libLLVM into the process with global symbols. Triton carries
    its own LLVM; loaded afterwards (torch imports it through torch._dynamo the first time an
    optimizer is made), its static initialisers bind to the system LLVM's symbols and the
    process dies with SIGSEGV in llvm::cl::Option::addArgument. Loaded first, triton binds to
    its own copy (Python loads extensions with RTLD_NOW) and both coexist."""
    if importlib.util.find_spec("triton") is not None:
        with contextlib.suppress(ImportError):
            import triton  # noqa: F401
    import pyvista as pv  # VTK loads slowly: only pictures pay for it

    return pv


@dataclass(frozen=True)
class View:
    """A camera: `direction` points from the focus to the camera, `up` is the screen's up."""

    direction: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 1.0, 0.0)


VIEWS: dict[str, View] = {
    "front": View((0.0, 0.0, 1.0)),
    "side": View((1.0, 0.0, 0.0)),  # the subject's left profile
    "side_right": View((-1.0, 0.0, 0.0)),
    "three_quarter": View((0.64, 0.12, 0.76)),  # from the subject's left, slightly above
    "three_quarter_right": View((-0.64, 0.12, 0.76)),
    "back": View((0.0, 0.0, -1.0)),
    "top": View((0.0, 1.0, 0.0), up=(0.0, 0.0, -1.0)),
}


@dataclass(frozen=True)
class ClipPlane:
    """Cut-away: removes the half-space the normal points into, keeps (x - origin)·n <= 0."""

    origin: tuple[float, float, float]
    normal: tuple[float, float, float]


@dataclass
class MeshLayer:
    vertices: np.ndarray  # (V, 3)
    triangles: np.ndarray  # (F, 3)
    color: Color = "lightgray"
    opacity: float = 1.0
    clip: ClipPlane | None = None
    smooth: bool = True
    show_edges: bool = False
    edge_color: Color = "dimgray"
    # Per-vertex values drawn through a colour map instead of `color` (e.g. errors in mm).
    scalars: np.ndarray | None = None
    cmap: str = "inferno"
    clim: tuple[float, float] | None = None
    scalar_bar: str | None = None  # title of a colour bar, None: no bar


@dataclass
class PointLayer:
    """Points drawn as spheres of `radius` metres (real geometry, so they sit on surfaces
    instead of z-fighting with them)."""

    points: np.ndarray  # (N, 3)
    color: Color = "red"
    radius: float = 0.0012
    opacity: float = 1.0
    clip: ClipPlane | None = None


@dataclass
class LineLayer:
    """Polylines: `segments` are pairs of indices into `points`."""

    points: np.ndarray  # (N, 3)
    segments: np.ndarray  # (M, 2)
    color: Color = "black"
    width: float = 2.0
    opacity: float = 1.0


Layer = MeshLayer | PointLayer | LineLayer


@dataclass(frozen=True)
class RenderSettings:
    size: tuple[int, int] = (800, 800)  # width, height in pixels
    background: Color = "white"
    view_angle_deg: float = 30.0
    margin: float = 1.08  # >1 leaves room around the framed box
    anti_aliasing: bool = True


@dataclass(frozen=True)
class Focus:
    """What the camera frames: an axis-aligned box. Share one between renders to keep them
    comparable (same scale and centre for the same view)."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]

    @staticmethod
    def of(layers: Sequence[Layer]) -> Focus:
        pts = [
            np.asarray(lay.vertices if isinstance(lay, MeshLayer) else lay.points, float)
            for lay in layers
        ]
        pts = [p.reshape(-1, 3) for p in pts if p.size]
        if not pts:
            raise ValueError("nothing to render: every layer is empty")
        allp = np.concatenate(pts)
        return Focus(tuple(allp.min(axis=0)), tuple(allp.max(axis=0)))

    def corners(self) -> np.ndarray:
        lo, hi = np.asarray(self.lo), np.asarray(self.hi)
        return np.array([[(lo, hi)[i >> k & 1][k] for k in range(3)] for i in range(8)])


def _check_layer(layer: Layer) -> None:
    if isinstance(layer, MeshLayer):
        v, t = np.asarray(layer.vertices), np.asarray(layer.triangles)
        if v.ndim != 2 or v.shape[1] != 3 or t.ndim != 2 or t.shape[1] != 3:
            raise ValueError(
                f"mesh layer needs (V,3) vertices and (F,3) triangles, got {v.shape} and {t.shape}"
            )
        if t.size and (t.min() < 0 or t.max() >= len(v)):
            raise ValueError("mesh layer: triangle index outside the vertex array")
        if layer.scalars is not None and np.shape(layer.scalars) != (len(v),):
            raise ValueError(f"mesh layer: need one scalar per vertex ({len(v)})")
    elif isinstance(layer, LineLayer):
        s = np.asarray(layer.segments)
        if s.size and (
            s.ndim != 2 or s.shape[1] != 2 or s.min() < 0 or s.max() >= len(layer.points)
        ):
            raise ValueError("line layer: segments must be (M,2) indices into points")
    if not 0.0 <= layer.opacity <= 1.0:
        raise ValueError(f"opacity must be in [0, 1], got {layer.opacity}")


def _polydata(layer: Layer):  # -> pv.PolyData | None
    pv = _pyvista()

    if isinstance(layer, MeshLayer):
        t = np.asarray(layer.triangles, dtype=np.int64)
        faces = np.hstack([np.full((len(t), 1), 3, np.int64), t]).ravel()
        mesh = pv.PolyData(np.asarray(layer.vertices, dtype=np.float64), faces)
        if layer.scalars is not None:  # point data survives the clip below
            mesh.point_data["values"] = np.asarray(layer.scalars, dtype=np.float64)
    elif isinstance(layer, PointLayer):
        pts = np.asarray(layer.points, dtype=np.float64).reshape(-1, 3)
        if not len(pts):
            return None
        mesh = pv.PolyData(pts).glyph(
            geom=pv.Sphere(radius=layer.radius, theta_resolution=12, phi_resolution=12),
            scale=False,
            orient=False,
        )
    else:
        seg = np.asarray(layer.segments, dtype=np.int64).reshape(-1, 2)
        if not len(seg):
            return None
        lines = np.hstack([np.full((len(seg), 1), 2, np.int64), seg]).ravel()
        mesh = pv.PolyData(np.asarray(layer.points, dtype=np.float64), lines=lines)
    clip = getattr(layer, "clip", None)
    if clip is not None:
        # pyvista's clip keeps the side the normal points away from when invert=True.
        mesh = mesh.clip(normal=clip.normal, origin=clip.origin, invert=True)
        if mesh.n_points == 0:
            return None
    return mesh


def _fit_camera(
    view: View, focus: Focus, settings: RenderSettings
) -> tuple[np.ndarray, np.ndarray]:
    """Camera position and focal point so that the focus box, seen from `view`, fills the
    image up to the margin."""
    d = np.asarray(view.direction, dtype=np.float64)
    d /= np.linalg.norm(d)
    right = np.cross(np.asarray(view.up, dtype=np.float64), d)
    right /= np.linalg.norm(right)
    up = np.cross(d, right)
    c = focus.corners()
    u, v, w = c @ right, c @ up, c @ d
    center = (
        right * (u.min() + u.max()) / 2 + up * (v.min() + v.max()) / 2 + d * (w.min() + w.max()) / 2
    )
    aspect = settings.size[0] / settings.size[1]
    half_h = max((v.max() - v.min()) / 2, (u.max() - u.min()) / 2 / aspect, 1e-6)
    tan_half = np.tan(np.radians(settings.view_angle_deg) / 2)
    # Distance from the box's near face so that its projected height fits the view angle.
    distance = half_h * settings.margin / tan_half + (w.max() - w.min()) / 2
    return center + d * distance, center


def render(
    layers: Sequence[Layer],
    view: str | View = "front",
    path: str | os.PathLike[str] | None = None,
    settings: RenderSettings | None = None,
    focus: Focus | None = None,
    title: str | None = None,
) -> np.ndarray:
    """Render layers from a named (or explicit) view; returns the RGB image (H, W, 3) uint8
    and writes it as PNG to `path` if given."""
    pv = _pyvista()

    settings = settings or RenderSettings()
    if isinstance(view, str):
        if view not in VIEWS:
            raise ValueError(f"unknown view {view!r}; known: {', '.join(VIEWS)}")
        view = VIEWS[view]
    for layer in layers:
        _check_layer(layer)
    focus = focus or Focus.of(layers)

    plotter = pv.Plotter(off_screen=True, window_size=list(settings.size))
    try:
        plotter.set_background(settings.background)
        for layer in layers:
            mesh = _polydata(layer)
            if mesh is None:
                continue
            if isinstance(layer, MeshLayer) and layer.scalars is not None:
                plotter.add_mesh(
                    mesh,
                    scalars="values",
                    cmap=layer.cmap,
                    clim=layer.clim,
                    opacity=layer.opacity,
                    smooth_shading=layer.smooth,
                    specular=0.2,
                    show_scalar_bar=layer.scalar_bar is not None,
                    scalar_bar_args={"title": layer.scalar_bar or "", "color": "black"},
                )
            elif isinstance(layer, MeshLayer):
                plotter.add_mesh(
                    mesh,
                    color=layer.color,
                    opacity=layer.opacity,
                    smooth_shading=layer.smooth,
                    show_edges=layer.show_edges,
                    edge_color=layer.edge_color,
                    specular=0.2,
                )
            elif isinstance(layer, PointLayer):
                plotter.add_mesh(
                    mesh, color=layer.color, opacity=layer.opacity, smooth_shading=True
                )
            else:
                plotter.add_mesh(
                    mesh,
                    color=layer.color,
                    opacity=layer.opacity,
                    line_width=layer.width,
                    lighting=False,
                )
        position, center = _fit_camera(view, focus, settings)
        plotter.camera.view_angle = settings.view_angle_deg
        plotter.camera_position = [tuple(position), tuple(center), view.up]
        plotter.reset_camera_clipping_range()
        if settings.anti_aliasing:
            plotter.enable_anti_aliasing("ssaa")  # FXAA is unsupported on EGL
        if title:
            plotter.add_text(title, position="upper_left", font_size=12, color="black")
        image = np.asarray(plotter.screenshot(return_img=True))[..., :3].copy()
    finally:
        plotter.close()
    if path is not None:
        save_png(image, path)
    return image


def save_png(image: np.ndarray, path: str | os.PathLike[str]) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.asarray(image, dtype=np.uint8)).save(path)
    return path


@dataclass
class TileSettings:
    columns: int | None = None  # None: all in one row
    label_height: int = 28
    font_size: int = 18
    padding: int = 6
    background: Color = "white"
    label_color: Color = "black"
    extra_labels: list[str] = field(default_factory=list)  # footer lines, e.g. measurements


def _font(size: int) -> ImageFont.ImageFont | ImageFont.FreeTypeFont:
    # DejaVu Sans (shipped with matplotlib) has the Greek labels use (σ of the identities);
    # Pillow's own default font draws them as boxes.
    try:
        from matplotlib import font_manager  # only for its font file

        return ImageFont.truetype(font_manager.findfont("DejaVu Sans"), size)
    except (ImportError, OSError, ValueError):
        pass
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1 has no sized default font
        return ImageFont.load_default()


def _wrap(text: str, font: ImageFont.ImageFont | ImageFont.FreeTypeFont, width: float) -> str:
    """`text` broken at spaces into lines no wider than `width` pixels where it can be; its own
    line breaks kept (a font measures one line at a time)."""
    lines: list[str] = []
    for paragraph in text.split("\n"):
        start = len(lines)
        for word in paragraph.split(" "):
            if len(lines) > start and font.getlength(f"{lines[-1]} {word}") <= width:
                lines[-1] = f"{lines[-1]} {word}"
            else:
                lines.append(word)
    return "\n".join(lines)


def tile(
    images: Sequence[np.ndarray | str | os.PathLike[str]],
    labels: Sequence[str] | None = None,
    path: str | os.PathLike[str] | None = None,
    settings: TileSettings | None = None,
) -> np.ndarray:
    """Lay renders out on a grid, each under its label, with optional footer lines; returns the
    RGB image and writes it as PNG to `path` if given."""
    settings = settings or TileSettings()
    if not images:
        raise ValueError("tile needs at least one image")
    imgs = [
        np.asarray(Image.open(i).convert("RGB"))
        if isinstance(i, str | os.PathLike)
        else np.asarray(i, dtype=np.uint8)[..., :3]
        for i in images
    ]
    labels = list(labels) if labels is not None else [""] * len(imgs)
    if len(labels) != len(imgs):
        raise ValueError(f"{len(imgs)} images but {len(labels)} labels")
    cols = settings.columns or len(imgs)
    rows = -(-len(imgs) // cols)
    cell_w = max(i.shape[1] for i in imgs)
    font = _font(settings.font_size)
    # Labels wider than their cell wrap onto more lines (they overlapped the next cell).
    labels = [_wrap(label, font, cell_w - 8) for label in labels]
    line_h = settings.font_size + 4
    label_h = settings.label_height + line_h * max(t.count("\n") for t in labels)
    cell_h = max(i.shape[0] for i in imgs) + label_h
    pad = settings.padding
    footer = len(settings.extra_labels) * (settings.font_size + 6)
    width = cols * cell_w + (cols + 1) * pad
    height = rows * cell_h + (rows + 1) * pad + footer
    canvas = Image.new("RGB", (width, height), settings.background)
    draw = ImageDraw.Draw(canvas)
    for k, (img, label) in enumerate(zip(imgs, labels, strict=True)):
        r, c = divmod(k, cols)
        x = pad + c * (cell_w + pad)
        y = pad + r * (cell_h + pad)
        draw.multiline_text((x + 4, y + 4), label, fill=settings.label_color, font=font, spacing=4)
        canvas.paste(Image.fromarray(img), (x, y + label_h))
    y = rows * cell_h + (rows + 1) * pad
    for line in settings.extra_labels:
        draw.text((pad + 4, y), line, fill=settings.label_color, font=font)
        y += settings.font_size + 6
    out = np.asarray(canvas)
    if path is not None:
        save_png(out, path)
    return out
