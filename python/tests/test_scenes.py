"""Every bundled scene loads and runs through Python (none skipped), with the numbers the
CLI's checks rely on: finite, and every stored step holding every body."""

import time

import numpy as np
import pytest

import linkage
from conftest import SCENES

BUNDLED = sorted(SCENES.glob("*.toml"))


def test_there_are_bundled_scenes():
    assert len(BUNDLED) >= 20


@pytest.mark.parametrize("path", BUNDLED, ids=[p.stem for p in BUNDLED])
def test_a_bundled_scene_loads_and_runs(path):
    started = time.perf_counter()
    scene = linkage.Scene.load(path)
    res = scene.run()
    seconds = time.perf_counter() - started
    print(f"{path.name}: {scene.describe()}; {seconds:.2f} s")
    assert res.steps[0].number == 0
    assert res.steps[-1].number <= scene.steps
    for step in res.steps:
        assert step.names == scene.bodies
        for b in step.bodies:
            assert np.isfinite(b.displacements).all()
            assert np.isfinite(b.axial_forces).all()
            assert b.positions.shape == b.displacements.shape
    assert res.summary["scene"] == scene.name
