"""Compile the simulators once and keep them in numba's cache (``python -m discovery.warm``).

The compiled kernels (the vibro-impact integrator with its event location, and Ueda's
oscillator) are cached by numba beside their sources (``__pycache__``).  Without a cache
the first simulation compiles them (one to a few minutes, most of it the vibro-impact
integrator with its event location and sensitivities; the README's times table has the
measured figure); ``make install`` runs this module once, with a line every
:data:`HEARTBEAT` seconds while it compiles, so that the first command after it starts in a
second, and
`discovery._startup._compile.announce_compile` says so in one line when a command has to compile
anyway.
"""

import sys
import threading
import time

from ._startup._compile import _ANNOUNCED, KERNELS, cached

__all__ = ["warm", "main", "HEARTBEAT"]

#: seconds between the "still compiling" lines
HEARTBEAT = 10.0


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


def _heartbeat(done, t0, every, stream):
    """A line on ``stream`` every ``every`` seconds until ``done`` is set."""
    while not done.wait(every):
        print(f"  still compiling ({time.perf_counter() - t0:.0f} s)", file=stream, flush=True)


def main(every=HEARTBEAT, stream=None):
    stream = stream or sys.stdout
    todo = [k for k in KERNELS if not cached(k)]
    done = threading.Event()
    if todo:
        print(
            f"compiling the simulators once ({', '.join(todo)}; one to a few minutes) ...",
            file=stream,
            flush=True,
        )
        beat = (done, time.perf_counter(), every, stream)
        threading.Thread(target=_heartbeat, args=beat, daemon=True).start()
    # said here once: the runs below need not announce their compile again
    _ANNOUNCED.update(KERNELS)
    try:
        seconds = warm()
    finally:
        done.set()
    print(
        "simulators ready ("
        + ", ".join(f"{k} {v:.1f} s" for k, v in seconds.items())
        + "); later runs load them from the cache",
        file=stream,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
