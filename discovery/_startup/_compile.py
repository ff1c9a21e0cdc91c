"""Whether the compiled kernels are in numba's cache, and one line when a run must compile
them (see :mod:`discovery.warm`)."""

import hashlib
import os
import sys
from pathlib import Path

__all__ = ["KERNELS", "cached", "refresh", "announce_compile", "borrowing_options"]

_HERE = Path(__file__).parent.parent  # the package, discovery/
KERNELS = {
    "vibro-impact": (
        _HERE / "vibroimpact" / "dynamics" / "kernel",
        "loop.integrate-",
    ),
    "oscillator": (_HERE / "ueda", "_kernel."),
}
_ANNOUNCED = set()
# the sources beyond a kernel's own folder that its compiled functions inline
_SHARED = (_HERE / "numerics" / "_dopri.py", _HERE / "numerics" / "_tableau.py")
_STAMP = "sources.sha1"
# the kernels split over the modules of a package: their cache is checked against all of them
_PACKAGES = {"vibro-impact"}


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
    ``"oscillator"``; a kernel whose sources changed since its cache was made is not, see
    :func:`refresh`)."""
    if kernel in _PACKAGES:
        refresh(kernel)
    folder, prefix = KERNELS[kernel]
    cache = _cache_folder(folder)
    return cache.is_dir() and any(
        p.name.startswith(prefix) and p.suffix == ".nbi" for p in cache.iterdir()
    )


def refresh(kernel="vibro-impact"):
    """Drop numba's cache of ``kernel`` if any of its sources changed since it was made.

    Numba stamps a cached function with the content of its own file only, while the function
    holds everything it calls or inlines from other modules: a kernel split over several
    modules (and built on the shared Dormand-Prince blocks) would otherwise run an edited
    module's old code from the cache of a module left as it was.  The digest of all the
    kernel folder's modules and the shared blocks is kept beside the cache (``sources.sha1``);
    when it differs, the folder's cached functions are removed and the digest written.
    Nothing happens where the cache cannot be written (numba then compiles in memory)."""
    folder, _ = KERNELS[kernel]
    digest = hashlib.sha1()
    for path in sorted(folder.glob("*.py")) + list(_SHARED):
        digest.update(path.read_bytes())
    cache = _cache_folder(folder)
    try:
        if (cache / _STAMP).read_text() == digest.hexdigest():
            return
    except OSError:
        pass
    try:
        if cache.is_dir():
            for p in cache.iterdir():
                if p.suffix in (".nbi", ".nbc"):
                    p.unlink(missing_ok=True)
        cache.mkdir(parents=True, exist_ok=True)
        (cache / _STAMP).write_text(digest.hexdigest())
    except OSError:  # a read-only install: numba compiles without its cache
        pass


def announce_compile(kernel="vibro-impact", stream=None):
    """One line on stderr before a run that must compile ``kernel`` (checked once per
    process)."""
    if kernel in _ANNOUNCED:
        return
    _ANNOUNCED.add(kernel)  # checked once per process
    if cached(kernel):
        return
    print(
        f"vidi: compiling the {kernel} simulator once (one to a few minutes; cached for "
        "every later run; `make install` does it ahead)",
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
