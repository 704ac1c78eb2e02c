"""The progress callback of simplify: called once per iteration with its
record, may cancel, and an exception inside it stops the run and is re-raised
(the process survives)."""

from __future__ import annotations

import numpy as np
import pytest

import abgs


def test_called_with_every_record(dense: abgs.Grid, coarse: abgs.Grid) -> None:
    """One call per iteration that collapsed something, records equal to the
    grid's own table (and to the run without a callback)."""
    seen: list[abgs.IterationRecord] = []
    g = dense.simplify(progress=seen.append)
    recs = g.iterations()
    assert coarse.simplify_report is not None and g.simplify_report is not None
    assert len(seen) >= 2 and len(recs) >= len(seen)
    for a, b in zip(seen, recs):
        assert a.struct_size == b.struct_size > 0
        assert {k: v for k, v in a.as_dict().items() if k != "seconds"} == {
            k: v for k, v in b.as_dict().items() if k != "seconds"
        }
    assert [r.iteration for r in seen] == list(range(1, len(seen) + 1))
    assert all(r.accepted > 0 for r in seen)
    assert np.all(np.diff([r.faces for r in seen]) < 0)
    np.testing.assert_array_equal(g.sizes, coarse.sizes)
    assert g.simplify_report.stop == abgs.STOP_CONVERGED


def test_cancel(dense: abgs.Grid) -> None:
    """A truthy return stops after that iteration: stop == CANCELLED, the grid
    is valid and equals a run limited to the same number of iterations."""
    calls = []

    def stop_at_two(rec: abgs.IterationRecord) -> bool:
        calls.append(rec.iteration)
        return rec.iteration == 2

    g = dense.simplify(progress=stop_at_two)
    assert calls == [1, 2]
    assert g.simplify_report is not None
    assert g.simplify_report.stop == abgs.STOP_CANCELLED
    assert g.simplify_report.iterations == 2
    ref = dense.simplify(max_iterations=2)
    assert ref.simplify_report is not None and ref.simplify_report.stop == abgs.STOP_MAX_ITERATIONS
    np.testing.assert_array_equal(g.vertices, ref.vertices)
    np.testing.assert_array_equal(g.triangles, ref.triangles)
    assert g.n_triangles < dense.n_triangles
    assert np.isfinite(g.sizes_at(g.vertices)).all()


class Boom(Exception):
    """Raised by the test callback."""


def test_exception_in_callback_is_reraised(dense: abgs.Grid) -> None:
    """The exception stops the run at once and comes out of simplify; the
    process and the dense grid are fine afterwards."""
    calls = []

    def boom(rec: abgs.IterationRecord) -> None:
        calls.append(rec.iteration)
        raise Boom(f"at iteration {rec.iteration}")

    with pytest.raises(Boom, match="at iteration 1"):
        dense.simplify(progress=boom)
    assert calls == [1]

    def interrupt(rec: abgs.IterationRecord) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        dense.simplify(progress=interrupt)
    # Still usable: a mutation goes through (nothing holds the grid any more).
    s = dense.sizes
    dense.set_sizes(s)
    assert dense.simplify(max_iterations=1).n_triangles < dense.n_triangles


def test_busy_inside_callback(dense: abgs.Grid) -> None:
    """A mutation of the grid being simplified, from inside the callback, is
    BUSY (nothing changed); so is closing it."""
    errors: list[BaseException] = []
    before = dense.sizes

    def mutate(rec: abgs.IterationRecord) -> bool:
        for fn in (lambda: dense.set_sizes(before * 2), dense.close):
            try:
                fn()
            except abgs.BusyError as e:
                errors.append(e)
        return True

    dense.simplify(progress=mutate)
    assert len(errors) == 2 and all(e.status == abgs.errors.ERR_BUSY for e in errors)
    assert not dense.closed
    np.testing.assert_array_equal(dense.sizes, before)


def test_global_selection(dense: abgs.Grid, coarse: abgs.Grid) -> None:
    """The paper's global selection estimates more for the same kind of grid
    (the default is the batched one)."""
    g = dense.simplify(selection="global")
    est = [sum(r.estimated for r in x.iterations()) for x in (g, coarse)]
    assert est[0] > est[1]
    assert g.simplify_report is not None and coarse.simplify_report is not None
    faces = (g.simplify_report.faces_out, coarse.simplify_report.faces_out)
    assert abs(faces[0] / faces[1] - 1.0) < 0.2, faces
    assert g.simplify_report.stop == abgs.STOP_CONVERGED


def test_fit_sizes_off(dense: abgs.Grid, coarse: abgs.Grid) -> None:
    """Without the size fit the same grid comes out with the sizes the
    collapses left: different from the fitted ones, but never by more than
    t_size (1.2)."""
    g = dense.simplify(fit_sizes=False)
    np.testing.assert_array_equal(g.vertices, coarse.vertices)
    np.testing.assert_array_equal(g.triangles, coarse.triangles)
    assert not np.array_equal(g.sizes, coarse.sizes)
    ratio = g.sizes / coarse.sizes
    assert np.all(np.maximum(ratio, 1.0 / ratio) <= 1.2 * (1.0 + 1e-12))
