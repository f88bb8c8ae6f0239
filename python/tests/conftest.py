import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture
def root() -> pathlib.Path:
    return ROOT


@pytest.fixture
def decks() -> pathlib.Path:
    return ROOT / "decks"


@pytest.fixture
def cli():
    """The mecano-rs binary cargo test built (tests/python.rs passes its path)."""
    path = os.environ.get("MECANO_BIN")
    if not path or not os.path.exists(path):
        pytest.skip("MECANO_BIN not set: run through `cargo test --test python`")
    return path
