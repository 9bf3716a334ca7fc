"""Shared fixtures: the template (from the ICT cache) and fitted layered head models."""

from __future__ import annotations

import pytest
from softdeca_train.template import Template


@pytest.fixture(scope="session")
def template() -> Template:
    return Template.load()
