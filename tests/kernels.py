"""The BLAS kernels the stored survey runs were made with, and whether this process uses them.

OpenBLAS picks its kernels by the CPU (SkylakeX on Intel's AVX-512 parts, Haswell or Zen on
AMD's), and the kernels round their sums in different orders.  Most records do not notice
(their forces agree to 1e-11 of the range), but a record of a long transient from rest
amplifies the last bit until the machine settles on another orbit: with the Haswell kernels,
the effects survey's draws 30, 33, 74 and 75 are other records (forces apart by the whole
range, the window shifted), explain's answer on them differs, and six slow tests of such draws
failed on an AMD machine.  Every stored survey run and every test of a named draw was made with
the SkylakeX kernels, which any CPU with AVX-512 runs (``OPENBLAS_CORETYPE=SkylakeX``
reproduces the runs bit for bit on an AMD EPYC).  On a CPU without AVX-512 the named draws are
not the stored records and their tests skip, saying so.
"""

import functools

STORED = "SkylakeX"


def has_avx512():
    """Whether this CPU has AVX-512 (the stored kernels need it)."""
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as f:
            for line in f:
                if line.startswith("flags"):
                    return "avx512f" in line.split()
    except OSError:
        pass
    return False


@functools.cache
def in_use():
    """The architectures of the OpenBLAS libraries numpy and scipy.linalg loaded here (a
    process's kernels are chosen once, when the libraries load)."""
    import numpy  # noqa: F401
    import scipy.linalg  # noqa: F401
    from threadpoolctl import threadpool_info

    return tuple(
        sorted(
            {
                i.get("architecture", "?")
                for i in threadpool_info()
                if i["internal_api"] == "openblas"
            }
        )
    )


def as_stored():
    """Whether every OpenBLAS library here runs the stored runs' kernels."""
    return in_use() == (STORED,)


def require_stored():
    """Skip the calling test where a named draw would not be the stored record."""
    import pytest

    if not as_stored():
        pytest.skip(
            f"a named survey draw is the stored record only on the {STORED} BLAS kernels "
            f"(this process runs {', '.join(in_use())}; tests/kernels.py)"
        )
