"""Survey of the periodic orbits of laws with impact memory (issue 48): the steady state
each law is said to reach, against a long run from rest (not a test).

Usage::

    python -m tests.survey_memory_orbits --n 120 [--first 0] [--workers 2]
        --out docs/_measured/memory-orbits.jsonl

Draw ``i`` takes a random machine of :mod:`tests.realistic`'s class ``i mod 4`` (P1,
slow P1, subharmonic, short contact: the machine's ranges only, its law is not used) and
a Flores (even ``i``) or Lankarani-Nikravesh (odd ``i``) law: ``n`` uniform in 1-1.6,
``e`` in 0.3-0.95, ``k`` giving the contact frequency ``2 pi f 10^U`` (``U`` in 0-1) on the
reduced mass at the typical penetration.  Nothing is rejected: chaotic motions, failures
and contacts that never end are rows too.

For each draw: :func:`~discovery.vibroimpact.dynamics.steady_states.steady_state` (the
regime and the largest Floquet multiplier), and a run from rest with the kernel's own
period-by-period integration (which carries the contact memory exactly): 2700 periods (longer
than the search follows the motion: its 366 periods of transients, then up to 2000 to see the
motion reach the orbit Newton found, with the 200 strobe points the run's period is read from
after that), and 15000 where that run has not settled.  A chaotic transient lands when it
lands: draw 83's search saw the motion reach its P4 after about 2300 periods, the run from
rest reached the same orbit after 7300 (a 1500-period run had called it a disagreement).  The
run's last 200 strobe points give its period (the smallest ``n <= 8`` recurring within
1e-6) and when it settled, and its strobe points' approach to the reported orbit its
contraction per orbit (a log-linear fit between 1e-3 and 100 times the final distance).  A
row agrees when the steady state says nonperiodic and the run does not settle within the
periods the search follows (366), or when the run ends within 1e-3 of the reported orbit
and the multiplier's rate per period is within 0.03 of the run's (``rho^(1/n)``; the
distance of a complex pair wobbles, so a fit over a few orbits is rough), or the run
reached the orbit too fast to measure one.

A row that disagrees is run again from rest at a hundred times tighter a tolerance (its
twin, ``rtol`` 1e-11): through a chaotic transient, which of two coexisting attractors the
motion ends on, and when, is decided by rounding well inside a valid integration's error
(the search's spans of 30, 300 and 50 periods and a period-by-period run from rest part by
2.6e-6 of the scales after 48 periods).  The table counts the rows that agree with either.
"""

import argparse
import json
import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
if not __package__:
    sys.path[0:1] = [str(HERE.parent)]

import numpy as np  # noqa: E402

from tests import measured  # noqa: E402

CATEGORIES = ("p1", "p1-slow", "subharmonic", "short-contact")
MODELS = ("flores", "lankarani-nikravesh")
#: the runs from rest, the second where the first has not settled: the search's transients,
#: its reach test's 2000 periods and the 200 strobe points the run's period is read from, with
#: margin; then a chaotic transient's time to land
LONG_RUNS = (2700, 15000)
#: the twin run's relative tolerance (of a row the first run disagrees with, :func:`run_case`;
#: the package's default is 1e-9)
TWIN_RTOL = 1e-11
#: the periods the steady-state search follows before it gives up (30 + 18 + 300 + 18)
SEARCHED = 366


def draw(i):
    """The scenario and memory law of draw ``i`` (and the law's model text)."""
    from discovery.vibroimpact.model.contact_models import parse_law
    from tests.realistic import _draw

    rng = np.random.default_rng(1000 + i)
    scenario, _, _ = _draw(rng, CATEGORIES[i % 4])
    mu = scenario.m1 * scenario.m2 / (scenario.m1 + scenario.m2)
    wc = 2 * math.pi * scenario.frequency * 10 ** rng.uniform(0, 1)
    z0 = scenario.scales()[1] / wc
    n = float(rng.uniform(1.0, 1.6))
    e = float(rng.uniform(0.3, 0.95))
    k = mu * wc**2 * z0 ** (1 - n)
    text = f"{MODELS[i % 2]}: k={k:.4g}, n={n:.3g}, e={e:.3g}"
    return scenario, parse_law(text), text


