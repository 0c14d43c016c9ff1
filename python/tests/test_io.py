"""Trajectory files through Python: write_trajectory's lines are the
formats' (checked against text written out here), its output reads back
to the same poses and timestamps, EuRoC times are converted exactly, and
every refusal is a ValueError naming the index."""

import numpy as np
import pytest

import bireg
from conftest import DATA


def test_tum_round_trip_keeps_timestamps_and_poses(tmp_path):
    data = bireg.read_trajectory(DATA / "se3_deepmimic_walk.tum", group="SE3")
    out = tmp_path / "walk.tum"
    bireg.write_trajectory(out, data["t"], data["Y"], group="SE3", format="tum",
                           timestamps=data["timestamps"], timestamps_format=data["format"])
    again = bireg.read_trajectory(out, group="SE3")
    assert again["format"] == "tum"
    assert again["timestamps"] == data["timestamps"]
    np.testing.assert_array_equal(again["t"], data["t"])
    # Matrix -> quaternion -> matrix: a few roundings of numbers of size 1.
    np.testing.assert_allclose(again["Y"], data["Y"], rtol=0, atol=1e-15)


def test_euroc_times_are_converted_exactly(tmp_path):
    data = bireg.read_trajectory(DATA / "se3_deepmimic_walk.tum", group="SE3")
    out = tmp_path / "walk.csv"
    bireg.write_trajectory(out, data["t"], data["Y"], format="euroc",
                           timestamps=data["timestamps"], timestamps_format="tum")
    lines = out.read_text().splitlines()
    assert lines[0].startswith("#timestamp [ns]")
    # 0.033332 s is 33332000 ns, exactly.
    assert [line.split(",")[0] for line in lines[1:4]] == ["0", "33332000", "66664000"]
    assert all(len(line.split(",")) == 17 for line in lines[1:])
    again = bireg.read_trajectory(out, group="SE3")
    np.testing.assert_array_equal(again["t"], data["t"])


def test_times_from_t_and_the_matrix_and_kitti_lines(tmp_path):
    t = np.array([0.0, 0.1, 0.25])
    Y = bireg.SE3.exp(np.array([[0, 0, 0, 0, 0, 0], [1, 2, 3, 0, 0, 0], [0, 0, 0, 0, 0, np.pi / 2]],
                               dtype=float))
    out = tmp_path / "poses.txt"
    bireg.write_trajectory(out, t, Y, format="matrix")
    first, second, _ = out.read_text().splitlines()
    assert first == "0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1"
    assert second == "0.1, 1, 0, 0, 1, 0, 1, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1"
    bireg.write_trajectory(out, t, Y, format="euroc")
    assert [line.split(",")[0] for line in out.read_text().splitlines()[1:]] == [
        "0", "100000000", "250000000"]
    bireg.write_trajectory(out, t, Y, format="kitti")
    lines = out.read_text().splitlines()
    assert lines[1] == "1 0 0 1 0 1 0 2 0 0 1 3"
    assert [float(v) for v in lines[2].split()] == pytest.approx(
        [0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0], abs=1e-15)
    # A rotation by pi/2 about z in TUM: q = (0, 0, sin(pi/4), cos(pi/4)).
    bireg.write_trajectory(out, t, Y, format="tum")
    last = out.read_text().splitlines()[2].split(" ")
    assert last[0] == "0.25"
    assert [float(v) for v in last[1:]] == pytest.approx(
        [0, 0, 0, 0, 0, np.sqrt(0.5), np.sqrt(0.5)], abs=1e-15)


def test_any_group_writes_the_matrix_format(tmp_path):
    t = np.linspace(0.0, 1.0, 5)
    Y = bireg.Sim3.exp(np.outer(t, [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]))
    out = tmp_path / "sim3.txt"
    bireg.write_trajectory(out, t, Y, group="Sim3", format="matrix")
    again = bireg.read_trajectory(out, group="Sim3")
    np.testing.assert_array_equal(again["Y"], Y)  # shortest round-trip text: exact
    np.testing.assert_array_equal(again["t"], t)


def test_write_refusals_are_value_errors(tmp_path):
    t = np.linspace(0.0, 1.0, 4)
    Y = bireg.SE3.exp(np.zeros((4, 6)))
    out = tmp_path / "x.txt"
    with pytest.raises(ValueError, match="not Sim3"):
        bireg.write_trajectory(out, t, bireg.Sim3.exp(np.zeros((4, 7))), group="Sim3",
                               format="tum")
    bad = Y.copy()
    bad[2, 0, 1] = 0.5
    with pytest.raises(ValueError, match=r"Y\[2\] is not an element of SE3"):
        bireg.write_trajectory(out, t, bad)
    with pytest.raises(ValueError, match=r"t\[1\] is not finite"):
        bireg.write_trajectory(out, [0.0, np.inf, 2.0, 3.0], Y)
    with pytest.raises(ValueError, match="timestamp 3"):
        bireg.write_trajectory(out, t, Y, timestamps=["0", "1", "2", "soon"])
    for blank in (" 1", "\n1", "1\r\n", "1,5", "\v1"):
        with pytest.raises(ValueError, match="timestamp 1 holds a space, a separator or a line"):
            bireg.write_trajectory(out, t, Y, timestamps=["0", blank, "2", "3"])
    with pytest.raises(ValueError, match=r"timestamps\[1\] must be a str"):
        bireg.write_trajectory(out, t, Y, timestamps=["0", 1, "2", "3"])
    with pytest.raises(ValueError, match="differ in length"):
        bireg.write_trajectory(out, t, Y, timestamps=["0", "1"])
    with pytest.raises(ValueError, match="unknown format"):
        bireg.write_trajectory(out, t, Y, format="csv")
