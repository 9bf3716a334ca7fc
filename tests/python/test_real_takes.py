"""The report's real takes: takes named by source, which ones a bundle trained on, and the
unseen takes at a reduced amplitude (controls/real_takes.py)."""

from __future__ import annotations

import numpy as np
import pytest
from softdeca_train.controls.real_takes import (
    FrameDistances,
    RecordedTake,
    readme_lines,
    recorded_takes,
    reduced,
    summarise,
    trained_on,
    trained_take_names,
    validate_real_takes,
    worse_when_calm,
)
from softdeca_train.streaming.frame import Frame
from softdeca_train.streaming.livelinkface import format_csv


def test_unseen_takes_at_a_reduced_amplitude_are_pooled_apart() -> None:
    """A reduced copy is the take's motion made calmly: reported per take with its amplitude,
    pooled in `unseen_reduced`, and never in the recorded takes' `unseen` figure."""
    seen = RecordedTake("source-a/seen", "0" * 64, np.full((3, 52), 0.5, np.float32))
    unseen = RecordedTake(
        "source-b/unseen", "1" * 64, np.full((3, 52), 0.5, np.float32)
    )
    calm = reduced(unseen, 0.3)
    assert (calm.name, calm.amplitude) == (unseen.name, 0.3)
    assert np.allclose(calm.weights, 0.15)
    with pytest.raises(ValueError, match="amplitude"):
        reduced(unseen, 1.0)
    d = FrameDistances(
        take=np.repeat([0, 1, 2], 3),
        softdeca_mm=np.array([0.1, 0.1, 0.1, 0.2, 0.2, 0.2, 0.05, 0.03, 0.04]),
        linear_mm=np.array([0.2, 0.2, 0.2, 0.4, 0.4, 0.4, 0.04, 0.04, 0.06]),
    )
    real = summarise(
        [seen, unseen, calm], [True, False, False], d, every=10, identities=1
    )
    validate_real_takes(real)
    assert real["unseen"]["frames"] == 3 and real["unseen"]["ratio"] == pytest.approx(
        0.5
    )
    assert real["unseen_reduced"]["frames"] == 3 and real["reduced_amplitude"] == 0.3
    assert real["unseen_reduced"]["ratio"] == pytest.approx(0.12 / 0.14)
    row = real["takes"][2]
    assert row["amplitude"] == 0.3 and row["calm"]["ratio"] == pytest.approx(
        0.08 / 0.08
    )
    row["calm"]["ratio"] = 1.2
    assert worse_when_calm(real) == ["source-b/unseen x0.3"]
    assert any("unseen takes x0.3, pooled" in line for line in readme_lines(real))
    with pytest.raises(ValueError, match="one reduced amplitude"):
        summarise(
            [seen, unseen, calm, reduced(unseen, 0.5)],
            [True, False, False, False],
            FrameDistances(np.repeat([0, 1, 2, 3], 1), *np.ones((2, 4))),
            every=10,
            identities=1,
        )


def test_the_takes_a_bundle_trained_on_come_from_its_training_record() -> None:
    manifest = {
        "training": {
            "dataset": {
                "splits": {"train": {"takes": ["apfel"]}, "test": {"takes": ["x"]}}
            },
            "more_static": [{"splits": {"train": {"takes": ["S07-001"]}}}],
            "contrasts": None,
        }
    }
    trained = trained_take_names(manifest)
    assert trained == {"apfel", "S07-001"}
    assert trained_take_names({"untrained": True}) == set()
    take = RecordedTake("another-source/apfel", "", np.zeros((1, 52)))
    assert trained_on(
        take, trained
    )  # a stem collision never flatters: it counts as seen
    assert not trained_on(RecordedTake("a/x", "", np.zeros((1, 52))), trained)


def test_recorded_takes_are_named_by_source_and_take(tmp_path) -> None:
    frames = [Frame(capture_time=i / 60.0) for i in range(5)]
    for f in frames:
        f.weights[:] = 0.1 * f.capture_time
    for source in ("one", "two"):
        (tmp_path / source).mkdir()
        (tmp_path / source / "a.csv").write_text(format_csv(frames))
    takes = recorded_takes(tmp_path, every=2)
    assert [t.name for t in takes] == ["one/a", "two/a"]
    assert takes[0].weights.shape == (3, 52)  # frames 0, 2, 4
    assert takes[0].sha256 == takes[1].sha256
    with pytest.raises(FileNotFoundError):
        recorded_takes(tmp_path / "one" / "none", every=1)
