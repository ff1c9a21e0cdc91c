"""Not a test module: which modules a piece of code loads, run in a fresh interpreter (the
test process itself has loaded everything by the time a test runs)."""

import subprocess
import sys


def loaded_after(code, modules, timeout=300):
    """Those of ``modules`` that are in ``sys.modules`` after ``code`` runs in a new
    interpreter (this one's executable, environment and working directory)."""
    probe = (
        f"{code}\nimport sys\nprint(','.join(m for m in {tuple(modules)!r} if m in sys.modules))"
    )
    out = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, timeout=timeout
    )
    return [m for m in out.stdout.strip().split(",") if m]
