"""The BLAS kernels the suite runs on: the stored survey runs' kernels wherever the CPU has
them, and on them a named draw is the stored record (tests/kernels.py)."""

import os

import pytest

from tests import kernels as K
from tests.measured import MEASURED, read


def test_the_suite_runs_the_stored_kernels_where_the_cpu_has_them():
    """The pin reaches the suite's processes, unless the run asked for other kernels: a
    value of ``OPENBLAS_CORETYPE`` set by the caller is kept (the Makefile and
    ``tests/__init__.py``), and the tests of named survey draws then skip, saying so."""
    if not K.has_avx512():
        pytest.skip("this CPU has no AVX-512: OpenBLAS runs its own kernels here")
    chosen = os.environ.get("OPENBLAS_CORETYPE", K.STORED)
    if chosen.lower() != K.STORED.lower():
        pytest.skip(
            f"OPENBLAS_CORETYPE={chosen} was set for this run (kept): OpenBLAS runs "
            f"{', '.join(K.in_use())}, not the stored runs' {K.STORED}"
        )
    assert K.as_stored(), (
        f"OpenBLAS runs {K.in_use()} on a CPU with AVX-512: the pin to {K.STORED} "
        "(Makefile, tests/__init__.py) did not reach this process"
    )


def test_a_named_draw_is_its_stored_record_on_the_stored_kernels():
    """Draw 30 (a short contact, P2 after a long transient from rest) is the draw the Haswell
    kernels turn into an irregular motion (the true law's I2 0.50): on the stored kernels its
    true model's I2 is the stored run's to the last digits."""
    from discovery.vibroimpact.verify import Reference, evaluate
    from tests import survey_effects as S

    K.require_stored()
    d = S.draw(30, "high")
    row = S._verify_truth(d.machine, d.true, d.lag, d.record, d.start, evaluate, Reference)
    _, rows = read(MEASURED / "effects.jsonl")
    stored = next(r for r in rows if r.get("draw") == 30 and r.get("noise") == "high")
    assert row["true_I2"] == pytest.approx(stored["true_I2"], rel=1e-9)
