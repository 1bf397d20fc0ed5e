"""Shared fixtures: the repository's paths and the command line scripts/python built."""

import os
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture
def repo() -> pathlib.Path:
    return REPO


def target() -> pathlib.Path:
    return pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))


@pytest.fixture
def clib() -> pathlib.Path:
    """The C library of the same build (`cargo build --release`)."""
    path = target() / "release" / "libhairtrace.so"
    assert path.is_file(), f"{path}: build the C library first (cargo build --release)"
    return path


@pytest.fixture
def cli() -> pathlib.Path:
    """The `hairtrace` command line of the same build (scripts/python says where)."""
    path = pathlib.Path(os.environ.get("HAIRTRACE_CLI", target() / "release" / "hairtrace"))
    assert path.is_file(), f"{path}: build the command line first (cargo build --release)"
    return path
