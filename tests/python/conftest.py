"""Shared fixtures: the template (from the ICT cache) and fitted layered head models."""

from __future__ import annotations

import pytest
from softdeca_train.data.config import GenerateConfig, RunSettings
from softdeca_train.data.generate import generate
from softdeca_train.template import Template

# The small dataset of the data generation and training tests: LHM level 2 (162 vertices per
# wrap), 16 static + 16 sparse frames and 2 dynamic sequences of 4 frames (2 lead-in).
SMALL = GenerateConfig(
    static=16,
    dynamic=2,
    sparse=16,
    level=2,
    frames_per_params=4,
    params_per_identity=2,
    sequences_per_identity=1,
    sequence_length=4,
    lead_in=2,
    test_share=0.3,
    seed=7,
)


@pytest.fixture(scope="session")
def template() -> Template:
    return Template.load()


@pytest.fixture(scope="session")
def small(tmp_path_factory) -> tuple:
    """The small dataset, generated once per test session on 2 worker processes."""
    out = tmp_path_factory.mktemp("small")
    summary = generate(SMALL, RunSettings(out=out, workers=2, progress=False))
    return out, summary
