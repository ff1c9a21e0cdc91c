"""The one evaluation of a law against a reference: simulate, align, score, decide.

Used by ``verify``, ``discover`` (every shortlisted model), ``identify`` (every
objective evaluation) and ``landscape`` (every grid point), so all of them compare
in the same way:

1. the law is simulated to its periodic steady state, from the machine's measured
   state when the record carries it (the attractor the machine is on), else from the
   scenario's initial state;
2. a failed simulation is a failure with its message (``status="failed"``), never
   the physical regime "nonperiodic";
3. the simulated orbit is aligned with the measured cycle: every impact of the orbit
   is tried as ``t*`` (the cyclic sequence of impacts is matched) and the one whose
   whole-orbit force history is closest (L2) to the measured cycle is kept;
4. the simulated force is sampled like the measurement and scored by I0..I4 over the
   whole orbit;
5. **consistency rule**: the model is consistent with the record when the regimes
   agree (same period and the same number of contacts per orbit) and, for each of
   the :data:`~.consistency.CONSISTENCY_CRITERIA` (I2: the force history; I4: the contact
   support, i.e. when contact starts and ends),
   ``I <= max(f x floor, floor + 3 sd) + CONSISTENCY_SLACK`` with ``f`` the
   criterion's :data:`CONSISTENCY_FACTORS` (2 for the force, 1.25 for the penetration).  I2 alone
   lets a law with the right impulse but the wrong contact duration pass at high
   force noise (a pure damper ``c zd`` against a spring-damper record: I2 within
   its floor, I4 = 0.30 against a floor of 0.012).
"""

from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np

from ..._api._printing import readable
from ..._api._result import Result
from ...errors import InputError, IntegrationError
from ...numerics import counts
from ...numerics.memo import Memo, value_key
from ..dynamics.law_response import impulse_from_steady_state
from ..dynamics.simulation import simulate
from ..dynamics.steady_states import steady_state
from .consistency import (
    CONSISTENCY_FACTORS,
    CONSISTENCY_SLACK,
    CONSISTENCY_SPREAD,
    consistency_limits,
)
from .criteria import compare, criteria_lines, evaluate_criteria
from .motion import MOTION_CRITERION
from .notes import contacts_note, transient_notes
from .span_evaluation import BlockJob, force_criteria, span_run, wants_motion

__all__ = ["Evaluation", "evaluate"]


class Status(StrEnum):
    """How an evaluation ended: ``"ok"`` (scored), ``"nonperiodic"`` (no stable periodic orbit:
    physical), ``"no-contact"`` (the bodies never touch) or ``"failed"`` (the simulation
    failed).  Compares equal to its text."""

    OK = "ok"
    NONPERIODIC = "nonperiodic"
    NO_CONTACT = "no-contact"
    FAILED = "failed"


