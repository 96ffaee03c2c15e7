"""Shared helpers of the package's tests: where the repository, its scenes and the CLI are."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
SCENES = REPO / "scenes"


def cli() -> pathlib.Path:
    """The `linkage` binary of this checkout (LINKAGE_BIN, else target/release/linkage)."""
    path = pathlib.Path(os.environ.get("LINKAGE_BIN", REPO / "target" / "release" / "linkage"))
    if not path.is_file():
        pytest.fail(f"{path}: no linkage binary: build it with `cargo build --release` or set LINKAGE_BIN")
    return path


def run_cli(*args: str) -> None:
    """Run the CLI; fail with its output when it fails."""
    done = subprocess.run([str(cli()), *args], capture_output=True, text=True)
    assert done.returncode == 0, f"linkage {' '.join(args)} failed:\n{done.stdout}\n{done.stderr}"


ARRAYS = ("displacements", "positions", "axial_forces", "strains", "stresses", "reactions", "loads", "contacts")


def assert_same_bits(a, b) -> None:
    """Two Results hold the same steps, every array bit for bit."""
    assert len(a.steps) == len(b.steps)
    for sa, sb in zip(a.steps, b.steps):
        assert sa.number == sb.number
        assert sa.load_factor == sb.load_factor
        assert sa.names == sb.names
        for ba, bb in zip(sa.bodies, sb.bodies):
            for name in ARRAYS:
                x, y = getattr(ba, name), getattr(bb, name)
                assert x.shape == y.shape, name
                assert x.tobytes() == y.tobytes(), f"{ba.name} step {sa.number}: {name} differ"
            assert np.array_equal(ba.overloaded, bb.overloaded)
            assert ba.contact_list == bb.contact_list
    assert a == b
