"""Results read back from a results folder equal the results of the same run in memory."""

import shutil

import linkage
from conftest import SCENES, assert_same_bits, run_cli


def test_results_load_of_a_cli_run_equals_the_in_memory_results(tmp_path):
    run_cli("run", str(SCENES / "paper_square.toml"), "--out", str(tmp_path))
    stored = linkage.Results.load(tmp_path / "paper_square")
    in_memory = linkage.Scene.load(SCENES / "paper_square.toml").run()
    assert_same_bits(stored, in_memory)
    assert stored.folder is not None and in_memory.folder is None
    assert stored.summary["scene"] == "paper_square"
    assert in_memory.summary["scene_digest"] == stored.summary["scene_digest"]


def test_results_load_reads_npz_folders_too(tmp_path):
    text = (SCENES / "paper_square.toml").read_text() + '\n[output]\nformat = "npz"\n'
    for name in ("square.nodes", "square.links"):
        shutil.copy(SCENES / name, tmp_path / name)
    (tmp_path / "square_npz.toml").write_text(text)
    run_cli("run", str(tmp_path / "square_npz.toml"), "--out", str(tmp_path / "out"))
    assert (tmp_path / "out" / "paper_square" / "model.npz").is_file()
    stored = linkage.Results.load(tmp_path / "out" / "paper_square")
    assert_same_bits(stored, linkage.Scene.load(tmp_path / "square_npz.toml").run())


def test_linkage_run_writes_the_folder_the_cli_writes(tmp_path):
    res = linkage.run(SCENES / "paper_square.toml", out=tmp_path)
    assert (tmp_path / "paper_square" / "summary.json").is_file()
    assert (tmp_path / "paper_square" / "steps" / "0001.json").is_file()
    assert_same_bits(res, linkage.Results.load(tmp_path / "paper_square"))
    # Step 1 of the paper's square: u = F L / (E A) along the loaded member.
    b = res.steps[-1].body("square")
    assert b.displacements.shape[1] == 2
    assert res.steps[-1].time is None


def test_a_missing_folder_is_a_results_error(tmp_path):
    try:
        linkage.Results.load(tmp_path / "nothing")
    except linkage.ResultsError as e:
        assert "nothing" in str(e) and "linkage run" in str(e)
    else:
        raise AssertionError("no ResultsError")


def test_progress_is_reported_up_to_every_step():
    seen = []
    linkage.Scene.load(SCENES / "two_disks.toml").run(progress=lambda done, total: seen.append((done, total)))
    assert seen[-1] == (5, 5)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)


def test_a_step_is_found_by_its_number_and_a_body_by_its_name():
    res = linkage.Scene.load(SCENES / "two_disks.toml").run()
    assert res.step(4).number == 4
    assert res.steps[-1].names == ["left", "right"]
    try:
        res.steps[-1].body("middle")
    except ValueError as e:
        assert "'left', 'right'" in str(e)
    else:
        raise AssertionError("no ValueError")
    # Contact: the disks press on each other, the contact forces are equal and opposite.
    left, right = res.steps[-1].body("left"), res.steps[-1].body("right")
    total = left.contacts.sum(axis=0) + right.contacts.sum(axis=0)
    assert abs(left.contacts.sum(axis=0)[0]) > 100.0
    assert abs(total[0]) < 1e-6 * abs(left.contacts.sum(axis=0)[0])
    assert left.contact_list[0]["with"] == "right"