@readable
@dataclass(frozen=True, eq=False)
class Evaluation(Result):
    """A law scored against a reference.

    Attributes
    ----------
    status : Status
    regime : dict
        ``{"measured": "P1", "simulated": "P1" or None}``.
    impacts : dict
        Contacts per orbit, ``{"measured": k, "simulated": k or None}``.
    criteria : dict
        ``I0..I4`` (and I5 with positions; empty unless ``status`` is ``"ok"``).
    noise_floor : dict
        The reference's floor of every criterion (mean over replicates).
    consistent : bool
    verdict : str
        One sentence.
    steady : SteadyState or None
    simulated : Impulse or None
        The aligned simulated impulse sampled like the measurement.
    message : str
    limits : dict
        ``{criterion: limit}`` of the consistency rule (from the floor's mean and spread;
        from the mean alone when not given).
    noise_floor_q95 : dict
        The floor's 95th percentile of every criterion.
    only_i4 : bool
        Inconsistent by the contact support (I4) alone (:func:`_only_i4`).
    aligned : Impulse or None
        The exact simulated orbit rotated onto the measured cycle (a steady-orbit comparison).
    comparison : str
        ``"steady orbit"`` or ``"record span"`` (block by block over the record).
    blocks : list or None
        ``[(measured, simulated)]`` impulses of each block of a record-span comparison.
    penetration : list or None
        The simulated penetration at each block's samples (a record-span comparison with
        positions).
    histories : list or None
        The simulated force at each block's samples, unfolded (a record-span comparison;
        not in the saved document).
    span : dict or None
        The record span compared: start time, cycles, blocks, the state fit, I2 per block.
    transient_i2 : float or None
        I2 between the law's trajectory over the record's span and its steady orbit (above
        :data:`TRANSIENT_GAP` the record is still in a transient under that law).
    impacts_folded : dict or None
        Contacts of the folded cycles, measured and simulated.
    notes : tuple of str
        What the verdict adds (contacts that agree within the noise, a transient).
    """

    status: Status
    regime: dict
    impacts: dict
    criteria: dict
    noise_floor: dict
    consistent: bool
    verdict: str
    steady: object = None
    simulated: object = None
    message: str = ""
    limits: dict = None
    noise_floor_q95: dict = field(default_factory=dict)
    only_i4: bool = False
    aligned: object = None
    comparison: str = "steady orbit"
    blocks: list = None
    penetration: list = None
    histories: list = None
    span: dict = None
    transient_i2: float = None
    impacts_folded: dict = None
    notes: tuple = ()

    KIND = "evaluation"
    _LOAD = {
        "status": lambda d: Status(d["status"]),
        "limits": lambda d: d.get("limits") or {},
        "notes": lambda d: tuple(d.get("notes", ())),
    }

    def __post_init__(self):
        object.__setattr__(self, "status", Status(self.status))
        if self.limits is None:
            lim = consistency_limits(self.noise_floor) if self.noise_floor else {}
            object.__setattr__(self, "limits", lim)
        object.__setattr__(self, "notes", tuple(self.notes))

    def value(self, name):
        """Criterion ``name``, ``inf`` when there is none (for ranking and optimisers)."""
        return self.criteria.get(name, float("inf"))

    @property
    def same_regime(self):
        """Scored, in the measured regime with the measured contacts per orbit."""
        return bool(
            self.status == Status.OK
            and self.regime["simulated"] == self.regime["measured"]
            and self.impacts["simulated"] == self.impacts["measured"]
        )

    def within(self, criterion, *, absent=False):
        """Whether ``criterion`` is within its consistency limit (``absent`` when the
        evaluation has no limit for it, e.g. I5 on a record without positions)."""
        if criterion not in self.limits:
            return absent
        return bool(self.criteria.get(criterion, np.inf) <= self.limits[criterion])

    def failing(self):
        """The criteria beyond their consistency limit."""
        return [k for k in self.limits if self.criteria.get(k, 0.0) > self.limits[k]]

    def as_dict(self):
        ss = self.steady
        return {
            "status": str(self.status),
            "regime": self.regime,
            "impacts": self.impacts,
            "criteria": self.criteria,
            "noise_floor": self.noise_floor,
            "limits": self.limits,
            "consistent": self.consistent,
            "verdict": self.verdict,
            "message": self.message,
            "comparison": self.comparison,
            "notes": list(self.notes),
            "transient_i2": self.transient_i2,
            "max_multiplier": None
            if ss is None or not ss.periodic
            else float(np.max(np.abs(ss.multipliers))),
        }

    def _lines(self):
        out = [f"{self.status}: {self.verdict or self.message}"]
        out += criteria_lines(self.criteria, self.noise_floor, self.limits)
        return out


def align(measured, exact):
    """The rotation of ``exact`` (one of its impacts at ``t* = 0``) whose force history,
    sampled like ``measured``, is closest to the measured one (L2).

    Returns
    -------
    rotated : Impulse
        ``exact`` with the matched impact at ``t* = 0`` (exact, not sampled).
    sampled : Impulse
        ``rotated`` sampled like ``measured``.
    """
    best, best_d = None, np.inf
    for o in exact.onsets:
        rot = exact.rotated(o)
        cand = rot.resampled_like(measured)
        c = compare(measured, cand)
        r = c.fn - c.fe
        d = float(np.sum(np.diff(c.t) * (r[1:] ** 2 + r[:-1] ** 2)))
        if d < best_d:
            best, best_d = (rot, cand), d
    return best


def _failed(reg, imp, exc):
    """The evaluation of a law whose simulation failed: inconsistent (the law cannot
    reproduce the record), with the failure's message and no criteria."""
    return Evaluation(
        "failed",
        reg,
        imp,
        {},
        {},
        False,
        f"inconsistent: the law's simulation failed: {exc}",
        message=str(exc),
    )


