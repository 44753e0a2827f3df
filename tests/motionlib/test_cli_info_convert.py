"""python -m motionlib info / convert."""

import subprocess
import sys

import numpy as np
import pytest

import motionlib
from motionlib.cli import main


def run(capsys, *args):
    status = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return status, out, err


def test_it_runs_as_a_module(bvh_13_29):
    result = subprocess.run([sys.executable, "-m", "motionlib", "info", str(bvh_13_29)],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert "frames:          4593" in result.stdout


def test_it_describes_a_bvh(capsys, bvh_13_29):
    status, out, _ = run(capsys, "info", bvh_13_29)
    assert status == 0
    lines = {k: v.strip() for k, v in (line.split(":", 1) for line in out.splitlines())}
    assert lines["format"] == "bvh" and lines["fps"] == "120"
    assert lines["frames"] == "4593" and lines["joints"] == "31"
    assert lines["duration"] == "38.275 s" and lines["rest pose frame"] == "0"
    assert lines["body parts"] == "19 of 19 mapped"


def test_it_says_when_joint_names_cannot_be_mapped(capsys, tmp_path):
    path = tmp_path / "robot.bvh"
    path.write_text("HIERARCHY\nROOT base\n{\n OFFSET 0 0 0\n CHANNELS 1 Xposition\n"
                    " End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 1\n"
                    "Frame Time: 0.1\n0\n")
    status, out, _ = run(capsys, "info", path)
    assert status == 0
    assert "body parts:      not mapped (no joint found for root, spine, chest" in out


def test_it_describes_an_amc_with_its_asf(capsys, amc_13_29):
    status, out, _ = run(capsys, "info", amc_13_29[0], "--asf", amc_13_29[1])
    assert status == 0
    assert "format:          amc" in out and "frames:          4592" in out
    assert "rest pose frame: none" in out


def test_it_converts_an_amc_to_bvh_with_the_same_positions(capsys, amc_13_29, tmp_path):
    out_path = tmp_path / "13_29.bvh"
    status, out, _ = run(capsys, "convert", amc_13_29[0], "--asf", amc_13_29[1], out_path,
                         "--stop", "600")
    assert status == 0 and "frames 0 to 599" in out
    amc = motionlib.read(amc_13_29[0], asf=amc_13_29[1]).slice(0, 600)
    bvh = motionlib.read(out_path)
    difference = motionlib.forward_kinematics(bvh) - motionlib.forward_kinematics(amc)
    assert np.abs(difference).max() < 1e-4


def test_it_reports_a_bad_file_in_one_line_with_status_2(capsys, tmp_path):
    bad = tmp_path / "bad.bvh"
    bad.write_text("HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 1 Xposition\n}\n"
                   "MOTION\nFrames: 2\nFrame Time: 0.1\n1\n")
    status, _, err = run(capsys, "info", bad)
    assert status == 2
    assert err == ("motionlib info: error: bad.bvh:10: truncated MOTION section: "
                   "'Frames: 2' but the file ends after 1 frame lines\n")


def test_it_reports_a_missing_asf_in_one_line(capsys, amc_13_29, tmp_path):
    status, _, err = run(capsys, "convert", amc_13_29[0], tmp_path / "out.bvh")
    assert status == 2 and err.count("\n") == 1
    assert "needs its .asf skeleton" in err


def test_it_reports_a_frame_range_outside_the_take(capsys, bvh_13_29, tmp_path):
    status, _, err = run(capsys, "convert", bvh_13_29, tmp_path / "x.bvh", "--start", "5000")
    assert status == 2
    assert "frame range [5000, 4593) is empty or outside" in err


def test_it_reports_an_unwritable_output(capsys, bvh_13_29, tmp_path):
    status, _, err = run(capsys, "convert", bvh_13_29, tmp_path / "no" / "such" / "x.bvh")
    assert status == 2 and "No such file or directory" in err and err.count("\n") == 1


def test_it_shows_usage_for_an_unknown_command(capsys):
    with pytest.raises(SystemExit) as caught:
        main(["dance"])
    assert caught.value.code == 2
    err = capsys.readouterr().err
    assert "invalid choice: 'dance'" in err and err.count("\n") == 1


def test_it_reports_a_missing_argument_in_one_line(capsys):
    with pytest.raises(SystemExit) as caught:
        main(["convert", "only_input.amc"])
    assert caught.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("python -m motionlib convert: error: the following arguments are "
                          "required: output") and err.count("\n") == 1
