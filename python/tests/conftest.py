"""Shared fixtures: the repository's paths and the command line scripts/python built."""

import os
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture
def repo() -> pathlib.Path:
    return REPO


@pytest.fixture
def cli() -> pathlib.Path:
    """The `hairtrace` command line of the same build (scripts/python says where)."""
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    path = pathlib.Path(os.environ.get("HAIRTRACE_CLI", target / "release" / "hairtrace"))
    assert path.is_file(), f"{path}: build the command line first (cargo build --release)"
    return path
