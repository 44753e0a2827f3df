import json

import pytest

from motionlib import read, synth, write_bvh
from motionlib.cli import main
from motionlib.segmenters import get_segmenter


@pytest.fixture(scope="module")
def bvh_path(tmp_path_factory):
    take, segments = synth.generate(seed=2, fps=60.0)
    path = tmp_path_factory.mktemp("takes") / "synth.bvh"
    write_bvh(take, path)
    return path, segments


def test_it_prints_cuts_as_json_with_exactly_the_documented_keys(bvh_path, capsys):
    path, segments = bvh_path
    assert main(["segment", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) == {"fps", "n_frames", "method", "cuts"}
    assert (out["fps"], out["n_frames"], out["method"]) == (60.0, segments[-1][1], "default")
    assert out["cuts"] and all(set(c) == {"frame", "confidence"} for c in out["cuts"])
    expected = get_segmenter("default")().fit_predict(read(path))
    assert [c["frame"] for c in out["cuts"]] == expected.cuts.tolist()
    assert [c["confidence"] for c in out["cuts"]] == pytest.approx(expected.confidence, abs=5e-5)


def test_it_prints_a_table_for_people(bvh_path, capsys):
    path, _ = bvh_path
    assert main(["segment", str(path), "--method", "bone_angle", "--param", "param=0.3"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "cuts by bone_angle" in lines[0]
    assert lines[1].split() == ["frame", "time", "s", "confidence"]


def test_it_draws_the_signal_with_the_cuts(bvh_path, tmp_path, capsys):
    path, _ = bvh_path
    out = tmp_path / "cuts.png"
    assert main(["segment", str(path), "--plot", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--param", "threshold=9"], "threshold: must be between 0 and 2, got '9'"),
        (["--param", "threshold"], "--param: expected NAME=VALUE, got 'threshold'"),
        (["--param", "bogus=1"], "bogus: unknown parameter for method 'default'"),
        (["--method", "nope"], "method: unknown segmenter 'nope'"),
    ],
)
def test_it_rejects_bad_arguments_in_one_line_with_exit_2(bvh_path, capsys, args, message):
    path, _ = bvh_path
    assert main(["segment", str(path), *args]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert message in err
