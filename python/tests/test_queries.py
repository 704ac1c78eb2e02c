"""Queries: batch == single == hinted bit for bit (surface and volume),
threads, arrays out and back in, files."""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np

import abgs


def test_batch_equals_single(coarse: abgs.Grid, points: np.ndarray) -> None:
    """sizes_at == size_at == hinted size_at == closest().size, bit for bit."""
    batch = coarse.sizes_at(points)
    single = np.array([coarse.size_at(p) for p in points])
    hint = abgs.Hint()
    assert hint.triangle is None
    hinted = np.array([coarse.size_at(p, hint) for p in points])
    assert hint.triangle is not None and 0 <= hint.triangle < coarse.n_triangles
    closest = np.array([coarse.closest(p).size for p in points[:200]])
    np.testing.assert_array_equal(batch, single)
    np.testing.assert_array_equal(batch, hinted)
    np.testing.assert_array_equal(batch[:200], closest)
    assert np.all(batch > 0)


def test_volume_batch_equals_single(coarse: abgs.Grid, points: np.ndarray) -> None:
    """Volume mode: batch == single; never above the surface size at the closest point."""
    batch = coarse.sizes_at_volume(points, beta=1.2)
    single = np.array([coarse.size_at_volume(p, beta=1.2) for p in points])
    np.testing.assert_array_equal(batch, single)
    assert np.all(batch <= coarse.sizes_at(points) * (1 + 1e-12) + 0.2 * np.array(
        [coarse.closest(p).distance for p in points]))


