"""``vidi identify``: identify a law's coefficients by simulation."""

import csv
import io
import json
from pathlib import Path

import numpy as np

from .._io import OutputDir, provenance
from ..criteria import CRITERIA
from ..errors import InputError
from ..law import ForceLaw
from ..scenario import load_scenario
from ._common import SCENARIO_HELP


def _pick_iterates(iterations, k):
    n = len(iterations)
    if n == 0:
        return []
    return sorted(set(np.unique(np.round(np.geomspace(1, n, k)).astype(int) - 1)))


def _load_landscape(path, cls):
    p = Path(path)
    p = p / "summary.json" if p.is_dir() else p
    try:
        d = json.loads(p.read_text())
    except (OSError, ValueError):
        raise InputError(f"--landscape {path!r}: no readable landscape summary.json") from None
    vals = {n: np.array(d[n], dtype=float) for n in CRITERIA}
    return cls(terms=tuple(d["terms"]), axes=(np.array(d["alpha1"]), np.array(d["alpha2"])),
               values=vals, regime=np.array(d["regime"], dtype=object),
               seconds=d["seconds"], workers=d["workers"])


def run(args):
    from reports import identification_figure

    from ..identify import identify
    from ..landscape import Landscape
    from ..measurement import Measurement
    from ..response import response

    sc = load_scenario(args.scenario)
    meas = Measurement.from_csv(args.data, scenario=sc)
    for note in meas.notes:
        print(f"note: {note}")
    E = meas.impulse(sc.period)
    start = ForceLaw.parse(args.start)
    res = identify(sc, E, start, criterion=args.criterion, method=args.method,
                   max_simulations=args.max_simulations, xtol=args.xtol)
    land = None
    if args.landscape:
        land = _load_landscape(args.landscape, Landscape)
    picks = _pick_iterates(res.iterations, 5)
    imps = []
    for k in picks:
        law = start.with_coefficients(list(res.iterations[k]["coefficients"].values()))
        r = response(sc, law)
        imps.append((f"iterate {k} ({res.iterations[k]['n_simulations']} sims)",
                     r.like(E) if r.impulse is not None else None))
    with OutputDir(args.out) as out:
        summary = {"command": "identify", "scenario": sc.as_dict(), "data": str(args.data),
                   "measured": {"n_cycles": E.n_cycles, "n_periods": E.n_periods,
                                "noise": E.noise, "threshold": E.threshold,
                                "peak": E.peak, "contact_time": E.contact_time},
                   "criterion": res.criterion, "method": res.method,
                   "start": start.as_dict(), "coefficients": res.coefficients,
                   "law": res.law.to_text(), "latex": res.law.latex(),
                   "criteria": res.criteria, "n_simulations": res.n_simulations,
                   "iterations": res.iterations, "message": res.message,
                   "seconds": res.seconds, **provenance(vars(args))}
        out.write_json("summary.json", summary)
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(["iterate", "n_simulations", res.criterion, *res.law.names])
        for k, it in enumerate(res.iterations):
            w.writerow([k, it["n_simulations"], f"{it['value']:.10g}",
                        *[f"{v:.10g}" for v in it["coefficients"].values()]])
        out.path("iterations.csv").write_text(buf.getvalue())
        identification_figure(res, E, imps, str(out.path("identification")), land)
    print(f"identified {res.law}")
    print(f"  {res.criterion} = {res.value:.4g} after {res.n_simulations} simulations "
          f"({res.method}, {res.seconds:.1f} s)")
    print("  criteria: " + ", ".join(f"{k} {v:.3g}" for k, v in res.criteria.items()))
    print(f"outputs in {args.out}/: summary.json, iterations.csv, identification.png, "
          "identification.pdf")
    return 0


def register(sub):
    s = sub.add_parser("identify", help="identify a law's coefficients from a measured CSV by "
                       "simulation (paper Figs. 6-7)")
    s.add_argument("--scenario", default="paper", help=SCENARIO_HELP)
    s.add_argument("--data", required=True, help="CSV with t [s], F [N] (w1, w2 optional)")
    s.add_argument("--criterion", default="I2", choices=list(CRITERIA),
                   help="criterion to minimise (I2)")
    s.add_argument("--method", default="least-squares",
                   choices=["coordinate-descent", "nelder-mead", "least-squares"],
                   help="optimiser (least-squares)")
    s.add_argument("--start", required=True, help="terms and start values, e.g. "
                   "'1.5e8*z + 0.9e7*zd'")
    s.add_argument("--max-simulations", type=int, default=600, help="simulation budget (600)")
    s.add_argument("--xtol", type=float, default=1e-5, help="relative coefficient tolerance")
    s.add_argument("--landscape", help="a landscape output (directory or summary.json) to draw "
                   "the path on")
    s.add_argument("--out", required=True, help="output directory")
    s.set_defaults(func=run)
