"""The controls gallery's machinery on tiny cases (no simulator: the physics and the model are
small functions of the setting), the evaluation report's schema, the control ranges of
plugin/data/parameters.json, and the data plan's per-instance and regional parameters."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
from softdeca_train.controls.definitions import (
    CONTROL_REGIONS,
    Control,
    Setting,
    global_controls,
    region_controls,
)
from softdeca_train.controls.gallery import Collected, control_entry, measure_controls
from softdeca_train.controls.metrics import (
    control_response,
    identity_spread,
    leakage,
    response_error,
    rest_split,
)
from softdeca_train.controls.real_takes import (
    MILD_MM,
    FrameDistances,
    RecordedTake,
    readme_lines,
    summarise,
    validate_real_takes,
    worse_when_calm,
)
from softdeca_train.controls.report import (
    kept_real_takes,
    merge_into_report,
    validate_report,
)
from softdeca_train.parameters import load_parameters
from softdeca_train.template.regions import REGIONS

REPO = Path(__file__).resolve().parents[2]
# A tiny "face": 6 vertices, the first two in the lips.
LABELS = np.array([REGIONS.index("lips")] * 2 + [REGIONS.index("nose")] * 4)
BASE = np.zeros((2, 6, 3))  # 2 expressions


def _physics(setting: Setting) -> np.ndarray:
    """Moves every vertex along x by the global value of "a" (mm), and the vertices of a
    region along y by its local value."""
    out = BASE.copy()
    out[..., 0] += 1e-3 * setting.globals.get("a", 0.0)
    if setting.local is not None:
        _, region, value = setting.local
        out[:, LABELS == REGIONS.index(region), 1] += 1e-3 * value
    return out


def _model(scale: float, leak: float):
    """A model that follows the physics by `scale` and leaks `leak` of a local change
    to every vertex outside the region."""

    def solve(setting: Setting) -> np.ndarray:
        out = BASE + scale * (_physics(setting) - BASE)
        if setting.local is not None:
            _, region, value = setting.local
            out[:, LABELS != REGIONS.index(region), 1] += 1e-3 * leak * value
        return out

    return solve


def _entries(controls: list[Control], model) -> dict[str, dict]:
    acc = Collected()
    measure_controls(controls, _physics, model, acc)
    return {c.name: control_entry(c, acc, LABELS) for c in controls}


def test_a_control_with_zero_range_gives_zero_response() -> None:
    flat = Control("a", "a", 2.0, 2.0)
    flat_local = Control("b@lips", "b", 3.0, 3.0, region="lips")
    e = _entries([flat, flat_local], _model(1.0, 0.5))
    for name in ("a", "b@lips"):
        assert e[name]["physics_max_mm"] == 0.0 and e[name]["model_max_mm"] == 0.0
        assert e[name]["response_error"] is None  # undefined: the physics does not move
    assert e["b@lips"]["leakage"] is None


def test_response_error_and_leakage_of_global_and_region_controls() -> None:
    wide = Control("a", "a", 0.0, 2.0)
    lips = Control("b@lips", "b", 0.0, 4.0, region="lips")
    e = _entries([wide, lips], _model(0.5, 0.25))
    assert e["a"]["physics_max_mm"] == pytest.approx(2.0)
    assert e["a"]["response_error"] == pytest.approx(0.5)  # follows half the change
    assert (
        e["a"]["leakage"] is None and e["a"]["physics_leakage"] is None
    )  # global: none
    assert e["b@lips"]["physics_max_mm"] == pytest.approx(4.0)
    # inside the model moves 0.5 * 4 mm, outside 0.25 * 4 mm: leakage 0.5; the physics none
    assert e["b@lips"]["leakage"] == pytest.approx(0.5)
    assert e["b@lips"]["physics_leakage"] == pytest.approx(0.0)
    # a model that does not move: response error 1
    still = _entries([wide], lambda s: BASE.copy())
    assert still["a"]["response_error"] == pytest.approx(1.0)


def test_metrics_reject_a_region_without_vertices() -> None:
    d = np.ones((1, 4, 3))
    with pytest.raises(ValueError, match="some vertices"):
        leakage(d, np.zeros(4, bool))
    assert response_error(d, np.zeros_like(d)) is None
    r = control_response(d, d, None)
    assert r.response_error == 0.0 and r.leakage is None


def test_identity_spread_is_how_far_one_identitys_change_misses_anothers() -> None:
    a = np.zeros((2, 6, 3))
    a[..., 0] = 1e-3
    assert identity_spread([a]) is None  # one identity: nothing to compare
    assert identity_spread([a, a.copy()]) == 0.0
    # the second identity moves twice as far: a for b misses by 1/2, b for a by 1
    assert identity_spread([a, 2 * a]) == pytest.approx(0.75)
    assert identity_spread([a, np.zeros_like(a)]) is None  # one identity does not move
    with pytest.raises(ValueError, match="same cases"):
        identity_spread([a, a[:1]])
    # the gallery reports it per control: one case per identity, here both the same
    acc = Collected()
    wide = Control("a", "a", 0.0, 2.0)
    measure_controls([wide], _physics, None, acc)
    measure_controls([wide], _physics, None, acc)
    assert control_entry(wide, acc, LABELS)["identity_spread"] == 0.0


def test_a_controls_change_splits_at_rest() -> None:
    """The part at rest and what the expression adds, each judged on its own: a model whose
    expression part is worse than none shows it above 1."""
    rest = np.zeros((2, 6, 3))
    rest[..., 0] = 1e-3  # 1 mm along x at rest (repeated over the 2 expressions)
    added = np.zeros((2, 6, 3))
    added[0, :, 1], added[1, :, 1] = (
        1e-3,
        -1e-3,
    )  # each expression adds 1 mm along +y / -y
    dp = rest + added
    exact = rest_split(dp, rest, dp, rest)
    assert exact.rest_error == 0 and exact.expression_error == 0
    assert exact.expression_share == pytest.approx(np.sqrt(0.5))  # |added| = |rest|
    assert rest_split(dp, rest, rest, rest).expression_error == pytest.approx(
        1.0
    )  # none
    wrong = rest_split(dp, rest, rest - added, rest)
    assert wrong.rest_error == 0 and wrong.expression_error == pytest.approx(2.0)
    assert rest_split(dp, rest, dp, 2 * rest).rest_error == pytest.approx(1.0)
    with pytest.raises(ValueError, match="does not move"):
        rest_split(np.zeros_like(dp), rest, dp, rest)
    # the gallery's entry carries the split where the control was measured at rest too
    wide = Control("a", "a", 0.0, 2.0)
    plain, acc = Collected(), Collected(rest=Collected())
    for into in (plain, acc):
        measure_controls([wide], _physics, _model(0.5, 0.0), into)
    measure_controls([wide], _physics, _model(0.5, 0.0), acc.rest)
    assert "expression_share" not in control_entry(wide, plain, LABELS)
    e = control_entry(wide, acc, LABELS)
    assert e["rest_error"] == pytest.approx(0.5) and e["expression_share"] == 0.0
    assert e["expression_error"] is None  # the physics' expressions add nothing here


def test_controls_come_from_the_parameter_definition() -> None:
    physics = load_parameters()
    controls = physics.controls()
    # the four parameters with no elements in the head model are no controls
    for dead in (
        "w_connect_volume",
        "w_connect_strain",
        "w_skull_strain",
        "w_skull_bending",
    ):
        assert dead in physics.names and dead not in controls.names
    for s in controls.specs:
        full = physics.specs[physics.names.index(s.name)]
        assert full.minimum <= s.minimum < s.maximum <= full.maximum
        assert s.minimum <= s.default_value <= s.maximum
    names = [c.name for c in global_controls(controls)]
    assert "gravity_strength" in names and "dyn_gamma" not in names  # static gallery
    azimuth = next(c for c in global_controls(controls) if c.name == "gravity_azimuth")
    assert azimuth.hi - azimuth.lo == 180.0 and dict(azimuth.fixed)["gravity_tilt"] > 0
    regional = region_controls(controls, ("target_volume",))
    assert [c.region for c in regional] == list(CONTROL_REGIONS)
    with pytest.raises(ValueError, match="global"):
        region_controls(controls, ("gravity_strength",))


def _report() -> dict:
    return {
        "errors": {"softdeca": {"mean_mm": 0.4}},
        "controls": [
            {
                "name": "gravity_strength",
                "region": None,
                "physics_max_mm": 1.2,
                "response_error": 0.8,
                "leakage": None,
            },
            {
                "name": "target_volume@lips",
                "region": "lips",
                "physics_max_mm": 1.0,
                "response_error": None,
                "leakage": 0.3,
            },
        ],
        "real_takes": _real_takes(),
    }


def _real_takes() -> dict:
    """Two takes, the first seen in training: 3 frames each, one of them mild."""
    takes = [
        RecordedTake("source-a/seen", "0" * 64, np.zeros((3, 52), np.float32)),
        RecordedTake("source-b/unseen", "1" * 64, np.zeros((3, 52), np.float32)),
    ]
    d = FrameDistances(
        take=np.array([0, 0, 0, 1, 1, 1]),
        softdeca_mm=np.array([0.01, 0.1, 0.2, 0.05, 0.3, 0.5]),
        linear_mm=np.array([0.05, 0.2, 0.4, 0.08, 0.2, 0.6]),
    )
    return summarise(
        takes, [True, False], d, every=10, identities=1, rest=(0.04, 0.0005)
    )


def test_real_takes_are_reported_per_take_with_unseen_and_mild_frames_apart() -> None:
    real = _real_takes()
    unseen, seen = real["takes"][1], real["takes"][0]
    assert (unseen["take"], unseen["trained_on"], seen["trained_on"]) == (
        "source-b/unseen",
        False,
        True,
    )
    assert real["unseen"]["frames"] == 3 and real["seen"]["frames"] == 3
    # pooled over frames, not the mean of per-frame ratios
    assert real["unseen"]["ratio"] == pytest.approx(0.85 / 0.88)
    assert real["unseen"]["mild"]["frames"] == 1  # linear 0.08 mm <= MILD_MM
    assert real["unseen"]["strong"]["ratio"] == pytest.approx(0.8 / 0.8)
    assert real["seen"]["mild"]["frames"] == 1 and real["seen"]["strong"]["frames"] == 2
    assert real["unseen"]["worst_take_ratio"] == pytest.approx(0.85 / 0.88)
    assert MILD_MM == real["mild_mm"]


def test_calm_frames_are_reported_and_a_take_worse_there_is_named() -> None:
    real = _real_takes()
    seen, unseen = real["takes"]
    assert seen["calm"]["frames"] == 1  # linear 0.05 mm <= CALM_MM
    assert seen["calm"]["ratio"] == pytest.approx(0.01 / 0.05)
    assert unseen["calm"] is None  # no frame of it within CALM_MM
    assert worse_when_calm(real) == []
    seen["calm"]["ratio"] = 1.4
    assert worse_when_calm(real) == ["source-a/seen"]
    assert any("further from the physics" in line for line in readme_lines(real))
    older = _real_takes()  # a report made before the calm figure is read as it is
    older.pop("calm_mm")
    for t in older["takes"]:
        t.pop("calm")
    validate_real_takes(older)
    assert "calm ratio" in "".join(readme_lines(older))


def test_the_report_schema() -> None:
    validate_report(_report())
    broken = []
    for change in (
        lambda d: d.pop("errors"),
        lambda d: d.pop("controls"),
        lambda d: d["controls"][0].pop("leakage"),
        lambda d: d["controls"][0].update(
            leakage=0.1
        ),  # a global control has no leakage
        lambda d: d["controls"][1].update(physics_max_mm=-1.0),
        lambda d: d["controls"][1].update(response_error=float("nan")),
        lambda d: d["real_takes"].pop("unseen"),
        lambda d: d["real_takes"]["takes"][0].update(frames=0),
        lambda d: d["real_takes"]["takes"][1].update(linear_mm=float("nan")),
        lambda d: d["real_takes"].update(unseen=None, seen=None),
        lambda d: d["real_takes"]["rest"].update(softdeca_mm=-1.0),
    ):
        d = copy.deepcopy(_report())
        change(d)
        broken.append(d)
    for d in broken:
        with pytest.raises(ValueError, match="report"):
            validate_report(d)


@pytest.mark.skipif(
    "controls"
    not in json.loads((REPO / "docs/evaluation/evaluation.json").read_text()),
    reason="the committed report has no controls yet",
)
def test_the_committed_report_follows_the_schema() -> None:
    doc = json.loads((REPO / "docs" / "evaluation" / "evaluation.json").read_text())
    validate_report(doc)


def test_a_rerun_without_real_takes_keeps_the_reports(tmp_path) -> None:
    report = tmp_path / "evaluation.json"
    assert kept_real_takes(report) is None
    real = _real_takes()
    report.write_text(json.dumps({"errors": {}, "real_takes": real}))
    kept = kept_real_takes(report)
    report.write_text(json.dumps({"errors": {}}))  # the rerun writes its report afresh
    assert merge_into_report(report, None, kept)["real_takes"] == real


def test_the_plan_samples_p_per_instance_with_regional_patterns() -> None:
    from softdeca_train.data.config import GenerateConfig
    from softdeca_train.data.expressions import expression_sources, load_takes
    from softdeca_train.data.plan import FIXED, make_plan
    from softdeca_train.data.ranges import sampling_parameters
    from softdeca_train.paths import default_recordings_path
    from softdeca_train.template.regions import REGIONAL_DOMAINS

    cfg = GenerateConfig(static=24, dynamic=0, sparse=8, region_share=0.5, seed=3)
    assert cfg.frames_per_params == 1 and cfg.ranges == "controls"
    params = sampling_parameters(load_parameters(), cfg.ranges)
    sources, _ = expression_sources(
        load_takes(default_recordings_path()), cfg.test_takes, cfg.seed, cfg.test_share
    )
    plan = make_plan(cfg, params, sources)
    groups = [(s.kind, g) for s in plan for g in s.groups]
    assert all(len(g.frames.weights) == 1 for _, g in groups)  # one p per instance
    ps = np.stack([g.p for _, g in groups])
    assert len({row.tobytes() for row in ps}) == len(ps)
    names = params.names
    dead = [names.index(n) for n in ("w_skull_strain", "w_connect_volume")]
    assert np.all(ps[:, dead] == params.defaults()[dead])  # no controls: defaults
    patterns = [(k, g) for k, g in groups if g.p_regions is not None]
    assert 0 < len(patterns) < len(groups)
    rows = [REGIONS.index(r) for r in CONTROL_REGIONS]
    others = [i for i in range(len(REGIONS)) if i not in rows]
    for kind, g in patterns:
        params.validate(g.p_regions)
        assert np.all(g.p_regions[others] == g.p)  # inner regions keep p
        varied = np.flatnonzero(np.any(g.p_regions != g.p, axis=0))
        for k in varied:
            s = params.specs[k]
            assert s.domain in REGIONAL_DOMAINS and s.control is not None
            assert s.name not in FIXED[kind]
    # legacy configurations (written before regional patterns) have none
    legacy = {k: v for k, v in cfg.as_dict().items() if k != "region_share"}
    assert GenerateConfig.from_dict(legacy).region_share == 0.0


def test_contrasts_share_frames_and_change_one_factor() -> None:
    from softdeca_train.data.config import GenerateConfig
    from softdeca_train.data.expressions import expression_sources, load_takes
    from softdeca_train.data.plan import FIXED, make_plan
    from softdeca_train.data.ranges import sampling_parameters
    from softdeca_train.paths import default_recordings_path

    cfg = GenerateConfig(
        static=30, dynamic=0, sparse=0, seed=4, frames_per_params=2, params_per_identity=4,
        contrasts=True,
    )  # fmt: skip
    params = sampling_parameters(load_parameters(), cfg.ranges)
    sources, _ = expression_sources(
        load_takes(default_recordings_path()), cfg.test_takes, cfg.seed, cfg.test_share
    )
    plan = make_plan(cfg, params, sources)
    regional = changed = 0
    for shard in plan:
        first, *rest = shard.groups
        for g in rest:
            n = len(g.frames.weights)
            assert np.array_equal(g.frames.weights, first.frames.weights[:n])
            a, b = (
                x.p_regions
                if x.p_regions is not None
                else np.repeat(x.p[None], len(REGIONS), 0)
                for x in (first, g)
            )
            moved = np.flatnonzero(np.any(a != b, axis=0))
            assert len(moved) <= 1  # one factor (a redraw may land on the same value)
            for k in moved:
                assert params.specs[k].name not in FIXED["static"]
                changed += 1
                regional += int(np.array_equal(g.p, first.p))
    assert changed > 0 and 0 < regional < changed
    # the last shard has fewer instances than the others: its groups still share frames
    assert sum(s.instances for s in plan) == cfg.static
    # datasets written before contrasts existed have none
    legacy = {k: v for k, v in cfg.as_dict().items() if k != "contrasts"}
    assert not GenerateConfig.from_dict(legacy).contrasts


def test_the_report_readme_section_is_replaced_not_repeated(tmp_path) -> None:
    from softdeca_train.controls.report import SECTION, update_readme

    readme = tmp_path / "README.md"
    readme.write_text("# Evaluation\n\ntext\n")
    update_readme(readme, _report())
    update_readme(readme, _report())
    text = readme.read_text()
    assert text.startswith("# Evaluation\n\ntext\n") and text.count(SECTION) == 1
    assert "median response error 0.800" in text and "target_volume@lips" in text
    # unseen takes first, each pooled figure labelled
    assert text.index("| source-b/unseen | no |") < text.index(
        "| source-a/seen | yes |"
    )
    assert "| **unseen takes, pooled** |  | 3 | 0.283 | 0.293 | 0.97 |" in text
    assert "in-distribution takes, pooled" in text
    assert "At rest (every weight 0) SoftDECA is 0.040 mm from the physics" in text


def test_the_gallery_page_names_the_tolerance_and_the_identity_spread() -> None:
    from dataclasses import asdict

    from softdeca_train.controls.gallery import GalleryConfig
    from softdeca_train.controls.pictures import markdown

    cfg = GalleryConfig(pictures=False, tolerance=2e-5)
    entry = {
        **{k: None for k in ("region", "leakage", "physics_leakage")},
        "name": "a",
        "lo": 0.0,
        "hi": 1.0,
        "unit": "",
        "physics_max_mm": 1.0,
        "physics_mean_mm": 0.5,
        "model_max_mm": 0.4,
        "response_error": 0.5,
        "identity_spread": 0.25,
    }
    config = {k: str(v) if isinstance(v, Path) else v for k, v in asdict(cfg).items()}
    page = markdown(
        cfg,
        {
            "config": config,
            "identity_seeds": [101, 202],
            "expressions": [[0.0] * 52] * 3,
            "controls": [entry],
            "seconds": 1.0,
        },
    )
    assert "tolerance of 2e-05" in page and "| identity spread |" in page
    assert "| 0.50 | 0.25 | – | – |" in page


def test_the_physics_cache_keys_on_inputs_and_physics_version(tmp_path) -> None:
    from softdeca_train.controls.physics_cache import PhysicsCache, physics_version

    cache = PhysicsCache(tmp_path / "c", "v1")
    a = np.arange(6.0).reshape(2, 3)
    key = cache.key((a,), {"setting": {"a": 1.0}})
    assert cache.get(key) is None
    cache.put(key, a * 2)
    np.testing.assert_array_equal(cache.get(key), a * 2)
    # any input, setting or physics version change is another entry
    assert cache.key((a + 1,), {"setting": {"a": 1.0}}) != key
    assert cache.key((a,), {"setting": {"a": 2.0}}) != key
    assert PhysicsCache(tmp_path / "c", "v2").key((a,), {"setting": {"a": 1.0}}) != key
    # a damaged entry is solved again, not trusted
    (tmp_path / "c" / f"{key}.npy").write_bytes(b"not an array")
    assert cache.get(key) is None
    # off (uncommitted physics changes): nothing read or written
    off = PhysicsCache(tmp_path / "off", None)
    off.put(key, a)
    assert off.get(key) is None and not (tmp_path / "off").exists()
    # outside a git checkout there is no version to trust
    assert physics_version(tmp_path) is None


def test_the_physics_version_ignores_control_ranges_only() -> None:
    from softdeca_train.controls.physics_cache import physics_parameters
    from softdeca_train.paths import REPO_ROOT

    text = (REPO_ROOT / "plugin" / "data" / "parameters.json").read_text()
    data = json.loads(text)
    spec = next(p for p in data["parameters"] if p["control"] is not None)
    spec["control"] = None  # no control any more: the same physics
    assert physics_parameters(json.dumps(data)) == physics_parameters(text)
    spec["default"] *= 1.5  # another default: other physics
    assert physics_parameters(json.dumps(data)) != physics_parameters(text)
