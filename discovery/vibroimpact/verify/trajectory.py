"""A law judged against what the machine did during the record.

With positions recorded, the simulation starts from the machine's state in the record's
first free flight (:mod:`~discovery.vibroimpact.verify.state`) and runs across the record's own
span; its force is sampled at the record's own sample times and both histories are folded onto
the drive's phase by the same :class:`~discovery.vibroimpact.verify.fold.Fold`.  A record that has
not yet settled (a slowly decaying alternation near a flip bifurcation, a drift) is then
compared with the law's own transient from the same state, never with a steady orbit it
has not reached; and no per-cycle onset is estimated, so the onset's noise does not
smear the force jump on one side only.

The noise floor goes through exactly the same processing: each replicate is the law's own
simulated record, started from a state drawn from the state fit's covariance, with the
record's force noise added at the record's sample times, folded and compared with the
noise-free fold.
"""

from dataclasses import dataclass, field

import numpy as np

from ..._api._validate import unchecked
from ...errors import InputError, IntegrationError
from ...numerics.memo import Memo, value_key
from ..data.contact_edges import contact_onsets
from ..data.measurement import Measurement
from ..data.noise import estimate_noise
from ..dynamics.kernel import codes as _K
from ..dynamics.simulation import simulate
from .block_farm import farm_for
from .criteria import evaluate_criteria
from .fold import make_fold
from .observed import observed, observed_derivatives
from .state import free_flight_runs, free_flight_state

__all__ = [
    "Block",
    "RecordSpan",
    "record_span",
    "simulated_history",
    "simulated_motion",
    "history_sensitivities",
    "penetration_sensitivities",
    "block_criteria",
    "BLOCK_CYCLES",
]

_MIN_FLIGHT = 0.08  # shortest free flight that gives a state, in drive periods


SINK_FACTOR = 10.0
"""A simulated penetration beyond this many motion scales (:meth:`Scenario.scales`) is no
contact any more: the law lets the moulding sink into the frame."""

POSITION_RESOLUTION = 1e-4
"""The penetration's noise is taken as at least this share of its range over the record (a
position sensor of about 14 bits): noise-free positions (a synthetic record) would weigh the
penetration without bound against the force."""

BLOCK_CYCLES = 4
"""Cycles per block: a long record (a run-up, a drift) is compared block by block, each
block folded on its own and simulated from the machine's state just before it."""


def _flight_samples(measurement, run):
    """The samples of one free flight ``run`` (a sample range) as a record of its own."""
    a, b = run
    return Measurement(
        t=measurement.t[a:b],
        F=measurement.F[a:b],
        channels={k: np.asarray(v)[a:b] for k, v in measurement.channels.items()},
    )


def _frame_key(scenario):
    """What the frame's free motion in a flight depends on."""
    sc = scenario
    return (sc.m1, sc.c1, sc.k1, sc.k3, sc.A, sc.frequency, sc.g)


@dataclass(frozen=True)
class Flight:
    """The free flight a block's state is estimated from: its samples (a
    :class:`~discovery.vibroimpact.data.measurement.Measurement` of the flight alone), the
    state's drive-clock time, the record's time offset and the machine (:func:`_frame_key`)
    the block's :attr:`Block.state` was estimated with."""

    samples: object
    t_a: float
    time_offset: float
    machine: tuple


