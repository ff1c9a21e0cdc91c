"""``vidi steady``: the periodic steady state of a law."""

from pathlib import Path

import numpy as np

from .._files._io import OutputDir
from ..errors import InputError, IntegrationError
from ..vibroimpact.model.scenario import load_scenario
from . import _options
from ._common import check_out, law_or_default, provenance_of


def run(args):
    from ..vibroimpact.dynamics.law_response import response
    from ..vibroimpact.dynamics.steady_states import SteadyStateSettings

    if args.out is not None:
        check_out(args)
    sc = load_scenario(args.scenario)
    law = law_or_default(args.law, sc)
    if args.sensitivities and law.permanent_set > 0:
        raise InputError(
            "--sensitivities is not available for a law with a permanent set ('set:' in "
            "--law): its unloading memory is a state the sensitivities do not carry"
        )
    r = response(sc, law)
    ss = r.steady
    if not ss.periodic and _runs_away(ss):
        d = ss.evidence["attempts"][-1]["recurrence"][1]
        raise IntegrationError(
            f"the steady state of {law} in scenario {sc.name!r} could not be computed: the "
            f"motion runs away (its strobe points move {d:.3g} of the motion's scale further "
            "every period: the moulding is thrown off and does not come back); check the "
            "scenario's drive amplitude, masses and the law's coefficients"
        )
    if not ss.periodic:
        print(
            f"{law}: no periodic steady state (no stable orbit of up to "
            f"{SteadyStateSettings().max_period} drive periods that the motion from the "
            f"scenario's state reaches, searched after {round(ss.t0 / sc.period)} periods); "
            "the motion is nonperiodic or still in a transient: see it with vidi simulate "
            "--from-rest --periods 400"
        )
    elif not (np.all(np.isfinite(ss.multipliers)) and np.isfinite(ss.residual)):
        raise IntegrationError(
            f"the steady state of {law} in scenario {sc.name!r} could not be computed "
            "(non-finite Floquet multipliers or residual: the simulation failed); check the "
            "scenario's drive amplitude, masses and the law's coefficients"
        )
    info = {}
    if r.impulse is not None:
        info.update(peak_force=r.impulse.peak, contact_time=r.impulse.contact_time)
    if ss.periodic:
        print(
            f"{law}: {ss.regime}, {ss.impacts} impact(s) per orbit, "
            f"max |Floquet multiplier| {np.max(np.abs(ss.multipliers)):.4g}, "
            f"residual {ss.residual:.2g}"
        )
    if r.impulse is not None:
        print(f"peak force {r.impulse.peak:.4g} N, contact time {r.impulse.contact_time:.4g} s")
    if args.sensitivities and ss.periodic:
        from ..vibroimpact.dynamics.orbit_sensitivity import orbit_sensitivity

        sens = orbit_sensitivity(sc, law, ss)
        print(sens)
        info["sensitivities"] = sens.as_dict()
    if args.out:
        ss.record_run(
            {"command": "steady", "law": law.to_text(), "scenario": sc.as_dict()},
            {**info, **provenance_of(args)},
        )
        with OutputDir(args.out) as out:
            ss.write_into(out)
        print(f"wrote {Path(args.out) / 'summary.json'}")
    return 0


def _runs_away(ss):
    """Whether a nonperiodic search's last strobe points move steadily away: the distance
    after ``n`` periods grows as ``n`` (within 20 %) and is beyond the motion's scale."""
    attempts = ss.evidence.get("attempts") or []
    rec = attempts[-1].get("recurrence", {}) if attempts else {}
    if len(rec) < 2 or not rec.get(1, 0.0) > 1.0:
        return False
    n = max(rec)
    return abs(rec[n] / (n * rec[1]) - 1.0) < 0.2


def register(sub):
    s = sub.add_parser(
        "steady", help="periodic steady state of a law: regime, impacts, Floquet multipliers"
    )
    _options.add_scenario_option(s)
    _options.add_law_option(s)
    s.add_argument(
        "--sensitivities",
        action="store_true",
        help="also how each impact's peak force, contact time and largest penetration move "
        "with each coefficient (exact derivatives of the periodic orbit, printed as "
        "elasticities; not for a law with a permanent set)",
    )
    s.add_argument(
        "--out", help="optional output directory for summary.json (default: none, print only)"
    )
    s.set_defaults(func=run)
