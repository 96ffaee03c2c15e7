"""`Material(..., continuum_modulus=...)`: a box lattice compressed uniaxially has the
modulus asked for (within 2 %), as the scene file's key gives it."""

import numpy as np
import pytest

import linkage

SIDE = 0.1
SHORTENING = 1e-5


def compressed_cube(material):
    body = linkage.Body("cube", box_lattice={"size": [SIDE] * 3, "cells": [4, 4, 4]}, material=material)
    body.support(on_plane={"point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}, fix=["z"])
    body.support(on_plane={"point": [0.0, 0.0, SIDE], "normal": [0.0, 0.0, 1.0]}, fix=["z"],
                 displacement=[0.0, 0.0, -SHORTENING])
    body.support(nearest=[SIDE / 2, SIDE / 2, 0.0], fix=["x", "y"])
    body.support(nearest=[SIDE, SIDE / 2, 0.0], fix=["y"])
    return linkage.Scene("cube", bodies=[body], steps=1)


def test_a_box_lattice_with_continuum_modulus_has_it():
    alu = linkage.Material("alu", youngs_modulus=70e9, continuum_modulus=70e9)
    res = compressed_cube(alu).run()
    first, last = res.steps[0].body("cube"), res.steps[-1].body("cube")
    top = np.abs(first.positions[:, 2] - SIDE) < 1e-9
    force = -last.reactions[top, 2].sum()
    modulus = force / SIDE**2 / (SHORTENING / SIDE)
    print(f"box lattice 4x4x4 with continuum_modulus = 70e9: {modulus:.4e} Pa")
    assert abs(modulus / 70e9 - 1.0) < 0.02


def test_area_with_continuum_modulus_is_a_scene_error():
    alu = linkage.Material("alu", youngs_modulus=70e9, area=1e-4, continuum_modulus=70e9)
    with pytest.raises(linkage.SceneError, match="not both"):
        compressed_cube(alu).run()
