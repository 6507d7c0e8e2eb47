"""Tests of the anisotropy measure g(M), the stretched-grid meshes and the robustness report's smoke run
(python3 -m pytest bench)."""

import json
import math

import numpy as np
import pytest

from meshes import anisotropic_height_field, anisotropy, ridged_height

kSqrt3 = math.sqrt(3)


def test_equilateral_triangles_have_anisotropy_one_whatever_their_size_and_placement():
    triangle = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, kSqrt3 / 2, 0]])
    rotated = triangle @ np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]]) * 7 + [3, -2, 5]
    positions = np.concatenate([triangle, rotated])
    assert anisotropy(positions, np.array([[0, 1, 2], [3, 4, 5]])) == pytest.approx(1.0, rel=1e-14)


def test_anisotropy_of_known_triangles_follows_the_formula_and_averages_over_faces():
    positions = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [4, 0, 0], [0, 3, 0]])
    # Right isosceles, legs 1: P = (2 + sqrt 2) / 2, H = sqrt 2, S = 1/2.
    isosceles = (2 + math.sqrt(2)) / 2 * math.sqrt(2) / (2 * kSqrt3 * 0.5)
    # The 3-4-5 right triangle: P = 6, H = 5, S = 6.
    pythagorean = 6 * 5 / (2 * kSqrt3 * 6)
    assert anisotropy(positions, np.array([[0, 1, 2]])) == pytest.approx(isosceles, rel=1e-14)
    assert anisotropy(positions, np.array([[0, 3, 4], [0, 1, 2]])) == pytest.approx(
        (isosceles + pythagorean) / 2, rel=1e-14)


def test_a_zero_area_face_makes_anisotropy_infinite():
    positions = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    assert anisotropy(positions, np.array([[0, 1, 2]])) == math.inf


@pytest.mark.parametrize("stretch", [1, 4, 64])
def test_stretched_grids_keep_face_count_and_shape_and_cover_the_square_once(stretch):
    positions, triangles = anisotropic_height_field(6000, stretch)
    assert abs(len(triangles) - 6000) < 0.02 * 6000
    np.testing.assert_array_equal(positions[0], [0, 0, ridged_height(np.array(0.0), np.array(0.0))])
    np.testing.assert_allclose(positions[:, 2], ridged_height(positions[:, 0], positions[:, 1]))
    # Seen from above every triangle is counter-clockwise and together they tile the unit square.
    corners = positions[triangles][:, :, :2]
    first, second = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    signed_areas = 0.5 * (first[:, 0] * second[:, 1] - first[:, 1] * second[:, 0])
    assert signed_areas.min() > 0
    assert signed_areas.sum() == pytest.approx(1.0, rel=1e-12)
    # Manifold with one boundary loop: every edge in at most two faces, interior edges in opposite directions.
    directed = {(int(t[i]), int(t[(i + 1) % 3])) for t in triangles for i in range(3)}
    assert len(directed) == 3 * len(triangles)


def test_anisotropy_grows_with_the_stretch_while_the_surface_area_stays_put():
    def area(positions, triangles):
        corners = positions[triangles]
        edges = corners[:, 1:] - corners[:, :1]
        return 0.5 * np.linalg.norm(np.cross(edges[:, 0], edges[:, 1]), axis=1).sum()

    meshes = [anisotropic_height_field(6000, stretch) for stretch in (1, 2, 8, 32)]
    g = [anisotropy(*mesh) for mesh in meshes]
    assert g == sorted(g)
    assert g[0] == pytest.approx(1.39, abs=0.05)  # square cells: right isosceles triangles, slightly curved
    # Long thin right triangles: g ~ stretch / sqrt(3), a little less where slopes lengthen the short legs.
    assert g[-1] == pytest.approx(32 / kSqrt3, rel=0.2)
    areas = [area(*mesh) for mesh in meshes]
    assert max(areas) - min(areas) < 1e-3 * areas[0]


def test_quick_robustness_run_writes_its_report(tmp_path, exactgeo_with_variants):
    pytest.importorskip("matplotlib")
    import anisotropy as robustness

    status = robustness.main(["--faces", "800", "--stretches", "1", "16", "--variants", "vtp", "ftp", "--peers",
                              "heat", "--repeat", "1", "--build-dir", str(exactgeo_with_variants.parent.parent),
                              "--work-dir", str(tmp_path / "work"), "--results-dir", str(tmp_path), "--name", "r"])
    assert status == 0
    report = json.loads((tmp_path / "r.json").read_text())
    assert [mesh["stretch"] for mesh in report["meshes"]] == [1, 16]
    assert report["meshes"][0]["g"] < report["meshes"][1]["g"]
    ours = [r for r in report["records"] if r["solver"] in ("vtp", "ftp")]
    assert len(ours) == 4 and all(r["exactness"]["agrees"] for r in ours)
    markdown = (tmp_path / "r.md").read_text()
    assert "## Propagation time against anisotropy" in markdown and "MISMATCH" not in markdown
    assert (tmp_path / "r.png").stat().st_size > 0
