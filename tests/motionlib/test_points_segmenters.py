"""Segmenters on point takes: body parts from the known marker sets, gaps closed for the
features only, bare points for the methods that need no body parts, and a clear reason from
the others."""

from dataclasses import replace

import numpy as np
import pytest

import motionlib
from motionlib import markersets
from motionlib.points import filled, make_point_take, point_skeleton
from motionlib.segmenters import get_segmenter, list_segmenters
from tests.motionlib.points_data import HDM05, points_file

METHODS = [cls.name for cls in list_segmenters()]


@pytest.fixture(scope="module")
def hdm05():
    return motionlib.read(points_file(*HDM05))


@pytest.fixture(scope="module")
def kinect():
    return motionlib.read(points_file("utkinect", "s01_e01.csv"))


@pytest.fixture(scope="module")
def vmci():
    return motionlib.read(points_file("vmci", "subject1_run1.tsv"))


def test_filled_interpolates_inside_a_gap_and_holds_the_ends():
    points = np.array([np.nan, 1.0, np.nan, 3.0, np.nan])[:, None, None].repeat(3, axis=2)
    out = filled(points)
    np.testing.assert_array_equal(out[:, 0, 0], [1, 1, 2, 3, 3])
    assert np.isnan(points[0, 0, 0])  # the input is left as it was


def test_filled_leaves_a_point_never_seen_unknown():
    points = np.full((4, 2, 3), np.nan)
    points[:, 0] = 1.0
    assert np.isnan(filled(points)[:, 1]).all()


def test_plug_in_gait_markers_give_every_body_part(hdm05):
    positions, joints = markersets.body_joints(hdm05)
    assert set(joints) == set(motionlib.CANONICAL_PARTS)
    assert not np.isnan(positions).any()
    height = positions[:, joints["head"], 1] - positions[:, joints["left_ankle"], 1]
    assert np.median(height) > 1200  # mm, head above ankle: Y up
    at = {n.split(":")[-1]: i for i, n in enumerate(hdm05.point_names)}
    wrist = (hdm05.positions[:, at["LWRA"]] + hdm05.positions[:, at["LWRB"]]) / 2
    np.testing.assert_allclose(positions[:, joints["left_wrist"]], wrist)


def test_kinect_joints_are_the_body_parts_themselves(kinect):
    positions, joints = markersets.body_joints(kinect)
    knee = kinect.point_names.index("knee_left")
    np.testing.assert_array_equal(positions[:, joints["left_knee"]],
                                  filled(kinect.positions)[:, knee])


@pytest.mark.parametrize("names, expected", [
    (["SpineBase", "SpineMid", "Neck", "Head", "ShoulderLeft", "ElbowLeft", "WristLeft",
      "ShoulderRight", "ElbowRight", "WristRight", "HipLeft", "KneeLeft", "AnkleLeft",
      "HipRight", "KneeRight", "AnkleRight", "SpineShoulder"], "kinect v2"),
    (["LASI", "RASI", "LPSI", "RPSI", "C7", "CLAV", "T10", "STRN", "LFHD", "LSHO", "LELB",
      "LWRA", "LKNE", "LANK", "RSHO", "RELB", "RWRA", "RKNE", "RANK"], "plug-in gait"),
    (["Shoulder", "Elbow", "Hand top"], None),
])
def test_it_identifies_the_marker_set_by_its_names(names, expected):
    assert markersets.identify(names) == expected


@pytest.mark.parametrize("name", METHODS)
def test_every_method_runs_on_a_plug_in_gait_c3d(hdm05, name):
    result = get_segmenter(name)().fit_predict(hdm05)
    assert len(result.cuts) > 0 and (result.cuts < hdm05.n_frames).all()
    assert all(np.isfinite(s).all() for s in result.signals.values())


@pytest.mark.parametrize("name", METHODS)
def test_every_method_runs_on_kinect_joints_with_long_gaps(kinect, name):
    assert np.isnan(kinect.positions).any(axis=(1, 2)).mean() > 0.5
    result = get_segmenter(name)().fit_predict(kinect)
    assert len(result.cuts) > 0
    assert all(np.isfinite(s).all() for s in result.signals.values())
    assert np.isnan(kinect.positions).any()  # the stored points keep their gaps


def test_the_default_method_runs_on_bare_points(vmci):
    result = get_segmenter("default")().fit_predict(vmci)
    assert (result.cuts > 0).all() and (result.cuts < vmci.n_frames).all()
    assert len(result.signals["novelty"]) == vmci.n_frames


def test_ppca_runs_on_the_coordinates_of_bare_points(vmci):
    from motionlib.points import bare_coordinates
    from motionlib.segmenters.ppca import pose_vectors

    x, first = pose_vectors(vmci)
    np.testing.assert_array_equal(x, bare_coordinates(vmci))
    assert first == 0 and x.shape == (vmci.n_frames, 39) and not np.isnan(x).any()
    result = get_segmenter("ppca")().fit_predict(vmci)
    assert (result.cuts < vmci.n_frames).all()
    assert np.isfinite(result.signals["mahalanobis"]).all()
    assert len(result.signals["mahalanobis"]) == vmci.n_frames


def test_the_default_method_on_bare_points_sees_the_coordinates(vmci):
    """Moving one marker's path changes the cuts: the detector reads the points."""
    channels = vmci.channels.copy()
    channels[: vmci.n_frames // 2] += 300.0
    moved = make_point_take(name="moved", format="tsv", fps=vmci.fps,
                            coordinates=channels.reshape(vmci.n_frames, -1, 3),
                            names=vmci.point_names, unit="mm", up="z")
    a = get_segmenter("default")().fit_predict(vmci).cuts
    b = get_segmenter("default")().fit_predict(moved).cuts
    assert not np.array_equal(a, b)


@pytest.mark.parametrize("name", ["bone_angle", "joint_distance_pca"])
def test_a_method_that_needs_body_parts_says_why_it_cannot_run_on_bare_points(vmci, name):
    with pytest.raises(motionlib.CaptureError, match=rf"subject1_run1\.tsv: method '{name}' "
                       r"cannot run on this take: it needs body parts .* follow no known "
                       r"marker set \(Plug-in Gait, Kinect v1, Kinect v2\)"):
        get_segmenter(name)().fit_predict(vmci)


def test_a_body_part_whose_markers_are_never_seen_is_named(hdm05):
    knee = hdm05.point_names.index("Bastian:LKNE")
    channels = hdm05.channels.copy()
    channels[:, 3 * knee: 3 * knee + 3] = np.nan
    positions = hdm05.positions.copy()
    positions[:, knee] = np.nan
    blind = replace(hdm05, channels=channels, positions=positions)
    with pytest.raises(motionlib.CaptureError, match=r"no point of the left knee \(LKNE\) is "
                       r"seen in any frame"):
        get_segmenter("bone_angle")().fit_predict(blind)


def test_point_links_must_not_form_a_cycle():
    with pytest.raises(ValueError, match="forest"):
        point_skeleton(["a", "b"], [1, 0])


def test_the_default_detector_adapts_to_reviewed_takes_of_bare_points(vmci):
    from motionlib import adapt

    other = motionlib.read(points_file("vmci", "subject1_run2.tsv"))
    model = adapt.fit_cut_model([(vmci, [44, 130, 281, 337, 404, 495, 599]),
                                 (other, [60, 200, 330, 470, 600])])
    result = adapt.detect(motionlib.read(points_file("vmci", "subject1_run3.tsv")), model)
    assert len(result.cuts) > 0 and (result.cuts > 0).all()
