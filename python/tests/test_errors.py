"""A bad scene raises SceneError (a ValueError) with the CLI's message: file and line."""

import linkage
from conftest import SCENES


def test_a_bad_value_names_the_file_and_line(tmp_path):
    text = (SCENES / "two_disks.toml").read_text().replace("youngs_modulus = 1e7", "youngs_modulus = -1e7")
    line = next(k for k, l in enumerate(text.splitlines(), 1) if "youngs_modulus = -1e7" in l)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    try:
        linkage.Scene.load(path)
    except linkage.SceneError as e:
        assert isinstance(e, ValueError)
        assert str(e).startswith(f"{path}:"), str(e)
        assert "material 'rubber'" in str(e), str(e)
        # The material's table starts a few lines above the key; the message names a line in it.
        at = int(str(e).split(":")[1])
        assert line - 3 <= at <= line, (at, line, str(e))
    else:
        raise AssertionError("no SceneError")


def test_an_unknown_key_names_the_line_and_column(tmp_path):
    path = tmp_path / "typo.toml"
    path.write_text('name = "t"\nsteps = 1\nstepz = 2\n')
    try:
        linkage.Scene.load(path)
    except linkage.SceneError as e:
        assert str(e).startswith(f"{path}: "), str(e)
        assert "line 3" in str(e) and "stepz" in str(e), str(e)
    else:
        raise AssertionError("no SceneError")


def test_a_missing_file_is_a_scene_error(tmp_path):
    try:
        linkage.Scene.load(tmp_path / "absent.toml")
    except linkage.SceneError as e:
        assert "cannot read the scene file" in str(e)
    else:
        raise AssertionError("no SceneError")