def test_closest_is_on_the_surface(coarse: abgs.Grid) -> None:
    """A vertex is its own closest point, at distance 0, with its own size."""
    v, s = coarse.vertices, coarse.sizes
    for i in (0, len(v) // 2, len(v) - 1):
        h = coarse.closest(v[i])
        assert h.distance == 0.0 and np.allclose(h.point, v[i])
        assert abs(sum(h.bary) - 1) < 1e-12
        assert abs(h.size - s[i]) <= 1e-12 * s[i]


def test_threads(coarse: abgs.Grid, points: np.ndarray) -> None:
    """Batches and single queries from 4 Python threads at once (the GIL is
    released in every call) give the single-threaded answers."""
    want = coarse.sizes_at(points)
    want_vol = coarse.sizes_at_volume(points)
    got: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

    def work(k: int) -> None:
        b = np.concatenate([coarse.sizes_at(points) for _ in range(5)])
        v = coarse.sizes_at_volume(points)
        h = abgs.Hint()
        s = np.array([coarse.size_at(p, h) for p in points[k::4]])
        got[k] = (b, v, s)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sorted(got) == [0, 1, 2, 3]
    for k, (b, v, s) in got.items():
        np.testing.assert_array_equal(b, np.tile(want, 5))
        np.testing.assert_array_equal(v, want_vol)
        np.testing.assert_array_equal(s, want[k::4])


def test_arrays_roundtrip(coarse: abgs.Grid, points: np.ndarray) -> None:
    """vertices / triangles / sizes out, from_arrays back in: same grid, same answers."""
    v, t, s = coarse.vertices, coarse.triangles, coarse.sizes
    assert v.shape == (coarse.n_vertices, 3) and v.dtype == np.float64
    assert t.shape == (coarse.n_triangles, 3) and t.dtype == np.uint32
    assert s.shape == (coarse.n_vertices,) and s.dtype == np.float64
    st = coarse.stats
    assert st.has_sizes == 1 and st.size_min == s.min() and st.size_max == s.max()
    assert np.allclose(st.bbox_min, v.min(axis=0)) and np.allclose(st.bbox_max, v.max(axis=0))
    with abgs.Grid.from_arrays(v, t.astype(np.int64), s) as g:
        np.testing.assert_array_equal(g.vertices, v)
        np.testing.assert_array_equal(g.triangles, t)
        np.testing.assert_array_equal(g.sizes_at(points), coarse.sizes_at(points))
    # Non-contiguous and Fortran-ordered input is taken as well.
    with abgs.Grid.from_arrays(np.asfortranarray(v), t[:, [0, 1, 2]], s[::1]) as g:
        np.testing.assert_array_equal(g.sizes_at(points[::3]), coarse.sizes_at(points[::3]))


def test_save_and_load(coarse: abgs.Grid, points: np.ndarray, tmp_path: Path) -> None:
    """vtk keeps every bit; msh (Gmsh's background field) loads back with its sizes."""
    for ext in ("vtk", "msh"):
        f = tmp_path / f"field.{ext}"
        coarse.save(f)
        with abgs.Grid.load(f) as g:
            assert g.n_triangles == coarse.n_triangles and g.has_sizes
            np.testing.assert_allclose(g.sizes_at(points), coarse.sizes_at(points), rtol=1e-12)
            if ext == "vtk":
                np.testing.assert_array_equal(g.sizes_at(points), coarse.sizes_at(points))


def test_set_sizes_and_gradation(dense: abgs.Grid) -> None:
    """set_sizes replaces the sizes; apply_gradation lowers a spike's neighbours."""
    with abgs.Grid.from_arrays(dense.vertices, dense.triangles, dense.sizes) as g:
        h = np.full(g.n_vertices, 10.0)
        h[0] = 0.01
        g.set_sizes(h)
        np.testing.assert_array_equal(g.sizes, h)
        g.apply_gradation(beta=1.2)
        after = g.sizes
        assert after[0] == 0.01 and after.max() <= 10.0 and (after < 10.0).sum() > 1


def test_remesh_outputs(surface: abgs.Grid, dense: abgs.Grid) -> None:
    """The dense grid's report, kept feature edges and issue texts."""
    r = dense.remesh_report
    assert r is not None and r.faces_out == dense.n_triangles and r.faces_in == surface.n_triangles
    fe = dense.feature_edges
    assert fe.shape == (r.feature_edges_out, 2) and fe.max() < dense.n_vertices
    assert len(dense.remesh_issues()) == r.n_issues
    assert dense.edges.shape == (dense.stats.edges, 2)
    vl, el = dense.lbo()
    assert vl.shape == (dense.n_vertices,) and el.shape == (dense.stats.edges,)


def test_sources_and_params(surface: abgs.Grid) -> None:
    """A point source lowers the sizes near it; hmax caps them."""
    g = surface.remesh(relative_length=0.05)
    d = g.stats.diagonal
    base = g.compute_sizes(hmax=d / 20)
    assert base.hmax == d / 20 and g.sizes.max() <= d / 20
    c = g.vertices[0]
    rep = g.compute_sizes(hmax=d / 20, sources=[abgs.point_source(c, d / 500, d / 50)])
    assert rep.limited_by_source > 0
    assert g.size_at(c) <= d / 500 * (1 + 1e-12)


def test_hausdorff(dense: abgs.Grid, coarse: abgs.Grid) -> None:
    """hausdorff == evaluate's, and the larger of the two one-sided distances."""
    h = abgs.hausdorff(dense, coarse, samples=20000, seed=3)
    e = abgs.evaluate(dense, coarse, samples=1000, hausdorff_samples=20000, seed=3)
    assert h == e.hausdorff > 0
    ab = abgs.hausdorff(dense, coarse, samples=20000, seed=3, directed=True)
    ba = abgs.hausdorff(coarse, dense, samples=20000, seed=3, directed=True)
    assert h == max(ab, ba)


def test_edge_scores(coarse: abgs.Grid) -> None:
    """One score per edge; invalid edges score 1 with NaN estimates."""
    s = coarse.edge_scores(method="lbo", t_size=1.2)
    n = coarse.stats.edges
    assert all(a.shape == (n,) for a in s.values())
    assert np.all((s["y"] >= 0) & (s["y"] <= 1))
    bad = ~s["valid"]
    assert np.all(s["y"][bad] == 1) and np.all(np.isnan(s["ds"][bad]))


def test_bytes_round_trip(coarse: abgs.Grid, points: np.ndarray) -> None:
    """to_bytes / from_bytes (what an MPI rank broadcasts): the same arrays and
    the same answers bit for bit; the bytes depend only on the grid; a
    corrupted byte is refused with a ParseError, never garbage."""
    data = coarse.to_bytes()
    assert data == coarse.to_bytes()
    back = abgs.Grid.from_bytes(data)
    np.testing.assert_array_equal(back.vertices, coarse.vertices)
    np.testing.assert_array_equal(back.triangles, coarse.triangles)
    np.testing.assert_array_equal(back.sizes, coarse.sizes)
    np.testing.assert_array_equal(back.sizes_at(points), coarse.sizes_at(points))
    assert back.to_bytes() == data
    bad = bytearray(data)
    bad[len(bad) // 2] ^= 0x40
    try:
        abgs.Grid.from_bytes(bad)
    except abgs.AbgsError as e:
        assert e.status != 0
    else:
        raise AssertionError("a corrupted byte was accepted")
    try:
        abgs.Grid.from_bytes(data[:10])
    except abgs.AbgsError:
        pass
    else:
        raise AssertionError("truncated bytes were accepted")


def test_remesh_in_pieces() -> None:
    """A unit cube at edge length 0.1 (about 1,400 triangles) in pieces of
    about 200 is cut along its edges and comes out closed, in one body;
    ``piece_faces=0`` never cuts."""
    v = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]
    t = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
         [3, 7, 6], [3, 6, 2], [0, 4, 7], [0, 7, 3], [1, 2, 6], [1, 6, 5]]
    cube = abgs.Grid.from_arrays(np.array(v, dtype=np.float64), np.array(t, dtype=np.uint32))
    whole = cube.remesh(edge_length=0.1, piece_faces=0)
    cut = cube.remesh(edge_length=0.1, piece_faces=200)
    assert whole.remesh_report.pieces == 0
    assert cut.remesh_report.pieces >= 2
    for g in (whole, cut):
        s = g.stats
        assert (s.bodies, s.boundary_edges, s.non_manifold_edges) == (1, 0, 0)
