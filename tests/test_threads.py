"""Every public entry point that simulates runs with one BLAS thread (issue 14)."""

import numpy as np
from threadpoolctl import threadpool_info, threadpool_limits

from holofold.mechanics import single_thread, single_threaded, solve_newton
from holofold.mechanics.structure import Structure


def _blas_threads():
    return [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]


def _blas_by_library():
    # Per library: some BLAS builds are single-threaded whatever the limit (cvxopt's OpenBLAS).
    return {i["filepath"]: i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}


def _bar():
    return Structure(
        nodes=[[0.0, 0, 0], [1, 0, 0]],
        bars=[[0, 1]],
        bar_area=1e-4,
        bar_E=1e9,
        springs=np.zeros((0, 4), int),
        spring_k=[],
        spring_rest=[],
        supports=[[True] * 3, [False, True, True]],
    )


def test_single_thread_is_reentrant_and_restores():
    with threadpool_limits(2):
        outside = _blas_by_library()
        assert 2 in outside.values()
        with single_thread():
            assert set(_blas_threads()) == {1}
            with single_thread():
                assert set(_blas_threads()) == {1}
            assert set(_blas_threads()) == {1}  # the inner exit keeps the outer limit
        assert _blas_by_library() == outside


def test_solvers_limit_blas_themselves():
    seen = []

    @single_threaded
    def probe():
        seen.append(set(_blas_threads()))

    with threadpool_limits(2):
        outside = _blas_by_library()
        probe()
        load = np.zeros((2, 3))
        load[1, 0] = 1.0
        import holofold.mechanics.assembly as assembly

        orig = assembly.Assembler.evaluate_factorized

        def spy(self, *a, **k):
            seen.append(set(_blas_threads()))
            return orig(self, *a, **k)

        assembly.Assembler.evaluate_factorized = spy
        try:
            res = solve_newton(_bar(), load, increments=2)
        finally:
            assembly.Assembler.evaluate_factorized = orig
        assert res.ok
        assert _blas_by_library() == outside
    assert seen and all(s == {1} for s in seen)