def _long_run(scenario, law, ss, tolerances=None):
    """The run from rest (with the integrator's ``tolerances``, default the package's): its
    period, its contraction per orbit onto ``ss``'s orbit and its final distance to it."""
    from discovery.numerics.shooting import recurrence
    from discovery.vibroimpact.dynamics.steady_states import StroboscopicMap

    for periods in LONG_RUNS:
        pm = StroboscopicMap(scenario, law, tolerances)
        pts = pm.strobe(scenario.initial_state(), periods)
        rec = recurrence(pts[-200:], pm.scale, 8)
        period = next((n for n in sorted(rec) if rec[n] < 1e-6), None)
        if period is not None:
            break
    out = {"long_period": period, "long_run": periods}
    if period is not None:
        # the first strobe point from which the run recurs within 1e-3 for good
        gap = np.max(np.abs(pts[period:] - pts[:-period]) / pm.scale, axis=1)
        out["settled_after"] = int(len(gap) - np.argmax(gap[::-1] >= 1e-3))
    if not ss.periodic:
        return out
    pm.zeta_max, pm.impact_v0 = ss.zeta_max0, ss.impact_v0
    orbit = pm.strobe(ss.y0, ss.n_periods)[:-1]
    d = np.array([min(np.max(np.abs(p - q) / pm.scale) for q in orbit) for p in pts])
    dd = d[:: ss.n_periods]
    out["final_distance"] = float(d[-1])
    floor = max(1e-9, 100 * dd[-1])
    above = np.nonzero(dd > floor)[0]
    if len(above):
        k = np.arange(above[-1] + 1)
        seg = dd[: above[-1] + 1]
        keep = (seg > floor) & (seg < 1e-3)
        if keep.sum() >= 5:
            out["contraction"] = float(np.exp(np.polyfit(k[keep], np.log(seg[keep]), 1)[0]))
    return out


def run_case(i):
    """One row: the draw, the steady state, the long run and whether they agree."""
    from discovery.errors import VidiError
    from discovery.numerics.tolerances import Tolerances
    from discovery.vibroimpact.dynamics.steady_states import steady_state

    scenario, law, text = draw(i)
    row = {"draw": i, "category": CATEGORIES[i % 4], "model": MODELS[i % 2], "law": text}
    try:
        ss = steady_state(scenario, law)
    except VidiError as exc:
        return {**row, "error": str(exc)}
    row.update(
        regime=ss.regime,
        impacts=ss.impacts,
        multiplier=float(np.max(np.abs(ss.multipliers))) if ss.periodic else None,
        in_contact=bool(ss.periodic and ss.y0[0] - ss.y0[2] > 0),
        simulations=ss.n_simulations,
    )
    try:
        row.update(_long_run(scenario, law, ss))
    except VidiError as exc:
        return {**row, "long_error": str(exc)}
    row["agrees"] = agrees(row)
    if not row["agrees"]:
        # the same run from rest at a hundred times tighter a tolerance: where a chaotic
        # transient decides between coexisting attractors, rounding at the 1e-6 of a valid
        # integration decides which one the motion ends on, and when
        try:
            twin = _long_run(scenario, law, ss, Tolerances(rtol=TWIN_RTOL))
        except VidiError as exc:
            twin = {"long_error": str(exc)}
        row["twin"] = twin
        row["twin_agrees"] = agrees({**row, **twin})
    return row


def agrees(r):
    """Whether a row's steady state is the long run's (see the module's docstring)."""
    if r.get("error") or r.get("long_error"):
        return False
    if r["regime"] == "nonperiodic":
        return r["long_period"] is None or r.get("settled_after", 0) > SEARCHED
    if r.get("final_distance", 1.0) > 1e-3:
        return False  # the run from rest is not on the reported orbit
    c, n = r.get("contraction"), int(r["regime"][1:])
    return c is None or abs(r["multiplier"] ** (1 / n) - c ** (1 / n)) <= 0.03


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=120)
    p.add_argument("--first", type=int, default=0)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", required=True, help="the run file of the rows (JSON lines)")
    args = p.parse_args(argv)
    from multiprocessing import get_context

    out = measured.RunFile(args.out, "survey_memory_orbits", argv)
    with get_context("spawn").Pool(args.workers) as pool:
        for row in pool.imap(run_case, range(args.first, args.first + args.n)):
            out.write(row)
            print(json.dumps(row), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())


# ------------------------------------------------------------- the docs' table
read_rows = measured.rows


def _outcome(r):
    if r.get("error") or r.get("long_error"):
        return "failed"
    return "nonperiodic" if r["regime"] == "nonperiodic" else "periodic"


def markdown_row(rows, label):
    """docs/contact-models.md's row ``label``: a model, a class, or "all"."""
    if label in MODELS:
        rows = [r for r in rows if r["model"] == label]
    elif label != "all":
        rows = [r for r in rows if r["category"] == label]
    periodic = [r for r in rows if _outcome(r) == "periodic"]
    inside = [r for r in periodic if r.get("in_contact")]
    cells = [
        label,
        str(len(rows)),
        str(len(periodic)),
        str(len(inside)),
        str(sum(_outcome(r) == "nonperiodic" for r in rows)),
        str(sum(_outcome(r) == "failed" for r in rows)),
        f"{sum(bool(r.get('agrees')) for r in rows)}/{len(rows)}",
        f"{sum(bool(r.get('agrees') or r.get('twin_agrees')) for r in rows)}/{len(rows)}",
        f"{sum(bool(r.get('agrees')) for r in periodic)}/{len(periodic)}",
    ]
    return "| " + " | ".join(cells) + " |"
