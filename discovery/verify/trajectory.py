"""A law judged against what the machine did during the record.

With positions recorded, the simulation starts from the machine's state in the record's
first free flight (:mod:`~discovery.verify.state`) and runs across the record's own span;
its force is sampled at the record's own sample times and both histories are folded onto
the drive's phase by the same :class:`~discovery.verify.fold.Fold`.  A record that has not
yet settled (a slowly decaying alternation near a flip bifurcation, a drift) is then
compared with the law's own transient from the same state, never with a steady orbit it
has not reached; and no per-cycle onset is estimated, so the onset's noise does not
smear the force jump on one side only.

The noise floor goes through exactly the same processing: each replicate is the law's own
simulated record, started from a state drawn from the state fit's covariance, with the
record's force noise added at the record's sample times, folded and compared with the
noise-free fold.
"""

from dataclasses import dataclass

import numpy as np

from ..criteria import CRITERIA, evaluate_criteria
from ..dynamics.simulate import simulate
from ..errors import InputError, IntegrationError
from ..impulse import Impulse, estimate_noise
from .fold import make_fold
from .state import free_flight_runs, free_flight_state

__all__ = ["RecordSpan", "record_span", "simulated_history", "span_floor"]

_MIN_FLIGHT = 0.08  # shortest free flight that gives a state, in drive periods


@dataclass(frozen=True)
class RecordSpan:
    """The part of a record a simulation is compared with, cycle by cycle.

    Attributes
    ----------
    fold : Fold
        The span's samples on one cycle (origin: the record's main onset).
    state : StateEstimate
        The machine's state where the simulation starts (before the span).
    F : ndarray of shape (m,)
        The measured force at the folded samples [N].
    sigma_f : float
        Force noise of one sample [N].
    threshold : float
        Contact threshold of the folded cycle [N].
    """

    fold: object
    state: object
    F: np.ndarray
    sigma_f: float
    threshold: float

    def impulse(self, values, onset_record_time=None):
        """A history at the folded samples as a folded :class:`Impulse`."""
        return self.fold.impulse(values, threshold=self.threshold, noise=self.sigma_f,
                                 onset_record_time=onset_record_time)


def record_span(measurement, scenario, cycle, *, time_offset=0.0):
    """The span of a record with positions: from its first usable free flight to its end.

    Parameters
    ----------
    measurement : Measurement
    scenario : Scenario
    cycle : Impulse
        The record's cycle from :func:`~discovery.impulse.impulse_from_samples` (its
        length in periods and its main onset give the fold).
    time_offset : float

    Returns
    -------
    RecordSpan or None
        ``None`` when the record has no free flight to start from or no whole cycle after
        one.
    """
    ch = measurement.channels
    if "w1" not in ch or "w2" not in ch:
        return None
    t, F = measurement.t, measurement.F
    T = scenario.period
    zeta = ch["w1"] - ch["w2"]
    runs = free_flight_runs(t, F, zeta, T, min_fraction=_MIN_FLIGHT)
    td_all = t + time_offset
    W = cycle.duration
    origin = cycle.onset + time_offset
    for run in runs:
        a, b = run
        t_a = 0.5 * (td_all[a] + td_all[b - 1])
        fold = make_fold(td_all, origin, cycle.n_periods, T, t_a, td_all[-1])
        if fold is None:
            return None
        if fold.n_cycles < max(1, int(0.5 * (td_all[-1] - td_all[0]) / W)):
            return None  # the first flights are too late to use most of the record
        state = free_flight_state(measurement, scenario, run, t_a, time_offset=time_offset)
        sigma = estimate_noise(F)
        Fi = F[fold.idx]
        peak = float(np.max(fold.average(Fi)))
        thr = max(5.0 * sigma / np.sqrt(fold.n_cycles), 1e-3 * peak)
        return RecordSpan(fold=fold, state=state, F=Fi, sigma_f=float(sigma), threshold=thr)
    return None


def simulated_history(scenario, law, span, *, tolerances=None, y0=None, observe=None):
    """The law's force at the span's sample times, simulated from the span's state.

    Parameters
    ----------
    scenario, law
    span : RecordSpan
    tolerances : Tolerances, optional
    y0 : ndarray of shape (4,), optional
        Another start state (a bootstrap draw); default the measured one.
    observe : callable, optional
        Observation model ``Impulse -> Impulse`` applied to the simulated history (the span
        taken as one periodic signal).

    Returns
    -------
    ndarray of shape (m,)
        Raises :class:`~discovery.errors.IntegrationError` when the simulation fails.
    """
    fold, st = span.fold, span.state
    y0 = st.y if y0 is None else y0
    tr = simulate(scenario, law, (st.t, fold.end), y0=y0, t_eval=fold.td,
                  tolerances=tolerances)
    Fs = np.asarray(tr.force, dtype=float)
    if observe is not None:
        L = fold.end - fold.origin
        tt = np.concatenate([[0.0], fold.td - fold.origin, [L]])
        FF = np.concatenate([[Fs[-1]], Fs, [Fs[-1]]])
        imp = Impulse(t=tt, F=FF, duration=L, support=np.zeros((0, 2)),
                      n_periods=fold.n_periods * fold.n_cycles, onset=fold.origin)
        Fs = observe(imp).evaluate(fold.td - fold.origin)
    return Fs


def span_floor(scenario, law, span, simulated, *, n_boot=16, seed=0, tolerances=None,
               observe=None):
    """Noise floor of every criterion if ``law`` were the truth, through the span's own
    processing.

    Each replicate starts the law from a state drawn from the state fit's covariance,
    adds the record's force noise at the record's sample times, folds, and is compared
    with ``simulated`` (the folded noise-free history from the measured state).

    Returns
    -------
    dict
        ``{"mean": {I0..I4}, "q95": {I0..I4}, "n_boot": n, "seed": seed}``.
    """
    rng = np.random.default_rng(seed)
    st = span.state
    try:
        L = np.linalg.cholesky(st.cov + 1e-30 * np.eye(4))
    except np.linalg.LinAlgError:
        L = np.diag(np.sqrt(np.clip(np.diag(st.cov), 0.0, None)))
    samples = {n: [] for n in CRITERIA}
    base = None
    for _ in range(n_boot):
        y0 = st.y + L @ rng.standard_normal(4)
        noise = rng.normal(0.0, span.sigma_f, span.F.size)
        try:
            Fr = simulated_history(scenario, law, span, tolerances=tolerances, y0=y0,
                                   observe=observe)
        except IntegrationError:  # a failed draw: the measured state's history instead
            if base is None:
                base = simulated_history(scenario, law, span, tolerances=tolerances,
                                         observe=observe)
            Fr = base
        try:
            rep = span.impulse(Fr + noise)
            crit = evaluate_criteria(rep, simulated)
        except InputError:
            continue
        for n, v in crit.items():
            samples[n].append(v)
    if not samples["I2"]:
        inf = {n: float("inf") for n in CRITERIA}
        return {"mean": inf, "q95": dict(inf), "n_boot": 0, "seed": seed}
    return {"mean": {n: float(np.mean(v)) for n, v in samples.items()},
            "q95": {n: float(np.quantile(v, 0.95)) for n, v in samples.items()},
            "n_boot": len(samples["I2"]), "seed": seed}