def _only_i4(same, consistent, crit, lim):
    """Inconsistent by the contact support (I4) alone: the regime and contacts agree and
    the force history (I2) is within its limit."""
    return bool(
        same
        and not consistent
        and np.isfinite(lim["I4"])
        and crit["I2"] <= lim["I2"]
        and crit["I4"] > lim["I4"]
    )


def _verdict(consistent, reg, imp, crit, floor, *, lim=None, transient=False):
    """One sentence; with ``transient`` (a record span the law's trajectory has not settled
    over) a regime difference is no mismatch and the law is judged over the span."""
    if not crit:
        return None
    if (reg["simulated"] != reg["measured"] and not transient) or imp["simulated"] != imp[
        "measured"
    ]:
        return (
            f"inconsistent: regime mismatch (measured {reg['measured']} with "
            f"{imp['measured']} contact(s), simulated {reg['simulated']} with "
            f"{imp['simulated']})"
        )
    lim = consistency_limits(floor) if lim is None else lim
    if not all(np.isfinite(v) for v in lim.values()):
        if np.isfinite(floor.get("I2", np.inf)):
            return (
                f"inconsistent: undecided: the noise floor under this law (I2 "
                f"{floor['I2']:.3g}) would pass a law without force (I2 = 1), so this "
                "record cannot test it"
            )
        return (
            "inconsistent: the noise floor under this law could not be estimated (no "
            "bootstrap replicate of its force history found the contacts)"
        )
    factors = ", ".join(f"{CONSISTENCY_FACTORS[k]:g} for {k}" for k in lim)
    rule = (
        f"max(f x noise floor, floor + {CONSISTENCY_SPREAD:g} sd) + {CONSISTENCY_SLACK:g}, "
        f"f = {factors}"
    )
    if consistent:
        within = ", ".join(f"{k} = {crit[k]:.3g} <= {lim[k]:.3g}" for k in lim)
        where = "over the record's span" if transient else f"same regime {reg['measured']}"
        return f"consistent: {within} ({rule}), {where}"
    over = ", ".join(f"{k} = {crit[k]:.3g} exceeds {lim[k]:.3g}" for k in lim if crit[k] > lim[k])
    if [k for k in lim if crit[k] > lim[k]] == ["I4"]:
        return (
            f"inconsistent by I4 alone: {over} ({rule}), while I2 = {crit['I2']:.3g} is "
            f"within {lim['I2']:.3g}; I4 compares the contact supports, which are "
            "noise-sensitive on flat force tails and short contacts: check the contact "
            "ends in the figure before rejecting the law"
        )
    return f"inconsistent: {over} ({rule})"


MEMO = Memo(32)
"""Steady states and their force histories (:mod:`discovery.numerics.memo`): a model is
verified again at the start of the next iteration of ``explain``, an optimiser's last point
with its noise floor."""


def _from_start(scenario, reference, steady_kwargs):
    """``steady_kwargs`` with the search started from the record's measured state (what the
    caller gave overriding it)."""
    return {
        "y_start": scenario.model_state(reference.start),
        "t_start": reference.start_time,
        **steady_kwargs,
    }


def _steady(scenario, law, tolerances, steady_kwargs):
    # a continuation's guess is keyed by the orbit it starts from
    g = steady_kwargs.get("guess")
    keyed = (
        {**steady_kwargs, "guess": (g.y0, g.n_periods, g.t0)} if g is not None else steady_kwargs
    )
    return MEMO.get(
        value_key("steady", scenario, law, tolerances, keyed),
        lambda: steady_state(scenario, law, tolerances=tolerances, **steady_kwargs),
    )


def _motion_not_checked(reference, from_state):
    """Why a record's verdict has no I5: the record was compared with the law's steady
    orbit, which has no penetration to compare, and why it was (the record has no
    positions, no usable free flight, or the caller asked for the steady orbit)."""
    why = getattr(reference, "no_span", "")
    if not why and reference.noise.get("zeta") is None:
        why = "the record has no positions"
    if not why and getattr(reference, "span", None) is not None and not from_state:
        why = "the steady orbit was asked for"
    if why == "the record has no positions":
        return f"{MOTION_CRITERION} (the penetration) not checked: {why}"
    return (
        f"{MOTION_CRITERION} (the penetration) not checked: the record was compared with "
        "the law's steady orbit, where the penetration is not compared"
        + (f" ({why})" if why else "")
    )


