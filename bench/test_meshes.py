"""Tests of the benchmark's OBJ reader and midpoint subdivision (python3 -m pytest bench)."""

import numpy as np
import pytest

from meshes import kSubdivided, read_obj, select_meshes, subdivide_midpoint, write_obj

# A unit tetrahedron: closed, 4 vertices, 6 edges, 4 faces, consistently oriented.
kTetraPositions = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
kTetraTriangles = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]], dtype=np.int32)


def triangle_areas(positions, triangles):
    corners = positions[triangles]
    return 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)


def directed_edges(triangles):
    return {(int(t[i]), int(t[(i + 1) % 3])) for t in triangles for i in range(3)}


def test_reads_quads_fanned_from_the_first_corner_with_slashes_and_negative_indices(tmp_path):
    path = tmp_path / "quad.obj"
    path.write_text("# comment\nv 0 0 0\nv 1 0 0\nvn 0 0 1\nv 1 1 0\nv 0 1 0 0.5\n"
                    "f 1//1 2//1 3//1 4//1\nf -4/1 -2/2 -1/3\n")
    positions, triangles = read_obj(path)
    np.testing.assert_array_equal(positions, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    np.testing.assert_array_equal(triangles, [[0, 1, 2], [0, 2, 3], [0, 2, 3]])
    assert triangles.dtype == np.int32


def test_rejects_an_index_past_the_last_vertex_naming_the_file(tmp_path):
    path = tmp_path / "bad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")
    with pytest.raises(ValueError, match="bad.obj: face index 4 out of range"):
        read_obj(path)


def test_rejects_a_face_with_two_vertices_naming_the_line(tmp_path):
    path = tmp_path / "short.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nf 1 2\n")
    with pytest.raises(ValueError, match="short.obj:3:"):
        read_obj(path)


def test_written_obj_reads_back_bit_for_bit(tmp_path):
    rng = np.random.default_rng(7)
    positions = rng.normal(size=(4, 3)) * 1e3
    path = tmp_path / "round_trip.obj"
    write_obj(path, positions, kTetraTriangles)
    read_positions, read_triangles = read_obj(path)
    assert np.array_equal(read_positions, positions)
    np.testing.assert_array_equal(read_triangles, kTetraTriangles)


def test_subdivision_counts_follow_euler_on_a_closed_mesh():
    positions, triangles = kTetraPositions, kTetraTriangles
    for _ in range(2):
        edges = len(directed_edges(triangles)) // 2
        new_positions, new_triangles = subdivide_midpoint(positions, triangles)
        assert len(new_positions) == len(positions) + edges
        assert len(new_triangles) == 4 * len(triangles)
        positions, triangles = new_positions, new_triangles
    assert len(positions) - len(directed_edges(triangles)) // 2 + len(triangles) == 2


def test_subdivision_keeps_old_vertices_and_puts_new_ones_at_edge_midpoints():
    positions, triangles = subdivide_midpoint(kTetraPositions, kTetraTriangles)
    np.testing.assert_array_equal(positions[:4], kTetraPositions)
    # Face 0 = (0, 2, 1): its first child is (corner 0, midpoint of 0-2, midpoint of 1-0).
    child = triangles[0]
    assert child[0] == 0
    np.testing.assert_array_equal(positions[child[1]], [0, 0.5, 0])
    np.testing.assert_array_equal(positions[child[2]], [0.5, 0, 0])


def test_subdivision_splits_each_face_into_four_quarter_area_faces_keeping_orientation():
    positions, triangles = subdivide_midpoint(kTetraPositions, kTetraTriangles)
    parent_areas = triangle_areas(kTetraPositions, kTetraTriangles)
    np.testing.assert_allclose(triangle_areas(positions, triangles), np.repeat(parent_areas / 4, 4), rtol=1e-15)
    # Consistent orientation: every directed edge appears once and its reverse also appears (closed mesh).
    edges = [(int(t[i]), int(t[(i + 1) % 3])) for t in triangles for i in range(3)]
    assert len(edges) == len(set(edges))
    assert all((b, a) in set(edges) for a, b in edges)


def test_the_third_subdivision_is_made_only_when_named(tmp_path):
    # A tetrahedron stands in for nefertiti: three levels give 4 * 64 faces in no time.
    mesh_dir = tmp_path / "meshes"
    mesh_dir.mkdir()
    write_obj(mesh_dir / "nefertiti.obj", kTetraPositions, kTetraTriangles)
    every = {mesh.name for mesh in select_meshes(mesh_dir, tmp_path / "work", None, kSubdivided)}
    assert every == {"nefertiti", "nefertiti-sub1", "nefertiti-sub2"}
    [sub3] = select_meshes(mesh_dir, tmp_path / "work", ["nefertiti-sub3"], kSubdivided)
    assert (sub3.name, sub3.face_count) == ("nefertiti-sub3", 4 * 64)
    assert read_obj(sub3.obj_path)[1].shape == (256, 3)
