"""python -m motionlib info / convert, run as a user would."""

import subprocess
import sys

import numpy as np

import motionlib


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "motionlib", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd)


def test_it_describes_a_bvh(bvh_13_29):
    result = run("info", bvh_13_29)
    assert result.returncode == 0, result.stderr
    lines = dict(line.split(":", 1) for line in result.stdout.splitlines())
    assert lines["format"].strip() == "bvh" and lines["fps"].strip() == "120"
    assert lines["frames"].strip() == "4593" and lines["joints"].strip() == "31"
    assert lines["duration"].strip() == "38.275 s"
    assert lines["rest pose frame"].strip() == "0"


def test_it_describes_an_amc_with_its_asf(amc_13_29):
    result = run("info", amc_13_29[0], "--asf", amc_13_29[1])
    assert result.returncode == 0, result.stderr
    assert "format:          amc" in result.stdout and "frames:          4592" in result.stdout
    assert "rest pose frame: none" in result.stdout


def test_it_converts_an_amc_to_bvh_with_the_same_positions(amc_13_29, tmp_path):
    out = tmp_path / "13_29.bvh"
    result = run("convert", amc_13_29[0], "--asf", amc_13_29[1], out, "--stop", "600")
    assert result.returncode == 0, result.stderr
    assert "frames 0 to 599" in result.stdout
    amc = motionlib.read(amc_13_29[0], asf=amc_13_29[1]).slice(0, 600)
    bvh = motionlib.read(out)
    difference = motionlib.forward_kinematics(bvh) - motionlib.forward_kinematics(amc)
    assert np.abs(difference).max() < 1e-4


def test_it_reports_a_bad_file_in_one_line_with_status_2(tmp_path):
    bad = tmp_path / "bad.bvh"
    bad.write_text("HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 1 Xposition\n}\n"
                   "MOTION\nFrames: 2\nFrame Time: 0.1\n1\n")
    result = run("info", bad)
    assert result.returncode == 2
    assert result.stderr.strip() == ("motionlib info: error: bad.bvh:10: truncated MOTION "
                                     "section: 'Frames: 2' but the file ends after 1 frame lines")
    assert "Traceback" not in result.stderr


def test_it_reports_a_missing_asf_in_one_line(amc_13_29):
    result = run("convert", amc_13_29[0], "out.bvh")
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1
    assert "needs its .asf skeleton" in result.stderr


def test_it_reports_a_frame_range_outside_the_take(bvh_13_29, tmp_path):
    result = run("convert", bvh_13_29, tmp_path / "x.bvh", "--start", "5000")
    assert result.returncode == 2
    assert "frame range [5000, 4593) is empty or outside" in result.stderr


def test_it_shows_usage_for_an_unknown_command():
    result = run("dance")
    assert result.returncode == 2 and "invalid choice: 'dance'" in result.stderr