@dataclass(frozen=True)
class Block:
    """Consecutive cycles of a record, folded together, with the state before them.

    Attributes
    ----------
    fold : Fold
    state : StateEstimate
        The machine's state in the free flight just before the block (the simulation of
        the block starts there).
    F : ndarray of shape (m,)
        The measured force at the folded samples [N].
    threshold : float
        Contact threshold of the folded cycle [N].
    Z : ndarray of shape (m,)
        The recorded penetration ``w1 - w2`` at the folded samples [m].
    impacts_before : int
        The record's contacts before :attr:`state` (a machine that sheds mass at each
        impact starts the block lighter: :meth:`machine`).
    """

    fold: object
    state: object
    F: np.ndarray
    threshold: float
    Z: np.ndarray
    impacts_before: int = 0
    flight: object = None
    states: dict = field(default_factory=dict, compare=False, repr=False)

    def state_for(self, scenario):
        """The state before the block as a simulation on ``scenario`` starts from it: the
        frame's free motion in the flight is fitted with the machine's own equations, so a
        machine changed since the record's states were estimated (a stiffening of the
        supports, a calibrated scale) re-estimates them from the same flight samples
        (:attr:`flight`; the state of ``scenario``'s machine is kept)."""
        if self.flight is None:
            return self.state
        key = _frame_key(scenario)
        if key == self.flight.machine:
            return self.state
        if key not in self.states:
            f = self.flight
            self.states[key] = free_flight_state(
                f.samples, scenario, (0, f.samples.t.size), f.t_a, time_offset=f.time_offset
            )
        return self.states[key]

    def machine(self, scenario):
        """``scenario`` as it is when the block starts: with a mass loss per impact, the
        moulding's mass after the record's impacts before it,
        ``m2 (1 - loss)^impacts_before`` (the drift channel's mass)."""
        if not (scenario.mass_loss and self.impacts_before):
            return scenario
        return scenario.replace(m2=scenario.mass_after(self.impacts_before))


@dataclass(frozen=True)
class RecordSpan:
    """The part of a record a simulation is compared with, block by block.

    Attributes
    ----------
    blocks : tuple of Block
        In time order; the last one ends with the record.
    sigma_f : float
        Force noise of one sample [N].
    sigma_z : float
        Penetration noise of one sample [m] (both position channels').
    """

    blocks: tuple
    sigma_f: float
    sigma_z: float = 0.0

    @property
    def state(self):
        """The state where the first block's simulation starts."""
        return self.blocks[0].state

    @property
    def fold(self):
        """The last block's fold (the record's latest cycles)."""
        return self.blocks[-1].fold

    @property
    def n_cycles(self):
        return int(sum(b.fold.n_cycles for b in self.blocks))

    @property
    def size(self):
        return int(sum(b.F.size for b in self.blocks))

    def impulses(self, histories, onset_record_time=None):
        """Each block's history (a list of arrays, one per block) as its folded
        :class:`~discovery.vibroimpact.data.impulse.Impulse`."""
        return [
            b.fold.impulse(
                h, threshold=b.threshold, noise=self.sigma_f, onset_record_time=onset_record_time
            )
            for b, h in zip(self.blocks, histories, strict=True)
        ]

    def measured(self, onset_record_time=None):
        """The measured folded cycle of every block."""
        return self.impulses([b.F for b in self.blocks], onset_record_time)


def _block_ranges(M, size):
    """``[(first, count), ...]`` of cycles, blocks of ``size`` counted from the end; a first
    block shorter than half a block joins the next."""
    out = []
    hi = M
    while hi > 0:
        lo = max(0, hi - size)
        out.insert(0, (lo, hi - lo))
        hi = lo
    if len(out) > 1 and out[0][1] < size / 2:
        (a, n0), (_, n1) = out[0], out[1]
        out[:2] = [(a, n0 + n1)]
    return out


