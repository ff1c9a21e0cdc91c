"""``vidi landscape``: criteria over a grid of two coefficients."""

import csv
import hashlib
import io

import numpy as np

from .._files._drawer import drawing
from .._files._io import OutputDir
from ..errors import InputError, IntegrationError
from ..vibroimpact.model.scenario import load_scenario
from ..vibroimpact.verify.criteria import CRITERIA, MOTION_DEFINITIONS
from . import _options
from ._common import (
    add_record_options,
    check_out,
    executor_of,
    law_or_default,
    machine_for,
    outputs_line,
    parse_range,
    provenance_of,
    read_record,
    reporter,
    sensor_lag_of,
)


def _grid_csv(land):
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow([land.terms[0], land.terms[1], "regime", *CRITERIA, "impacts", "consistent"])
    for i, a in enumerate(land.axes[0]):
        for j, b in enumerate(land.axes[1]):
            w.writerow(
                [
                    f"{a:.10g}",
                    f"{b:.10g}",
                    land.regime[i, j],
                    *[f"{land.values[n][i, j]:.10g}" for n in CRITERIA],
                    int(land.impacts[i, j]),
                    int(land.consistent[i, j]),
                ]
            )
    return buf.getvalue()


def _sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _ranges(args, law):
    """The two coefficient ranges and where they came from."""
    from ..vibroimpact.verify.criteria_landscape import DEFAULT_SPREAD, default_range

    out, origin = [], []
    for k, (text, opt) in enumerate(((args.range0, "--range0"), (args.range1, "--range1"))):
        if text is None:
            out.append(default_range(law.coefficients[k], law.names[k], opt))
            origin.append(
                f"default: {1 - DEFAULT_SPREAD:g}x..{1 + DEFAULT_SPREAD:g}x the "
                f"template's coefficient {law.coefficients[k]:.6g}"
            )
        else:
            lo, hi = parse_range(text, None, opt)
            if lo <= 0 <= hi:
                raise InputError(
                    f"{opt} {text!r} reaches zero: the coefficient of "
                    f"{law.names[k]} would vanish or change sign inside the grid; "
                    "give a range on one side of zero, e.g. "
                    f"{0.5 * abs(law.coefficients[k]):.3g}:"
                    f"{1.5 * abs(law.coefficients[k]):.3g}"
                )
            out.append((lo, hi))
            origin.append(f"{opt} {text}")
    return out, origin


def _reference(args, sc):
    """``(Reference or None, description for summary.json, notes)``."""
    from ..vibroimpact.verify import Reference

    if args.data is None:
        if sc.law is None:
            raise InputError(
                f"scenario {sc.name!r} has no reference law; pass --data D.csv "
                "(a measured record) or add [law] text to the scenario"
            )
        return None, {"source": "law", "law": sc.law.to_text()}, sc
    meas = read_record(args, sc)
    for note in meas.notes:
        print(f"note: {note}")
    (sc,), machine = machine_for(args, [sc], [meas], args.time_offset)
    ref = Reference.from_measurement(
        meas, sc, time_offset=args.time_offset, n_boot=args.n_boot, seed=args.seed
    )
    info = {
        "source": str(args.data),
        "sha256": _sha256(args.data),
        **ref.measured(),
        "time_offset": ref.time_offset,
        "n_boot": ref.n_boot,
        "seed": ref.seed,
        "notes": list(meas.notes),
        "machine": machine,
    }
    return ref, info, sc


#: the results' module the drawer loads while the command computes
#: (:mod:`discovery._files._drawer`)
_RESULTS = ("discovery.vibroimpact.verify.criteria_landscape",)


def run(args):
    check_out(args)
    with drawing(["landscape_figure"], _RESULTS) as drawer:
        return _run(args, drawer)


