"""`Scene.load(values=)` is the variant of a `[sweep]` with those values."""

import linkage
from conftest import SCENES, assert_same_bits, run_cli


def test_values_equal_the_sweep_variant(tmp_path):
    text = (SCENES / "two_disks.toml").read_text()
    (tmp_path / "two_disks.toml").write_text(text + '\n[sweep]\n"materials.rubber.youngs_modulus" = [1e7, 2e7]\n')
    run_cli("run", str(tmp_path / "two_disks.toml"), "--out", str(tmp_path / "out"))
    variant = linkage.Results.load(tmp_path / "out" / "two_disks" / "2")
    scene = linkage.Scene.load(SCENES / "two_disks.toml", values={"materials.rubber.youngs_modulus": 2e7})
    res = scene.run()
    assert_same_bits(res, variant)
    assert res.summary["scene_digest"] == variant.summary["scene_digest"]
    # And the value did change the run: the stiffer disks move less.
    base = linkage.Scene.load(SCENES / "two_disks.toml").run()
    u = lambda r: abs(r.steps[-1].body("left").displacements).max()
    assert u(res) < u(base)


def test_a_value_for_a_key_the_scene_lacks_is_a_scene_error():
    try:
        linkage.Scene.load(SCENES / "two_disks.toml", values={"materials.steel.area": 1.0})
    except linkage.SceneError as e:
        assert "two_disks.toml: values: `materials.steel.area`" in str(e)
        assert "no entry named 'steel'" in str(e)
    else:
        raise AssertionError("no SceneError")


def test_a_scene_with_a_sweep_is_refused_by_run_with_what_to_do(tmp_path):
    text = (SCENES / "two_disks.toml").read_text()
    (tmp_path / "two_disks.toml").write_text(text + '\n[sweep]\n"materials.rubber.youngs_modulus" = [1e7, 2e7]\n')
    try:
        linkage.run(tmp_path / "two_disks.toml", out=tmp_path / "out")
    except linkage.SceneError as e:
        assert "[sweep] of 2 variants" in str(e) and "values=" in str(e)
    else:
        raise AssertionError("no SceneError")