def record_span(
    measurement, scenario, cycle, *, time_offset=0.0, block_cycles=BLOCK_CYCLES, why=None
):
    """The span of a record with positions: from its first usable free flight to its end.

    Parameters
    ----------
    measurement : Measurement
    scenario : Scenario
    cycle : Impulse
        The record's cycle from :func:`~discovery.vibroimpact.data.impulse.impulse_from_samples`
        (its length in periods and its main onset give the fold).
    time_offset : float
    block_cycles : int
        Cycles per block.
    why : list, optional
        Where the span is ``None``, the reason is appended to it (a clause a verdict can
        state: ``"no free flight ends before its first compared cycle"``).

    Returns
    -------
    RecordSpan or None
        ``None`` when the record has no free flight to start from or no whole cycle after
        one.
    """

    def none(reason):
        if why is not None:
            why.append(reason)
        return None

    ch = measurement.channels
    if "w1" not in ch or "w2" not in ch:
        return none("the record has no positions")
    t, F = measurement.t, measurement.F
    T = scenario.period
    zeta = ch["w1"] - ch["w2"]
    runs = free_flight_runs(t, F, zeta, T, min_fraction=_MIN_FLIGHT)
    if not runs:
        return none("the record has no free flight to start a simulation from")
    td_all = t + time_offset
    W = cycle.duration
    mids = np.array([0.5 * (td_all[a] + td_all[b - 1]) for a, b in runs])
    ends = np.array([td_all[b - 1] for _, b in runs])
    # the compared cycles begin after the first free flight ends: every block then has a
    # flight that ends before it to start from
    whole = make_fold(td_all, cycle.onset + time_offset, cycle.n_periods, T, (ends[0], td_all[-1]))
    if whole is None or whole.n_cycles < max(1, int(0.5 * (td_all[-1] - td_all[0]) / W)):
        # the first flights are too late to use most of the record
        return none("the record's first free flight comes too late to use most of the record")
    sigma = float(estimate_noise(F))
    # the record's contacts (a machine that sheds mass per impact starts each block lighter)
    onsets = contact_onsets(t, F, T, zeta=zeta)
    blocks = []
    for first, count in _block_ranges(whole.n_cycles, max(1, int(block_cycles))):
        o = whole.origin + first * W
        # the latest free flight that ends before the block starts
        ok = np.flatnonzero(ends <= o)
        if not ok.size:
            return none("no free flight of the record ends before its first compared cycle")
        j = int(ok[-1])
        fold = make_fold(
            td_all, o, cycle.n_periods, T, (o, o + count * W + 0.5 * (td_all[1] - td_all[0]))
        )
        state = free_flight_state(measurement, scenario, runs[j], mids[j], time_offset=time_offset)
        flight = Flight(
            _flight_samples(measurement, runs[j]), mids[j], time_offset, _frame_key(scenario)
        )
        # the block's recorded channels, read-only: the fold keeps what it computes of them
        Fi, Zi = F[fold.idx], zeta[fold.idx]
        Fi.setflags(write=False)
        Zi.setflags(write=False)
        peak = float(np.max(fold.average(Fi)))
        thr = max(5.0 * sigma / np.sqrt(fold.n_cycles), 1e-3 * peak)
        blk = Block(
            fold=fold,
            state=state,
            F=Fi,
            threshold=thr,
            Z=Zi,
            impacts_before=int(np.count_nonzero(onsets + time_offset < state.t)),
            flight=flight,
        )
        if not len(fold.impulse(Fi, threshold=thr, noise=sigma).support):
            continue  # no contact in these cycles (a run-up's start): nothing to compare
        blocks.append(blk)
    if not blocks:
        return none("no compared cycle of the record has a contact")
    sigma_z = max(float(estimate_noise(zeta, 3)), POSITION_RESOLUTION * float(np.ptp(zeta)))
    return RecordSpan(blocks=tuple(blocks), sigma_f=sigma, sigma_z=sigma_z)


MEMO = Memo(64)
"""The block simulations from the measured states (:mod:`discovery.numerics.memo`): an
optimiser's last point verified with its noise floor, a model's residual after its
verification, reuse them.  The key holds the block's identity, so the entry keeps the
block alive (its id is not reused while cached)."""


def _simulate_block(scenario, law, blk, y0, tolerances, **kwargs):
    """The law simulated over a block from ``y0`` (default the block's measured state),
    sampled at its sample times."""
    fold, st = blk.fold, blk.state_for(scenario)
    scenario = blk.machine(scenario)
    return unchecked(simulate)(
        scenario,
        law,
        (min(st.t, fold.td[0]), fold.end),
        y0=scenario.model_state(st.y if y0 is None else y0),
        t_eval=fold.td,
        tolerances=tolerances,
        **kwargs,
    )


