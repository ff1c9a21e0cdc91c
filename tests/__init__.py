"""The test suite and the surveys (``python -m tests.survey_...``).

The BLAS kernels are pinned before numpy loads them (``tests/kernels.py`` says why); the
Makefile pins them too, for every process of ``make test``, ``make surveys`` and ``make
bench``.  Set here, the pin also reaches a plain ``pytest`` run's workers and a survey run
with ``python -m``, and it is set even where this process has loaded numpy already, for the
processes it starts.  A value set by the caller is kept.
"""

import os

from tests.kernels import STORED, has_avx512

if has_avx512():
    os.environ.setdefault("OPENBLAS_CORETYPE", STORED)
