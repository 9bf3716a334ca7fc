"""The physics sanity bounds and the stress suite: the bounds' definitions, the expression
library, a reduced suite (LHM level 3, two identities) and the snarl frame that once exploded."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from bounds import above, below
from softdeca_train.sim.expressions import (
    COMBINATIONS,
    SNARL,
    combinations,
    single_shapes,
)
from softdeca_train.sim.sanity import BOUNDS, FrameCheck, bench_figures, failure_counts
from softdeca_train.sim.stress import (
    StressCase,
    StressPlan,
    build_cases,
    parse_material,
    run_stress,
    run_stress_parallel,
)
from softdeca_train.template import Template
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

LEVEL = 3
IDENTITIES = ("template", "seed 1")


def _check(**changes: object) -> FrameCheck:
    base: dict[str, object] = {
        "converged": True,
        "iterations": 10,
        "max_displacement_mm": 2.0,
        "explained_mm": 0.0,
        "max_target_distance_mm": 2.0,
        "penetrating_linear": 3,
        "penetrating_physics": 0,
        "opening_linear_mm": 10.0,
        "opening_physics_mm": 10.0,
        "inverted_elements": 0,
        "volume_linear_percent": 1.0,
        "volume_physics_percent": 0.5,
    }
    return FrameCheck(**(base | changes))  # type: ignore[arg-type]


def test_bounds_name_each_failure() -> None:
    assert _check().failures() == []
    assert _check(max_displacement_mm=15.5).failures() == ["exploded"]
    # A contact may undo the linear blend's own penetration depth.
    assert _check(max_displacement_mm=15.5, explained_mm=1.0).failures() == []
    assert _check(penetrating_physics=4).failures() == ["penetration"]
    assert _check(opening_physics_mm=8.9).failures() == ["mouth_open_ratio"]
    assert _check(opening_physics_mm=11.1).failures() == ["mouth_open_ratio"]
    # A lip the linear blend sinks 1.9 mm into the teeth comes out: the opening may change by
    # that depth beyond the ratio (a generated frame: 12.1 mm linear, 13.5 mm physics).
    rolled = {"opening_linear_mm": 12.1, "explained_mm": 1.9}
    assert _check(**rolled, opening_physics_mm=13.5).failures() == []
    assert _check(**rolled, opening_physics_mm=15.3).failures() == ["mouth_open_ratio"]
    assert _check(**rolled, opening_physics_mm=9.0).failures() == []
    assert _check(**rolled, opening_physics_mm=8.9).failures() == ["mouth_open_ratio"]
    # The bench's ratio is the judged one: the explained part off, the rest counted.
    assert _check(**rolled, opening_physics_mm=13.5).judged_open_ratio == 1.0
    assert _check(**rolled, opening_physics_mm=15.3).judged_open_ratio == pytest.approx(
        (12.1 + 1.3) / 12.1
    )
    assert _check(**rolled, opening_physics_mm=9.0).judged_open_ratio == pytest.approx(
        (12.1 - 1.2) / 12.1
    )
    assert _check(opening_physics_mm=10.5).judged_open_ratio == pytest.approx(1.05)
    # A closed linear mouth has no ratio to keep.
    closed = _check(opening_linear_mm=BOUNDS.open_mm, opening_physics_mm=0.1)
    assert math.isnan(closed.open_ratio) and closed.failures() == []
    # Crossed lips (the upper lip's middle below the lower's: negative opening) are an
    # interpenetration for the penetration bound, not an open mouth.
    crossed = _check(opening_linear_mm=-10.0, opening_physics_mm=-4.0)
    assert math.isnan(crossed.open_ratio) and crossed.failures() == []
    assert _check(opening_physics_mm=-1.0).failures() == ["mouth_open_ratio"]
    assert _check(inverted_elements=1).failures() == ["inverted_elements"]
    # within the slack (the tissue's compliance under load), then beyond it
    assert _check(volume_physics_percent=-1.9).failures() == []
    assert _check(volume_physics_percent=-2.1).failures() == ["volume"]
    # A soft tissue asked to grow 7.6 % (target_volume 1.076; a generated shard: physics
    # +4.3 %, linear -1.0 %) is measured from that request, not from the rest volume.
    grown = {"volume_physics_percent": 4.3, "volume_linear_percent": -1.0}
    assert _check(**grown).failures() == ["volume"]
    assert _check(**grown, volume_requested_percent=7.6).failures() == []
    assert _check(**grown, volume_requested_percent=-2.0).failures() == ["volume"]
    # A regional request (a generated frame: face -11 %, head and neck +14 %; together +0.06 %)
    # is judged over its regions: each moved part of the way, shrinking further than growing,
    # so the total missed the mean request by 1.1 points while the regions came closer.
    regional = {
        "volume_physics_percent": -1.02,
        "volume_linear_percent": 0.07,
        "volume_requested_percent": 0.06,
    }
    assert _check(**regional).failures() == ["volume"]
    met = ((-8.1, -5.9, -11.0, 0.5), (6.2, 5.8, 13.6, 0.5))
    assert _check(**regional, volume_regions=met).failures() == []
    # A region pulled past its request by neighbours asked otherwise (a generated frame's:
    # physics +0.3 %, linear +2.3 %, asked +2.1 %) does not fail a frame whose regions as a
    # whole moved toward theirs...
    pulled = ((0.3, 2.3, 2.1, 0.2), (-7.7, 2.5, -9.5, 0.4), (8.7, 0.3, 12.7, 0.4))
    check = _check(**regional, volume_regions=pulled)
    assert check.failures() == []
    physics, linear = check.volume_errors
    assert physics == pytest.approx(
        math.sqrt(0.2 * 1.8**2 + 0.4 * 1.8**2 + 0.4 * 4.0**2)
    )
    assert linear > physics
    # ...but regions that as a whole end farther from what was asked do, and the shares weigh
    # them: one region far short of its request, one that reached its own, as the volume
    # between them lies.
    short, reached = (3.0, 5.8, 13.6), (-10.5, -5.9, -11.0)
    lost = ((*short, 0.8), (*reached, 0.2))
    assert _check(**regional, volume_regions=lost).failures() == ["volume"]
    light = ((*short, 0.2), (*reached, 0.8))
    assert _check(**regional, volume_regions=light).failures() == []
    assert _check(converged=False).failures() == ["not_converged"]
    both = [_check(), _check(penetrating_physics=9, inverted_elements=2)]
    counts = failure_counts(both)
    assert (
        counts["failed_frames"] == 1
        and counts["penetration"] == counts["inverted_elements"] == 1
    )
    fig = bench_figures(both)
    assert (
        fig["stress_penetration_worse_frames"] == 1
        and fig["stress_exploded_frames"] == 0
    )
    assert fig["mouth_open_ratio_min"] == fig["mouth_open_ratio_max"] == 1.0
    # A rolled lip out of the teeth: 1.16 plain, 1.0 as judged; both are reported.
    fig = bench_figures([_check(**rolled, opening_physics_mm=14.0)])
    assert fig["mouth_open_ratio_max"] == 1.0
    assert fig["mouth_open_raw_ratio_max"] == pytest.approx(14.0 / 12.1)


def test_expression_library() -> None:
    singles = single_shapes()
    assert len(singles) == len(ARKIT_BLENDSHAPES) == 52
    assert all(w.sum() == 1.0 for w in singles.values())
    combos = combinations()
    assert len(combos) >= 20
    snarl = combos["snarl"]
    assert snarl[ARKIT_BLENDSHAPES.index("noseSneerLeft")] == pytest.approx(0.8)
    assert snarl[ARKIT_BLENDSHAPES.index("jawOpen")] == pytest.approx(0.4)
    assert COMBINATIONS["snarl"] is SNARL
    for name, w in combos.items():
        assert (w >= 0).all() and (w <= 1).all(), name


def test_extra_material_cases_are_parsed_and_planned() -> None:
    values = parse_material("w_soft_volume=3, max_strain=1.3")
    assert values == {"w_soft_volume": 3.0, "max_strain": 1.3}
    plan = StressPlan(identities=("seed 1", "template"), extra_materials=(values,))
    case = next(
        c
        for c in build_cases(plan)
        if c.group == "materials w_soft_volume=3,max_strain=1.3"
    )
    assert case.identity == "seed 1" and case.parameters == values
    assert len(case.frames) == len(combinations())
    for bad in ("w_soft_volume", "nope=1", "w_soft_volume=x", "max_strain=5", ""):
        with pytest.raises(ValueError):
            parse_material(bad)


def test_plan_covers_the_suite() -> None:
    cases = build_cases(StressPlan())
    groups = {c.group for c in cases}
    assert {
        "expressions",
        "level 4",
        "materials soft",
        "materials stiff",
        "dynamic",
    } <= groups
    assert sum(g.startswith("gravity 2 g") for g in groups) >= 3
    assert {c.identity for c in cases} >= {
        "template",
        "seed 1",
        "seed 2",
        "h+2.5σ",
        "h-2.5σ",
    }
    dynamic = next(c for c in cases if c.dynamic)
    assert dynamic.judge_every > 1 and len(dynamic.frames) % dynamic.judge_every == 0


@pytest.fixture(scope="module")
def reduced(template: Template) -> list:
    """The reduced suite: every combination and every mouth/jaw shape alone, level 3, two
    identities, static, default parameters, collisions on."""
    mouth = {
        k: v
        for k, v in single_shapes().items()
        if k.startswith(("mouth", "jaw", "tongue", "cheekPuff"))
    }
    frames = list((combinations() | mouth).items())
    cases = [StressCase("reduced", who, LEVEL, frames) for who in IDENTITIES]
    return run_stress(template, cases, keep_worst=0, progress=False).frames


def _failures(frames: list, reason: str) -> list[str]:
    return [
        f"{f.identity} {f.label}: {f.check.as_dict()}"
        for f in frames
        if reason in f.check.failures()
    ]


@pytest.mark.parametrize(
    "reason",
    [
        "exploded",
        # Rolled lips (mouthRollLower and mouthRollUpper at 1, seed 1): the linear blend has
        # 355 lip points up to 2.8 mm inside the other lip or the teeth; the contacts resolve
        # them all (docs/physics.md, Collisions).
        "penetration",
        # mouthClose at 1 alone (the lips pressed 40 mm through each other over a closed jaw)
        # inverts 28 lip tets of the template without the solver's stiffening rounds, none
        # with them on the head's (reproducible) tet mesh (docs/physics.md, Known limits).
        "inverted_elements",
        "volume",
    ],
)
def test_reduced_suite_holds_the_bounds(reduced: list, reason: str) -> None:
    bad = _failures(reduced, reason)
    assert not bad, (
        f"{len(bad)} of {len(reduced)} frames fail '{reason}':\n" + "\n".join(bad[:10])
    )


def test_open_mouths_stay_open_unless_the_lips_are_pressed(reduced: list) -> None:
    """The opening bound is the only one with an exception the contact model explains: where
    the linear blend presses one lip into the other (mouthShrugLower 1 on the template: 267
    penetrating lip points, deepest 3.5 mm), resolving the contact moves the lip middles; a
    tie moves both sides, so by at most twice the deepest penetration."""
    for f in reduced:
        c = f.check
        if "mouth_open_ratio" in c.failures():
            change = abs(c.opening_physics_mm - c.opening_linear_mm)
            assert c.penetrating_linear > 0 and change <= 2 * c.explained_mm + 1.0, (
                c.as_dict()
            )


def test_snarl_frame_does_not_explode(template: Template) -> None:
    """A real take's strong snarl (identity seed 1, level 3, static, collisions on) once
    moved lip points 349 mm and made lip penetration worse than linear blendshapes."""
    case = StressCase("snarl", "seed 1", LEVEL, [("snarl", combinations()["snarl"])])
    (frame,) = run_stress(template, [case], keep_worst=0, progress=False).frames
    c = frame.check
    assert c.max_displacement_mm <= BOUNDS.exploded_mm + c.explained_mm, c.as_dict()
    assert c.penetrating_physics <= c.penetrating_linear, c.as_dict()
    # 27 mm open in the linear blend; the data's own sanity bound (+-10 %): tight by its
    # definition around a kept opening (1.00 here, on every kernel family)
    lo, hi = BOUNDS.open_ratio
    above(c.open_ratio, lo, "the data's sanity bound", what="open ratio", tight=True)
    below(c.open_ratio, hi, "the data's sanity bound", what="open ratio", tight=True)
    assert np.isfinite(c.max_target_distance_mm)


@pytest.mark.parametrize(
    ("shape", "most"), [("eyeBlinkLeft", 0), ("mouthSmileLeft", 0), ("jawOpen", 10)]
)
def test_jaw_and_skin_motion_do_not_invert_the_muscle_layer(
    template: Template, shape: str, most: int
) -> None:
    """With the jaw's skull vertices behind the oral cavity pinned to the jaw, jawOpen 1 left
    278 inverted tets on the template at level 3; with a 2 mm muscle layer behind the sockets,
    eyeBlinkLeft 1 left 5 and mouthSmileLeft 1 36 (docs/physics.md, Inverted elements)."""
    case = StressCase(
        "single", "template", LEVEL, [(shape, single_shapes()[f"{shape}=1"])]
    )
    (frame,) = run_stress(template, [case], keep_worst=0, progress=False).frames
    assert frame.check.inverted_elements <= most, frame.check.as_dict()


def test_the_suite_on_several_processes_gives_what_one_process_gives(
    template: Template,
) -> None:
    frames = list(combinations().items())[:2]
    cases = [StressCase("tiny", who, LEVEL, frames) for who in IDENTITIES]
    one = run_stress(template, cases, keep_worst=3, progress=False)
    two = run_stress_parallel(None, cases, keep_worst=3, workers=2, progress=False)
    # as JSON: a closed mouth's ratio is NaN, which equals nothing
    assert [json.dumps(f.as_dict()) for f in two.frames] == [
        json.dumps(f.as_dict()) for f in one.frames
    ]
    assert [w.title for w in two.worst] == [w.title for w in one.worst]
    assert [w.score for w in two.worst] == sorted(
        (w.score for w in two.worst), reverse=True
    )