def _block_run(scenario, law, blk, y0, tolerances):
    """The law's force at a block's sample times, simulated from ``y0`` (default the
    block's measured state), the contact onsets of that run and its penetration at the
    sample times."""
    tr = _simulate_block(scenario, law, blk, y0, tolerances)
    zmax = float(np.max(tr.y[0] - tr.y[2]))
    Z = scenario.recorded_penetration(tr.y[0] - tr.y[2])
    Z.setflags(write=False)
    if zmax > SINK_FACTOR * scenario.scales()[0]:
        raise IntegrationError(
            f"under law '{law}' the moulding sinks into the frame (penetration "
            f"{zmax:.3g} m, over {SINK_FACTOR:g} times the drive's motion scale): the law "
            "is far too soft for the record"
        )
    F = np.asarray(tr.force, dtype=float)
    F.setflags(write=False)
    return F, tr.event_t[tr.event_kind == _K.EV_ONSET], Z


def _sample_edges(td):
    """The edges of the intervals around the sample times ``td`` (midway between samples,
    half a spacing beyond the ends), made once per block's sample times and kept
    (:data:`_EDGES`, :meth:`~discovery.numerics.memo.Memo.of`; every evaluation of every
    block asked for them)."""

    def made():
        mid = 0.5 * (td[1:] + td[:-1])
        edges = np.concatenate([[td[0] - (mid[0] - td[0])], mid, [td[-1] + (td[-1] - mid[-1])]])
        edges.setflags(write=False)
        return edges

    return _EDGES.of(td, made)


_EDGES = Memo(256)
"""The sample intervals' edges of each block's sample times (:func:`_sample_edges`)."""


def _onset_weights(td, onsets):
    """The samples whose interval holds a contact onset, the onset's fraction ``u`` of it,
    and the intervals' lengths (see :func:`simulated_history`)."""
    edges = _sample_edges(td)
    k = np.searchsorted(edges, onsets, "right") - 1
    keep = (k >= 0) & (k < td.size)
    k = k[keep]
    width = edges[k + 1] - edges[k]
    return k, (onsets[keep] - edges[k]) / width, width, keep


def _sensitivity_run(scenario, law, blk, tolerances):
    """A block's run from its measured state with the coefficients' sensitivities (the
    state's steps: the force is the plain run's): ``(F, dF, onsets, d_onsets)``."""
    tr = _simulate_block(
        scenario,
        law,
        blk,
        None,
        tolerances,
        sensitivities="coefficients",
        control_sensitivities=False,
    )
    on = tr.event_kind == _K.EV_ONSET
    return (
        tr.force,
        tr.force_sensitivity,
        tr.event_t[on],
        tr.event_time_sensitivity[on],
        tr.penetration_sensitivity,
    )


def _sensitivity_key(scenario, law, blk, tolerances):
    return value_key("sensitivities", scenario, law, tolerances, id(blk))


def _sensitivities(scenario, law, blk, tolerances, made=None):
    """A block's sensitivity run (memoised: asked by the force's and the penetration's
    rows of one Jacobian); ``made``: that run made elsewhere (a block farm), kept as is."""
    return MEMO.get(
        _sensitivity_key(scenario, law, blk, tolerances),
        lambda: (blk, *(made or _sensitivity_run(scenario, law, blk, tolerances))),
    )[1:]


def sensitivity_outcome(reference, k, scenario, law, tolerances):
    """Block ``k``'s sensitivity run (:func:`_sensitivity_run`), or the exception it
    raised (a block farm's job)."""
    try:
        return _sensitivity_run(scenario, law, reference.span.blocks[k], tolerances)
    except Exception as exc:  # raised where the block is asked for, in block order
        return exc


