"""A scene built from numpy arrays is the scene its TOML file is, bit for bit."""

import math

import numpy as np
import pytest

import linkage
from conftest import assert_same_bits

# A right triangle: node 1 pinned, node 3 on a roller (held in x), 1 kN down at node 2.
NODES = np.array([[0, 0], [1, 0], [0, 1]])
MEMBERS = np.array([[1, 2], [2, 3], [1, 3]])
TOML = """name = "truss"
steps = 2

[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4

[[bodies]]
name = "truss"
nodes = "truss.nodes"
links = "truss.links"
material = "steel"

[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]

[[bodies.supports]]
nodes = [3]
fix = ["x"]

[[bodies.loads]]
nodes = [2]
force = [0.0, -1000.0]
"""


def truss_from_arrays(**material_keys) -> linkage.Scene:
    steel = linkage.Material("steel", youngs_modulus=200e9, area=1e-4, **material_keys)
    body = linkage.Body("truss", nodes=NODES, members=MEMBERS, material=steel)
    body.support(nodes=[1], fix=["x", "y"])
    body.support(nodes=[3], fix=["x"])
    body.load(nodes=[2], force=[0.0, -1e3])
    return linkage.Scene("truss", bodies=[body], steps=2)


def test_a_truss_from_numpy_arrays_gives_the_bits_of_the_same_scene_from_toml(tmp_path):
    (tmp_path / "truss.toml").write_text(TOML)
    (tmp_path / "truss.nodes").write_text("0 0\n1 0\n0 1\n")
    (tmp_path / "truss.links").write_text("1 2\n2 3\n1 3\n")
    from_file = linkage.Scene.load(tmp_path / "truss.toml").run()
    from_arrays = truss_from_arrays().run()
    assert_same_bits(from_arrays, from_file)
    # The hand calculation (joint equilibrium at nodes 2 and 3), to 1e-12 relative:
    # N12 = -1000 N, N23 = 1000·√2 N, N13 = -1000 N; A = 1e-4 m² gives the stresses.
    last = from_arrays.steps[-1].body("truss")
    expected = np.array([-1000.0, 1000.0 * math.sqrt(2.0), -1000.0])
    np.testing.assert_allclose(last.axial_forces, expected, rtol=1e-12)
    np.testing.assert_allclose(last.stresses, expected / 1e-4, rtol=1e-12)
    # Node 2 moves by the shortening of member 1-2 in x: u = N L / (E A) = -5e-5 m.
    assert last.displacements.shape == (3, 2)
    assert last.displacements[1, 0] == pytest.approx(-1000.0 / (200e9 * 1e-4), rel=1e-12)
    # Reactions balance the load: row i is node i + 1, zero where there is no support.
    np.testing.assert_allclose(last.reactions.sum(axis=0), [0.0, 1000.0], rtol=1e-12, atol=1e-9)
    assert not last.reactions[1].any()
    assert list(last.supported_nodes) == [1, 3]
    # Half the load at step 1 of 2.
    assert from_arrays.steps[1].load_factor == 0.5


def test_to_toml_writes_the_scene_and_paper_files_the_cli_runs(tmp_path):
    scene = truss_from_arrays()
    scene.to_toml(tmp_path / "truss.toml")
    assert (tmp_path / "truss.nodes").read_text() == "0.0 0.0\n1.0 0.0\n0.0 1.0\n"
    assert (tmp_path / "truss.links").read_text() == "1 2\n2 3\n1 3\n"
    again = linkage.Scene.load(tmp_path / "truss.toml")
    assert_same_bits(again.run(), scene.run())


def test_member_materials_are_the_links_files_third_column():
    steel = linkage.Material("steel", youngs_modulus=200e9, area=1e-4)
    alu = linkage.Material("alu", youngs_modulus=70e9, area=1e-4)
    body = linkage.Body("truss", nodes=NODES, members=MEMBERS, material=steel, member_materials=[steel, alu, steel])
    body.support(nodes=[1], fix=["x", "y"])
    body.support(nodes=[3], fix=["x"])
    body.load(nodes=[2], force=[0.0, -1e3])
    res = linkage.Scene("truss", bodies=[body]).run()
    b = res.steps[-1].body("truss")
    # A statically determinate truss: the same forces, strains in the ratio of the moduli.
    np.testing.assert_allclose(b.axial_forces, [-1000.0, 1000.0 * math.sqrt(2.0), -1000.0], rtol=1e-12)
    np.testing.assert_allclose(b.strains[1], 1000.0 * math.sqrt(2.0) / (70e9 * 1e-4), rtol=1e-12)


def test_to_dict_and_from_dict_round_trip_through_the_scene_types(tmp_path):
    (tmp_path / "truss.toml").write_text(TOML)
    (tmp_path / "truss.nodes").write_text("0 0\n1 0\n0 1\n")
    (tmp_path / "truss.links").write_text("1 2\n2 3\n1 3\n")
    scene = linkage.Scene.load(tmp_path / "truss.toml")
    d = scene.to_dict()
    assert d["materials"][0] == {"name": "steel", "youngs_modulus": 200e9, "area": 1e-4}
    assert d["bodies"][0]["supports"][1] == {"nodes": [3], "fix": ["x"]}
    again = linkage.Scene.from_dict(d, path=tmp_path / "truss.toml")
    assert_same_bits(again.run(), scene.run())
    # Every scene key is reachable: one the file did not have, set through the dict.
    d["bodies"][0]["kinematics"] = "large"
    large = linkage.Scene.from_dict(d, path=tmp_path / "truss.toml").run()
    assert large.summary["steps"][-1]["iterations"] > 1


def test_bad_arrays_are_value_errors_naming_the_body():
    with pytest.raises(ValueError, match=r"body 'truss': nodes: give an array of shape \(n, 2\) or \(n, 3\)"):
        linkage.Body("truss", nodes=np.zeros((3, 4)), members=MEMBERS)
    with pytest.raises(ValueError, match="member 2 names node 0: node numbers are 1-based"):
        linkage.Body("truss", nodes=NODES, members=np.array([[1, 2], [0, 3]]))
    steel = linkage.Material("steel", youngs_modulus=200e9, area=1e-4)
    body = linkage.Body("truss", nodes=NODES, members=np.array([[1, 2], [2, 4]]), material=steel)
    with pytest.raises(linkage.SceneError, match=r"truss\.links:2: .*4"):
        linkage.Scene("truss", bodies=[body])
