"""Compile the simulators once and keep them in numba's cache (``python -m discovery.warm``).

The compiled kernels (the vibro-impact integrator with its event location, and Ueda's
oscillator) are cached by numba beside their sources (``__pycache__``).  Without a cache
the first simulation compiles them (about a minute on two cores, most of it the
vibro-impact integrator with its event location and sensitivities; the oscillator's
records, scans, charts and exponents about 20 s); ``make install`` runs
this module once so that the first command after it starts in a second, and
`discovery._compile.announce_compile` says so in one line when a command has to compile
anyway.
"""

import sys
import time

from ._compile import _ANNOUNCED, KERNELS, cached

__all__ = ["warm", "main"]


def warm():
    """Compile (or load) every kernel: ``{kernel: seconds}``."""
    out = {}
    t0 = time.perf_counter()
    from .vibroimpact.dynamics.warmup import compile_kernels

    compile_kernels()
    out["vibro-impact"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    from .ueda.exponents import lyapunov, lyapunov_two_trajectory
    from .ueda.record import simulate_record
    from .ueda.regime_chart import chart
    from .ueda.strobe import strobe_points
    from .ueda.system import UedaSystem

    system = UedaSystem.from_model("negres")
    simulate_record(system, 2, 50, 0.0, 0, transient=2)
    strobe_points(system, n=2, transient=2)
    lyapunov(system, transient=2, periods=4, batches=2)
    lyapunov_two_trajectory(system, transient=2, periods=4, batches=2)
    # a chart's scan with its early exit, and the Floquet check of a period-1 point
    chart(system, [1.0], [0.6], workers=1, progress=False)
    out["oscillator"] = time.perf_counter() - t0
    return out


def main():
    todo = [k for k in KERNELS if not cached(k)]
    if todo:
        print(
            f"compiling the simulators once ({', '.join(todo)}; about a minute on two cores) ...",
            flush=True,
        )
    # said here once: the runs below need not announce their compile again
    _ANNOUNCED.update(KERNELS)
    seconds = warm()
    print(
        "simulators ready ("
        + ", ".join(f"{k} {v:.1f} s" for k, v in seconds.items())
        + "); later runs load them from the cache"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
