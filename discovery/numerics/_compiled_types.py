"""The array types the compiled loops are declared with (numba is imported with this module,
so only the modules that compile import it)."""

from numba import types

__all__ = ["readonly"]


def readonly(dtype, ndim=1):
    """A C-ordered read-only array type of ``dtype`` (a numba type) and ``ndim``.

    A loop declared with it is compiled once: numba types a read-only array apart from a
    writeable one, and takes a writeable array as a read-only one where only that version
    exists, so neither a memoised (read-only) array nor a fresh one compiles another version
    at a user's first command (two more versions of the criteria's interpolation took 0.5 s
    of the quickstart's first ``verify``)."""
    return types.Array(dtype, ndim, "C", readonly=True)
