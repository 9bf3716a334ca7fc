"""The gallery's pictures and page: per control the change between the ends of its range on
the physics and on the model (one colour scale), and at the top end the distance of the model
and of the linear blendshapes to the physics; the summary figures over all controls."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image
from tqdm import tqdm

from softdeca_train.controls.cases import PhysicsCase
from softdeca_train.controls.definitions import Control
from softdeca_train.render import MeshLayer, RenderSettings, TileSettings, render, tile

SIZE = (220, 220)


def _fmt(x: float | None, digits: int = 3) -> str:
    return "–" if x is None else f"{x:.{digits}f}"


def _heat(shape: np.ndarray, tris: np.ndarray, mm: np.ndarray, vmax: float) -> np.ndarray:
    layer = MeshLayer(shape, tris, scalars=mm, clim=(0.0, vmax))
    return render([layer], "three_quarter", settings=RenderSettings(size=SIZE))


def control_picture(
    path: Path, c: Control, shown: dict[str, np.ndarray], case: PhysicsCase
) -> None:
    """One row per expression: physics change, model change, and at the top of the range
    |model - physics| and |linear - physics| (mm)."""
    tris = case.template.skin_triangles
    d_phys = 1e3 * np.linalg.norm(shown["physics"] - shown["lo"], axis=-1)
    has_model = "model" in shown
    d_model = (
        1e3 * np.linalg.norm(shown["model"] - shown["model_lo"], axis=-1) if has_model else None
    )
    # the change on one scale (a region's change fills the colours), the distances to the
    # physics at the top of the range on another
    vmax = max(float(np.percentile(d_phys, 99.9)), 1e-3)
    lin = 1e3 * np.linalg.norm(case.targets - shown["physics"], axis=-1)
    emax = max(float(np.percentile(lin, 99)), 1e-3)
    images, labels = [], []
    for e in range(len(d_phys)):
        shape = shown["physics"][e]
        images.append(_heat(shape, tris, d_phys[e], vmax))
        labels.append(f"physics change, max {d_phys[e].max():.2f}")
        if d_model is not None:
            images.append(_heat(shape, tris, d_model[e], vmax))
            labels.append(f"SoftDECA change, max {d_model[e].max():.2f}")
            err = 1e3 * np.linalg.norm(shown["model"][e] - shape, axis=-1)
            images.append(_heat(shape, tris, err, emax))
            labels.append(f"|SoftDECA - physics|, mean {err.mean():.2f}")
        images.append(_heat(shape, tris, lin[e], emax))
        labels.append(f"|linear - physics|, mean {lin[e].mean():.2f}")
    cols = 4 if d_model is not None else 2
    footer = (
        f"{c.name}: {c.lo:g} -> {c.hi:g} {c.unit} (rows: expressions); inferno colours: change "
        f"0-{vmax:.2f} mm, distance to the physics at {c.hi:g}: 0-{emax:.2f} mm"
    )
    sheet = tile(
        images,
        labels,
        None,
        TileSettings(columns=cols, font_size=13, label_height=20, extra_labels=[footer]),
    )
    # 256 colours keep a sheet of heat maps a few hundred kB at most (committed to docs/)
    Image.fromarray(sheet).quantize(256).save(path, optimize=True)


def summary_figure(path: Path, entries: list[dict]) -> None:
    import matplotlib  # loads slowly: only this figure uses it

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after the backend is chosen

    names = [e["name"] for e in entries]
    fig, axes = plt.subplots(3, 1, figsize=(10, 9), sharex=True)
    y = np.arange(len(names))
    axes[0].bar(y, [e["physics_max_mm"] for e in entries], color="tab:blue")
    axes[0].axhline(1.0, color="k", lw=0.8, ls="--")
    axes[0].set_ylabel("physics max change (mm)")
    axes[0].set_yscale("log")
    axes[1].bar(
        y, [np.nan if e["response_error"] is None else e["response_error"] for e in entries]
    )
    spread = [e["identity_spread"] for e in entries]
    axes[1].plot(
        y, [np.nan if v is None else v for v in spread], "k_", ms=14, label="identity spread"
    )
    axes[1].legend(loc="upper right", fontsize=8)
    axes[1].axhline(0.3, color="k", lw=0.8, ls="--")
    axes[1].set_ylabel("response error")
    axes[2].bar(
        y, [np.nan if e["leakage"] is None else e["leakage"] for e in entries], color="tab:red"
    )
    axes[2].axhline(0.2, color="k", lw=0.8, ls="--")
    axes[2].set_ylabel("leakage (SoftDECA)")
    axes[2].set_xticks(y, names, rotation=70, ha="right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def draw_gallery(
    out: Path,
    controls: list[Control],
    shown: dict[str, dict[str, np.ndarray]],
    case: PhysicsCase,
    entries: list[dict],
    progress: bool = True,
    complete: bool = False,
) -> None:
    """One picture per control and the summary; with `complete` (every control drawn) the
    folder's other pictures, of controls the gallery no longer has, are removed."""
    out.mkdir(parents=True, exist_ok=True)
    drawn = {out / "summary.png"}
    for c in tqdm(controls, desc="pictures", disable=not progress):
        path = out / f"{c.name.replace('@', '-')}.png"
        control_picture(path, c, shown[c.name], case)
        drawn.add(path)
    summary_figure(out / "summary.png", entries)
    if complete:
        for old in set(out.glob("*.png")) - drawn:
            old.unlink()


def markdown(cfg, result: dict) -> str:  # cfg: GalleryConfig
    c = result["config"]
    lines = [
        "# Controls gallery",
        "",
        "Every control moved from the bottom to the top of its range, everything else at its "
        f"default, on {len(result['identity_seeds'])} identities no dataset holds (seeds "
        f"{', '.join(map(str, result['identity_seeds']))}) x {len(result['expressions'])} "
        "expressions of the held-out take (widest jaw opening, broadest smile, strongest "
        f"pucker); LHM level {c['level']}, static frames, physics solved to a tolerance of "
        f"{c['tolerance']:g}, {c['ranges']} ranges; model: "
        f"`{c['bundle']}`. Written by `python -m softdeca_train controls` "
        f"({result['seconds']:.0f} s); docs/controls.md says what the figures mean.",
        "",
        "| control | region | range | physics max (mm) | physics mean (mm) | SoftDECA max (mm) "
        "| response error | identity spread | leakage | physics leakage |",
        "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for e in result["controls"]:
        rng = f"{e['lo']:g} – {e['hi']:g} {e['unit']}".strip()
        if e.get("model_clamped"):
            rng += " (model clamped to its trained range)"
        lines.append(
            f"| {e['name']} | {e['region'] or 'global'} | {rng} | {_fmt(e['physics_max_mm'])} "
            f"| {_fmt(e['physics_mean_mm'])} | {_fmt(e['model_max_mm'])} "
            f"| {_fmt(e['response_error'], 2)} | {_fmt(e['identity_spread'], 2)} "
            f"| {_fmt(e['leakage'], 2)} "
            f"| {_fmt(e['physics_leakage'], 2)} |"
        )
    if cfg.pictures:
        lines += ["", "![summary](summary.png)", ""]
        for e in result["controls"]:
            name = e["name"].replace("@", "-")
            lines += [f"## {e['name']}", "", f"![{e['name']}]({name}.png)", ""]
    return "\n".join(lines) + "\n"