def evaluate(
    scenario,
    law,
    reference,
    *,
    tolerances=None,
    from_state=True,
    floor=True,
    observe=None,
    objective=None,
    **steady_kwargs,
):
    """Simulate ``law`` and score it against ``reference`` (see the module docstring).

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
    reference : Reference
    tolerances : Tolerances, optional
    from_state : bool
        Start from the reference's measured state when it has one (default), else from
        the scenario's initial state.
    floor : bool
        Compute the noise floor under the hypothesis that ``law`` is true (a parametric
        bootstrap, ~0.1 s) and decide consistency.  Optimisers that only need the
        criteria pass ``False`` (then ``noise_floor`` is empty and ``consistent`` False).
    observe : callable, optional
        An observation model ``Impulse -> Impulse`` applied to the exact simulated force
        history before it is aligned and sampled (e.g. the force sensor's own dynamics,
        :func:`~discovery.vibroimpact.verify.sensors.observation`).
    objective : sequence of str, optional
        An optimiser's evaluation: the criteria it reads (``()``: none, the residual reads
        the histories; I5 only when named), only those computed without a floor (the
        others, the contact supports of I0 and I4 and the penetration's I5 most, were
        about 40 % of an evaluation's time); and for a record span the simulated sample
        whose interval holds a contact onset is the force averaged over that interval (see
        :func:`~discovery.vibroimpact.verify.trajectory.simulated_history`), so the criteria
        are continuous in the law's coefficients.  The default (None) is the verdict's:
        every criterion, point samples compared with the record's point samples.
    **steady_kwargs
        Passed to :func:`~discovery.vibroimpact.dynamics.steady_states.steady_state`.

    Returns
    -------
    Evaluation
    """
    counts.count("evaluations")
    names = None if floor or objective is None else tuple(objective)
    if from_state and getattr(reference, "span", None) is not None:
        job = BlockJob(
            scenario,
            law,
            tolerances,
            observe,
            objective is not None,
            reference.impulse.onset,
            names,
        )
        return _evaluate_span(job, reference, floor=floor, steady_kwargs=steady_kwargs)
    reg = {"measured": reference.regime, "simulated": None}
    imp = {"measured": reference.impacts, "simulated": None}
    if from_state and reference.start is not None:
        steady_kwargs = _from_start(scenario, reference, steady_kwargs)
    try:
        ss = _steady(scenario, law, tolerances, steady_kwargs)
        if not ss.periodic:
            return Evaluation(
                "nonperiodic",
                reg,
                imp,
                {},
                {},
                False,
                "inconsistent: the law has no stable periodic steady state "
                f"(measured {reg['measured']})",
                steady=ss,
            )
        reg["simulated"] = ss.regime
        exact = MEMO.get(
            value_key("impulse", scenario, law, tolerances, steady_kwargs),
            lambda: impulse_from_steady_state(scenario, law, ss, tolerances=tolerances),
        )
    except IntegrationError as exc:
        return _failed(reg, imp, exc)
    if exact is not None and observe is not None:
        exact = observe(exact)
    if exact is None:
        imp["simulated"] = 0
        return Evaluation(
            "no-contact",
            reg,
            imp,
            {},
            {},
            False,
            "inconsistent: the simulated bodies never come into contact",
            steady=ss,
        )
    rot, sim = align(reference.impulse, exact)
    # contacts per simulated orbit, seen through the measurement's threshold rules
    imp["simulated"] = int(round(len(sim.support) * ss.n_periods / sim.n_periods))
    crit = evaluate_criteria(reference.impulse, sim, force_criteria(names))
    if not floor:
        return Evaluation(
            "ok", reg, imp, crit, {}, False, "", steady=ss, simulated=sim, aligned=rot
        )
    fl = reference.floor_for(rot)
    same = reg["simulated"] == reg["measured"] and imp["simulated"] == imp["measured"]
    lim = consistency_limits(fl["mean"], fl.get("sd"))
    # an undefined floor (no bootstrap replicate found the contacts) decides nothing
    consistent = bool(same and all(np.isfinite(lim[k]) and crit[k] <= lim[k] for k in lim))
    only_i4 = _only_i4(same, consistent, crit, lim)
    verdict = _verdict(consistent, reg, imp, crit, fl["mean"], lim=lim)
    if verdict is not None and reference.noise:  # a record, not an exact reference
        verdict += "; " + _motion_not_checked(reference, from_state)
    return Evaluation(
        "ok",
        reg,
        imp,
        crit,
        fl["mean"],
        consistent,
        verdict,
        steady=ss,
        simulated=sim,
        aligned=rot,
        noise_floor_q95=fl["q95"],
        only_i4=only_i4,
        limits=lim,
    )


