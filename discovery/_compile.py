"""Whether the compiled kernels are in numba's cache, and one line when a run must compile
them (see :mod:`discovery.warm`)."""

import hashlib
import os
import sys
from pathlib import Path

__all__ = ["KERNELS", "cached", "announce_compile", "borrowing_options"]

_HERE = Path(__file__).parent
KERNELS = {
    "vibro-impact": (
        _HERE / "vibroimpact" / "dynamics" / "kernel",
        "loop.integrate-",
    ),
    "oscillator": (_HERE / "ueda", "_kernel."),
}
_ANNOUNCED = set()


def _cache_folder(folder):
    """Where numba caches the functions of the modules in ``folder``: ``__pycache__`` beside
    them, or with ``NUMBA_CACHE_DIR`` set, numba's subfolder there (the folder's name and the
    SHA-1 of its absolute path)."""
    root = os.environ.get("NUMBA_CACHE_DIR")
    if not root:
        return folder / "__pycache__"
    path = os.path.abspath(folder)
    return Path(root) / f"{os.path.basename(path)}_{hashlib.sha1(path.encode()).hexdigest()}"


def cached(kernel="vibro-impact"):
    """Whether numba's cache holds the compiled ``kernel`` (``"vibro-impact"`` or
    ``"oscillator"``)."""
    folder, prefix = KERNELS[kernel]
    cache = _cache_folder(folder)
    return cache.is_dir() and any(
        p.name.startswith(prefix) and p.suffix == ".nbi" for p in cache.iterdir()
    )


def announce_compile(kernel="vibro-impact", stream=None):
    """One line on stderr before a run that must compile ``kernel`` (checked once per
    process)."""
    if kernel in _ANNOUNCED:
        return
    _ANNOUNCED.add(kernel)  # checked once per process
    if cached(kernel):
        return
    print(
        f"vidi: compiling the {kernel} simulator once (under a minute on two cores; "
        "cached for every later run; `make install` does it ahead)",
        file=stream or sys.stderr,
        flush=True,
    )


def borrowing_options():
    """The numba options of a kernel function that allocates nothing and takes its arrays
    borrowed: ``{"_nrt": False}`` (no reference counts, as numba compiles its own helpers)
    where this numba has that option, else none, so that a release without the private
    option still compiles the kernels, with the counts (the same arithmetic, slower)."""
    try:
        from numba.core.cpu import CPUTargetOptions
    except ImportError:  # a numba without that module: the counts stay
        return {}
    return {"_nrt": False} if hasattr(CPUTargetOptions, "_nrt") else {}