def _shared_sensitivities(scenario, law, span, tolerances):
    """The span's sensitivity runs made on the block farm that holds it, when one does
    (:func:`~.block_farm.shared_blocks`), and kept in :data:`MEMO` as if made here (a block
    whose run failed is left to be run, and to fail, here)."""
    farm = farm_for(span)
    if farm is None:
        return
    if all(_sensitivity_key(scenario, law, b, tolerances) in MEMO for b in span.blocks):
        return
    outcomes = farm.map(sensitivity_outcome, span, (scenario, law, tolerances)) or []
    for blk, o in zip(span.blocks, outcomes, strict=False):
        if not isinstance(o, Exception):
            _sensitivities(scenario, law, blk, tolerances, made=o)


def penetration_sensitivities(scenario, law, span, *, tolerances=None):
    """The derivatives of the simulated penetration at the span's sample times along the
    law's coefficients (loading, then unloading terms), one array of shape (m, samples)
    per block, from the same runs as :func:`history_sensitivities` (a contact offset only
    shifts the penetration, so it is the model's)."""
    _shared_sensitivities(scenario, law, span, tolerances)
    return [_sensitivities(scenario, law, blk, tolerances)[4] for blk in span.blocks]


def history_sensitivities(scenario, law, span, *, tolerances=None, observe=None):
    """The derivatives of the optimisers' force history (:func:`simulated_history` with
    ``window=True``) along the law's coefficients (loading, then unloading terms), one
    array of shape (m, samples) per block, each from one simulation with the variational
    equations (:func:`~discovery.vibroimpact.dynamics.simulate`'s ``sensitivities``); the
    onset blend's weight moves with the onset's own time derivative.  An observation model
    must be linear in the force (``observe.linear``, e.g. a sensor's lag): it is applied to
    each derivative.  Raises :class:`~discovery.errors.InputError` for a law with a
    permanent set or a nonlinear observation and
    :class:`~discovery.errors.IntegrationError` when a run fails."""
    if observe is not None and not getattr(observe, "linear", False):
        raise InputError("the observation model is not linear in the force")
    _shared_sensitivities(scenario, law, span, tolerances)
    out = []
    for blk in span.blocks:
        td = blk.fold.td
        F, dF, onsets, d_on, _ = _sensitivities(scenario, law, blk, tolerances)
        if observe is not None:
            # no onset blend through an observation model (:func:`_history`)
            out.append(observed_derivatives(blk, (F, dF, onsets, d_on), observe))
            continue
        dH = dF.copy()
        if td.size > 1 and onsets.size:
            k, u, width, keep = _onset_weights(td, onsets)
            d_on = d_on[keep]
            for i, kk in enumerate(k):
                # blended value blk.F + |2u - 1| (F - blk.F): the weight's own derivative
                # moves with the onset time
                w = abs(2.0 * u[i] - 1.0)
                dw = 2.0 * np.sign(2.0 * u[i] - 1.0) / width[i] * d_on[i]
                dH[:, kk] = w * dF[:, kk] + dw * (F[kk] - blk.F[kk])
        out.append(dH)
    return out


def simulated_history(
    scenario, law, span, *, tolerances=None, starts=None, observe=None, window=False
):
    """The law's force at the span's sample times, each block simulated from its state.

    Parameters
    ----------
    scenario, law
    span : RecordSpan
    tolerances : Tolerances, optional
    starts : sequence of ndarray of shape (4,), optional
        Other start states, one per block (a bootstrap draw); default the measured ones.
    observe : callable, optional
        Observation model ``Impulse -> Impulse`` applied to each block's simulated history
        (the block taken as one periodic signal).
    window : bool
        For optimisers: a sample whose interval holds a contact onset at fraction ``u`` is
        blended towards the record's value with weight ``|2u - 1|`` (whole at the
        interval's ends, nothing where the onset crosses the sample time).  With point
        values (``False``, the default, like the record's) a force jump at the onset
        switches a whole sample from 0 to ``F(0+)`` as the law's coefficients change, and
        the output error is a staircase in the coefficients; blended, it is continuous,
        and at the truth the blended residual is still the record's noise (no bias, also
        when the sampling is a multiple of the drive frequency).

    Returns
    -------
    list of ndarray
        One history per block.  Raises :class:`~discovery.errors.IntegrationError` when a
        simulation fails.
    """
    return simulated_motion(
        scenario, law, span, tolerances=tolerances, starts=starts, observe=observe, window=window
    )[0]