def _own_contacts(ss, n_periods):
    """Contact onsets per ``n_periods`` drive periods (the record's folded cycle) of the
    law's own periodic motion ``ss`` (its steady orbit from the record's state), or None
    when it has none or its period does not divide into the cycle's evenly."""
    if ss is None or not ss.periodic or (ss.impacts * n_periods) % ss.n_periods:
        return None
    return int(ss.impacts * n_periods // ss.n_periods)


TRANSIENT_GAP = CONSISTENCY_SLACK
"""I2 between the law's trajectory over the record's span and its steady orbit sampled at
the same times above which the record is taken to be still in a transient under that law."""


def _orbit_history(scenario, law, ss, block, tolerances):
    """The steady orbit's force at a block's sample times (the orbit is periodic in
    ``n T`` from ``ss.t0``)."""
    W = ss.n_periods * scenario.period
    fold = block.fold
    t0 = ss.t0 + np.floor((block.state.t - ss.t0) / W) * W
    tr = simulate(
        scenario,
        law,
        (t0, fold.end),
        y0=ss.y0,
        t_eval=fold.td,
        tolerances=tolerances,
        zeta_max0=ss.zeta_max0,
        impact_v0=ss.impact_v0,
    )
    return np.asarray(tr.force, dtype=float)


def _orbit_gap(orbit, sim):
    """I2 between the law's trajectory over the last block (``sim``) and its steady orbit
    there (``orbit``); when the orbit has no contact force there (I2 is undefined), 0 if the
    trajectory has none either, else ``inf``."""
    c = compare(orbit, sim)
    if not np.any(c.fe > 0):
        return 0.0 if not np.any(c.fn > 0) else float("inf")
    return evaluate_criteria(orbit, sim, ["I2"])["I2"]


def _span_steady_state(scenario, law, reference, sim, reg, *, tolerances, steady_kwargs):
    """The law's steady state from the record's state (only to report its regime, set in
    ``reg``) and ``transient``: I2 between the law's trajectory over the last block of
    ``reference.span`` (``sim``, its folded cycle) and its steady orbit (``None`` without a
    periodic orbit).  Returns ``(steady state or None, transient, why)``, ``why`` saying
    why the law's steady orbit is unknown (empty when it is known); the regime is then
    ``"unknown"``: the span was compared, only the orbit that reports the regime is
    missing."""
    span = reference.span
    last = span.blocks[-1]
    if scenario.mass_loss > 0:
        reg["simulated"] = "drifting"
        return (
            None,
            None,
            (
                f"the machine sheds {scenario.mass_loss:g} of the moulding's mass per impact, "
                "so the law has no steady orbit"
            ),
        )
    steady_kwargs = _from_start(scenario, reference, steady_kwargs)
    try:
        ss = _steady(scenario, law, tolerances, steady_kwargs)
    except (IntegrationError, InputError) as exc:
        reg["simulated"] = "unknown"
        return None, None, f"the search for its steady orbit failed ({exc})"
    if not ss.periodic:
        reg["simulated"] = "nonperiodic"
        return ss, None, ""
    reg["simulated"] = ss.regime
    try:
        orbit = last.fold.impulse(
            _orbit_history(scenario, law, ss, last, tolerances),
            threshold=last.threshold,
            noise=span.sigma_f,
        )
    except (IntegrationError, InputError) as exc:
        return ss, None, f"its steady orbit could not be followed over the record's span ({exc})"
    return ss, _orbit_gap(orbit, sim), ""


def _evaluate_span(job, reference, *, floor, steady_kwargs):
    """:func:`evaluate` for a record with positions (what each block is asked: ``job``, a
    :class:`~.span_evaluation.BlockJob`): the law simulated from the machine's states
    across the record's span, block by block, both histories folded by the same operator
    (:mod:`~discovery.vibroimpact.verify.trajectory`); the criteria are the blocks' mean
    (weighted by cycles); the steady state is found only to report the law's regime and to
    tell a transient from a regime mismatch."""
    scenario, law, tolerances, observe = job.scenario, job.law, job.tolerances, job.observe
    span = reference.span
    E = reference.impulse
    reg = {"measured": reference.regime, "simulated": None}
    imp = {"measured": reference.impacts, "simulated": None}
    try:
        # every block run, folded and compared (shared out over a block farm when one holds
        # the span: :mod:`~discovery.vibroimpact.verify.block_farm`)
        blocks = span_run(job, reference)
    except IntegrationError as exc:
        return _failed(reg, imp, exc)
    hist, z_sim = blocks.histories, blocks.penetrations
    if not any(np.any(h > 0) for h in hist):
        imp["simulated"] = 0
        return Evaluation(
            "no-contact",
            reg,
            imp,
            {},
            {},
            False,
            "inconsistent: the simulated bodies never come into contact over the record's span",
        )
    sims = blocks.impulses()
    sim = sims[-1]
    imp["simulated"] = int(len(sim.support))
    crit, per_block = blocks.criteria(span)
    if span.sigma_z > 0 and wants_motion(job.criteria):
        crit[MOTION_CRITERION], _ = blocks.penetration(span)
    last = span.blocks[-1]
    found = {
        "comparison": "record span",
        "penetration": z_sim,
        "histories": hist,
        "blocks": list(zip(reference.blocks, sims, strict=True)),
        "span": {
            "start_time": span.state.t,
            "cycles": span.n_cycles,
            "blocks": len(span.blocks),
            "state": last.state.method,
            "state_samples": last.state.n_samples,
            "block_I2": [p.get("I2") for p in per_block],
        },
    }
    if not floor:
        return Evaluation("ok", reg, imp, crit, {}, False, "", simulated=sim, **found)
    ss, transient, why = _span_steady_state(
        scenario, law, reference, sim, reg, tolerances=tolerances, steady_kwargs=steady_kwargs
    )
    found["transient_i2"] = transient
    settled = transient is not None and transient <= TRANSIENT_GAP
    fl = reference.floor_for(
        sims, scenario=scenario, law=law, tolerances=tolerances, observe=observe
    )
    lim = consistency_limits(fl["mean"], fl.get("sd"))
    # contacts per cycle agree, or the law's own noisy replicates show the measured count
    # (noise near the threshold can split a contact or hide a small one)
    folded = int(len(E.support))  # the record's folded cycle, same operator as the law's
    own = _own_contacts(ss, E.n_periods)
    same_impacts = (
        imp["simulated"] in (imp["measured"], folded)
        or folded in (fl.get("impacts") or [])
        or own == imp["measured"]
    )
    regime_ok = reg["simulated"] == reg["measured"] or not settled
    within = all(np.isfinite(lim[k]) and crit[k] <= lim[k] for k in lim)
    consistent = bool(same_impacts and regime_ok and within)
    # a regime "mismatch" while the law's own trajectory over the span has not settled is a
    # transient, judged by the block-by-block comparison alone
    transient_mismatch = not settled and reg["simulated"] != reg["measured"]
    found["impacts_folded"] = {"measured": folded, "simulated": imp["simulated"]}
    notes = []
    if same_impacts and imp["simulated"] != imp["measured"]:
        notes.append(contacts_note(imp["simulated"], imp["measured"], folded, own))
        imp = {**imp, "simulated": imp["measured"]}
    elif not same_impacts and own is not None:
        imp = {**imp, "simulated": own}  # the count a rejection states: the law's motion's
    verdict = _verdict(
        consistent, reg, imp, crit, fl["mean"], lim=lim, transient=transient_mismatch
    )
    notes += transient_notes(transient_mismatch, settled, transient, reg, ss, why=why)
    if notes and verdict is not None:
        verdict = f"{verdict}; " + "; ".join(notes)
    found.update(
        noise_floor_q95=fl["q95"],
        notes=notes,
        limits=lim,
        only_i4=_only_i4(same_impacts and regime_ok, consistent, crit, lim),
    )
    return Evaluation(
        "ok", reg, imp, crit, fl["mean"], consistent, verdict, steady=ss, simulated=sim, **found
    )
