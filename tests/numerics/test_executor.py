"""One executor for every sweep: serial, process pool and Dask give the same results."""

import multiprocessing
import time

import numpy as np
import pytest

from discovery import ForceLaw, landscape, load_scenario
from discovery.errors import InputError
from discovery.numerics.executor import Pool, Serial, make_executor, map_on
from discovery.ueda import UedaSystem
from discovery.ueda.regime_chart import chart


def _square(context, job):
    return (context or 0) + job * job


def _fail_on_three(context, job):
    if job == 3:
        raise InputError("three")
    return job


def test_executors_agree_and_place_results_by_index():
    jobs = list(range(12))
    want = [10 + j * j for j in jobs]
    assert Serial().map(_square, jobs, 10) == want
    assert Pool(2).map(_square, jobs, 10) == want
    assert isinstance(make_executor(1), Serial) and isinstance(make_executor(2), Pool)


def test_map_on_reports_each_finished_job_once():
    for workers in (1, 2):
        seen = []
        got = map_on(
            _square, range(7), 1, workers=workers, done=lambda k, n, s=seen: s.append((k, n))
        )
        assert got == [1 + j * j for j in range(7)]
        assert seen == [(k, 7) for k in range(1, 8)]


def _blas_threads(context, job):
    from threadpoolctl import threadpool_info

    return sorted({i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"})


def test_every_job_runs_with_one_blas_thread():
    """Wherever a job runs, its BLAS has one thread (idle BLAS threads spin and take the
    other workers' cores; one count everywhere keeps a job's arithmetic the same)."""
    assert Serial().map(_blas_threads, [0, 1]) == [[1], [1]]
    assert Pool(2).map(_blas_threads, [0, 1]) == [[1], [1]]


def test_the_blas_libraries_are_looked_for_again_only_after_an_import():
    """The libraries one job found serve the next, until a module is imported (it may
    bring a BLAS of its own); outside a job the BLAS has its threads back."""
    import sys
    import types

    from threadpoolctl import threadpool_info

    from discovery.numerics import executor as E

    before = [i["num_threads"] for i in threadpool_info()]
    with E.one_blas_thread():
        pass
    first = E._BLAS["controller"]
    with E.one_blas_thread():
        assert _blas_threads(None, 0) == [1]
    assert E._BLAS["controller"] is first
    sys.modules["_a_module_imported_since"] = types.ModuleType("_a_module_imported_since")
    try:
        with E.one_blas_thread():
            assert _blas_threads(None, 0) == [1]
        assert E._BLAS["controller"] is not first
    finally:
        del sys.modules["_a_module_imported_since"]
    assert [i["num_threads"] for i in threadpool_info()] == before


def test_pool_raises_the_job_error_and_leaves_no_worker():
    with pytest.raises(InputError, match="three"):
        Pool(2).map(_fail_on_three, list(range(8)))
    time.sleep(0.2)
    assert not multiprocessing.active_children()


def test_dask_executor_agrees_with_serial():
    pytest.importorskip("distributed")
    from discovery.numerics.executor import Dask

    with Dask("local", workers=2) as ex:
        assert ex.map(_square, list(range(12)), 10) == [10 + j * j for j in range(12)]


def _landscape(**kw):
    sc = load_scenario("paper")
    law = ForceLaw.parse("2.06e8*z + 1.28e7*zd")
    return landscape(sc, law, np.linspace(1.5e8, 2.5e8, 4), np.linspace(1e7, 1.5e7, 3), **kw)


def _same_landscape(a, b):
    for n in a.values:
        assert np.array_equal(a.values[n], b.values[n], equal_nan=True), n
    assert np.array_equal(a.regime, b.regime) and np.array_equal(a.consistent, b.consistent)


def test_landscape_is_bitwise_the_same_on_every_executor():
    serial = _landscape(workers=1)
    _same_landscape(serial, _landscape(workers=2))
    with Serial() as ex:
        _same_landscape(serial, _landscape(executor=ex))
    pytest.importorskip("distributed")
    from discovery.numerics.executor import Dask

    with Dask("local", workers=2) as ex:
        land = _landscape(executor=ex)
    _same_landscape(serial, land)
    assert land.workers == 2


def test_chart_is_bitwise_the_same_on_the_pool_and_serially():
    system = UedaSystem.from_model("negres")
    kw = dict(transient=20, periods=32, max_period=8)
    a = chart(system, [0.9, 1.0, 1.1], [0.4, 0.8], workers=1, **kw)
    b = chart(system, [0.9, 1.0, 1.1], [0.4, 0.8], workers=2, **kw)
    for name in ("kind", "period", "lyapunov", "rotation"):
        assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=True), name