def _runs(scenario, law, span, tolerances, starts):
    """Each block's run ``(block, F, onsets, Z)`` from its measured state (memoised: the
    fitting loops ask again) or from ``starts`` (a bootstrap draw: asked once)."""
    for k, blk in enumerate(span.blocks):
        if starts is None:
            yield _memo_run(scenario, law, blk, tolerances)
        else:
            yield (blk, *_block_run(scenario, law, blk, starts[k], tolerances))


def simulated_motion(
    scenario, law, span, *, tolerances=None, starts=None, observe=None, window=False
):
    """:func:`simulated_history` and, from the same runs, the simulated penetration at the
    span's sample times: ``(histories, penetrations)``, one array per block each."""
    out, zs = [], []
    for blk, F, onsets, Z in _runs(scenario, law, span, tolerances, starts):
        zs.append(Z)
        out.append(_history(blk, F, onsets, observe, window))
    return out, zs


def _history(blk, F, onsets, observe, window):
    """A block's simulated force at its sample times as the comparison sees it: with
    ``window``, onset samples blended towards the record (:func:`simulated_history`); seen
    through ``observe``."""
    fold = blk.fold
    td = fold.td
    Fs = F.copy()
    if observe is not None:
        # through an observation model the onset's jump is placed at the run's event time
        # (:func:`~.observed.observed`), which makes the observed history continuous in the onset: a
        # sample blended towards the record, whose force the sensor has already filtered,
        # would filter it twice (the lag came out 1-2 % low)
        return observed(fold, Fs, observe, onsets, record=blk.F)
    if window and td.size > 1:
        # the sample whose interval [e_i, e_i+1) holds a contact onset at fraction u is
        # blended towards the record's value with weight |2u - 1|: its residual is 0
        # when the onset crosses the sample time (where the point value jumps) and
        # whole at the interval's ends, so the residual is continuous in the law's
        # coefficients and unbiased (at the truth it is the record's noise, weighted)
        k, u, _, _ = _onset_weights(td, onsets)
        if k.size:
            w = np.abs(2.0 * u - 1.0)
            Fs[k] = blk.F[k] + w * (Fs[k] - blk.F[k])
    return Fs


def _memo_run(scenario, law, blk, tolerances, made=None):
    """A block's run from its measured state, memoised (:data:`MEMO`); ``made``: that run
    made elsewhere (a block farm), kept as is."""
    key = value_key(scenario, law, tolerances, id(blk))
    return MEMO.get(key, lambda: (blk, *(made or _block_run(scenario, law, blk, None, tolerances))))


def block_criteria(measured, simulated, span, names=None):
    """Criteria of every block, and their mean weighted by the blocks' cycles.

    Returns
    -------
    mean : dict
    per_block : list of dict
    """
    criteria = unchecked(evaluate_criteria)
    per = [criteria(m, s, names) for m, s in zip(measured, simulated, strict=True)]
    return _block_mean(per, span), per


def _block_mean(per, span):
    """The blocks' criteria ``per`` averaged, weighted by the blocks' cycles."""
    w = np.array([b.fold.n_cycles for b in span.blocks], dtype=float)
    w = w / w.sum()
    return {k: float(np.dot(w, [p[k] for p in per])) for k in per[0]}
