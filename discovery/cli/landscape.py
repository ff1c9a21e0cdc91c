"""``vidi landscape``: criteria over a grid of two coefficients."""

import csv
import io

import numpy as np

from .._io import OutputDir, provenance
from ..criteria import CRITERIA
from ..scenario import load_scenario
from ._common import SCENARIO_HELP, law_or_default, parse_range


def _grid_csv(land):
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow([land.terms[0], land.terms[1], "regime", *CRITERIA])
    for i, a in enumerate(land.axes[0]):
        for j, b in enumerate(land.axes[1]):
            w.writerow([f"{a:.10g}", f"{b:.10g}", land.regime[i, j],
                        *[f"{land.values[n][i, j]:.10g}" for n in CRITERIA]])
    return buf.getvalue()


def run(args):
    from reports import landscape_figure

    from ..landscape import landscape, parse_grid

    sc = load_scenario(args.scenario)
    law = law_or_default(args.law, sc)
    n0, n1 = parse_grid(args.grid)
    r0 = parse_range(args.range0, (1.03e8, 3.09e8), "--range0")
    r1 = parse_range(args.range1, (0.64e7, 1.92e7), "--range1")
    a0, a1 = np.linspace(*r0, n0), np.linspace(*r1, n1)
    land = landscape(sc, law, a0, a1, workers=args.workers)
    with OutputDir(args.out) as out:
        summary = {"command": "landscape", "scenario": sc.as_dict(), "terms": land.terms,
                   "alpha1": a0, "alpha2": a1,
                   **{n: land.values[n] for n in CRITERIA},
                   "regime": land.regime.tolist(), "seconds": land.seconds,
                   "workers": land.workers,
                   "minima": {n: {"alpha1": a0[land.argmin(n)[0]], "alpha2": a1[land.argmin(n)[1]]}
                              for n in CRITERIA},
                   **provenance(vars(args))}
        out.write_json("summary.json", summary)
        out.path("landscape.csv").write_text(_grid_csv(land))
        truth = tuple(sc.law.coefficients[:2]) if sc.law is not None else None
        landscape_figure(land, str(out.path("landscape")), truth=truth)
    regimes = {r: int(np.sum(land.regime == r)) for r in set(land.regime.ravel())}
    print(f"landscape {n0}x{n1} in {land.seconds:.1f} s on {land.workers} processes; "
          f"regimes {regimes}")
    for n in CRITERIA:
        i, j = land.argmin(n)
        print(f"  {n}: minimum {np.nanmin(land.values[n]):.3g} at ({a0[i]:.4g}, {a1[j]:.4g})")
    print(f"outputs in {args.out}/: summary.json, landscape.csv, landscape.png, landscape.pdf")
    return 0


def register(sub):
    s = sub.add_parser("landscape", help="criteria I0..I4 over a grid of the first two "
                       "coefficients (paper Figs. 4-5)")
    s.add_argument("--scenario", default="paper", help=SCENARIO_HELP)
    s.add_argument("--law", help="template law whose first two coefficients vary "
                   "(default: the scenario's law)")
    s.add_argument("--grid", default="41x41", help="points per axis, e.g. 41x41")
    s.add_argument("--range0", help="LOW:HIGH of the first coefficient (1.03e8:3.09e8)")
    s.add_argument("--range1", help="LOW:HIGH of the second coefficient (0.64e7:1.92e7)")
    s.add_argument("--workers", type=int, help="processes (default: all cores)")
    s.add_argument("--out", required=True, help="output directory")
    s.set_defaults(func=run)