def _run(args, drawer):
    from ..vibroimpact.verify.criteria_landscape import landscape, parse_grid

    sc = load_scenario(args.scenario)
    law = law_or_default(args.law, sc)
    if len(law.terms) < 2:
        raise InputError(
            f"the template law '{law}' has {len(law.terms)} term(s); a landscape "
            "varies two coefficients, give --law with at least two terms, e.g. "
            "'2.06e8*z + 1.28e7*zd'"
        )
    n0, n1 = parse_grid(args.grid)
    (r0, r1), origin = _ranges(args, law)
    ref, ref_info, sc = _reference(args, sc)
    # the force sensor the calibration found (or --sensor-lag): read through, as verify does
    tau = sensor_lag_of(args, ref_info.get("machine"))
    a0, a1 = np.linspace(*r0, n0), np.linspace(*r1, n1)
    with reporter(args) as rep, executor_of(args) as ex:
        land = landscape(
            sc,
            law,
            a0,
            a1,
            ref,
            workers=args.workers,
            progress=rep,
            executor=ex,
            continuation=not args.no_continuation,
            sensor_lag=tau,
        )
    count, first, at = land.failures
    if count and count >= n0 * n1:  # nothing to show: one line and no output
        raise IntegrationError(
            f"every one of the {count} simulations of the landscape failed, first at "
            f"({a0[at[0]]:.4g}, {a1[at[1]]:.4g}): {first}; give --range0/--range1 nearer "
            "the coefficients of the record's law"
        )
    ref_info.update(regime=land.reference["regime"], start=land.reference["start"])
    if ref is None:
        ref_info["impacts"] = land.reference["impacts"]
    with OutputDir(args.out) as out:
        land.record_run(
            {
                "command": "landscape",
                "scenario": sc.as_dict(),
                "law": law.to_text(),
                "sensor_lag": tau,
            },
            {
                "reference": ref_info,
                "grid": [n0, n1],
                "ranges": {"alpha1": list(r0), "alpha2": list(r1), "from": origin},
                **provenance_of(args),
            },
        )
        summary = land.to_dict()
        out.write_json("summary.json", summary)
        out.path("landscape.csv").write_text(_grid_csv(land))
        truth = None
        if ref is None and sc.law.names[:2] == law.names[:2]:
            truth = tuple(sc.law.coefficients[:2])
        src = land.reference.get("source") if isinstance(land.reference, dict) else None
        if isinstance(src, str) and "$" in src:  # a file name is text, never mathtext
            land.reference["source"] = src.replace("$", r"\$")
        stem = str(out.path("landscape"))
        drawer.draw(stem, "landscape_figure", land, stem, truth=truth)
    src = "the scenario's law" if ref is None else f"{args.data}"
    count, first, at = land.failures
    minima = summary["minima"]
    print(
        f"landscape {n0}x{n1} of {law.names[0]} in [{r0[0]:.4g}, {r0[1]:.4g}] x "
        f"{law.names[1]} in [{r1[0]:.4g}, {r1[1]:.4g}] against {src} "
        f"({land.reference['regime']}): {land.seconds:.1f} s on {land.workers} processes"
    )
    print(f"  regimes {land.regime_counts()}; consistent at {int(land.consistent.sum())} point(s)")
    if count:
        print(
            f"  {count} simulation(s) failed, first at ({a0[at[0]]:.4g}, {a1[at[1]]:.4g}): {first}"
        )
    exact = land.reference["exact"]
    # the force's criteria, then the motion's (I5) when the record has positions
    for n in [k for k in (*CRITERIA, *MOTION_DEFINITIONS) if k in minima]:
        m = minima[n]
        if m is None:
            print(f"  {n}: no point with a periodic steady state with contact")
            continue
        fl = (land.noise_floor or {}).get(n)
        beside = "" if exact or fl is None else f" (noise floor {fl:.3g})"
        print(f"  {n}: minimum {m['value']:.3g}{beside} at ({m['alpha1']:.4g}, {m['alpha2']:.4g})")
    if not exact:
        print(f"  noise floor under {land.floor_under}")
    print(outputs_line(args, ["summary.json", "landscape.csv", "landscape.png", "landscape.pdf"]))
    return 0


def register(sub):
    s = sub.add_parser(
        "landscape",
        help="criteria I0..I5 over a grid of the first two coefficients (paper Figs. 4-5)",
    )
    _options.add_scenario_option(s)
    s.add_argument(
        "--law", help="template law whose first two coefficients vary (default: the scenario's law)"
    )
    s.add_argument(
        "--data",
        help="CSV record (t, F [, w1, v1, w2, v2]) to compare with "
        "(default: the exact impulse of the scenario's law)",
    )
    add_record_options(s).needs = "--data"
    s.add_argument(
        "--grid", default="41x41", help="points per axis, e.g. 41x41 (default: %(default)s)"
    )
    s.add_argument(
        "--range0",
        help="LOW:HIGH of the first coefficient (default: 0.5x..1.5x the template's coefficient)",
    )
    s.add_argument(
        "--range1",
        help="LOW:HIGH of the second coefficient (default: 0.5x..1.5x the template's coefficient)",
    )
    _options.add_time_offset_option(s, needs="--data", help_prefix="with --data: ")
    _options.add_n_boot_option(s, help_prefix="with --data: ", needs="--data")
    _options.add_seed_option(s, "with --data: seed of the bootstrap", needs="--data")
    _options.add_sensor_lag_option(s).needs = "--data"
    s.add_argument(
        "--no-continuation",
        action="store_true",
        help="search every point's steady state from the start state (by default "
        "each point starts from its neighbour's orbit along the row, several "
        "times faster; the search from the start state when that fails)",
    )
    _options.add_parallel_options(s)
    _options.add_out_option(s)
    s.set_defaults(func=run)
