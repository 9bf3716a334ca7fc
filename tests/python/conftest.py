"""Shared fixtures: the template (from the ICT cache), the committed bundle in the native library
and fitted layered head models."""

from __future__ import annotations

import json
import os
from pathlib import Path

import bounds
import pytest
from softdeca_train.data.config import GenerateConfig, RunSettings
from softdeca_train.data.generate import generate
from softdeca_train.host.fit_check import DEFAULT_BUNDLE
from softdeca_train.host.native import NativeModel
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
def shipped_model() -> NativeModel:
    """The committed bundle (models/softdeca-default) in the native library."""
    return NativeModel(DEFAULT_BUNDLE)


@pytest.fixture(scope="session")
def small(tmp_path_factory) -> tuple:
    """The small dataset, generated once per test session on 2 worker processes."""
    out = tmp_path_factory.mktemp("small")
    summary = generate(SMALL, RunSettings(out=out, workers=2, progress=False))
    return out, summary


def pytest_terminal_summary(terminalreporter) -> None:
    """The numerical bounds that came closest to their values (bounds.py), and the whole list
    in $SOFTDECA_BOUNDS_REPORT when it is set."""
    if not bounds.RECORDED:
        return
    terminalreporter.section("numerical bounds")
    for line in bounds.summary_lines():
        terminalreporter.write_line(line)
    out = os.environ.get("SOFTDECA_BOUNDS_REPORT")
    if out:
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        Path(out).write_text(json.dumps(bounds.report(), indent=1, default=str))
        terminalreporter.write_line(f"every bound with its margin: {out}")
