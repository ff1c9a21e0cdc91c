"""Records on the drive's phase: one origin for every cycle, the same operator on both sides.

The record's ``t`` is the drive's clock, so a simulation started from the machine's
measured state can be sampled at the record's *own* sample times.  A :class:`Fold`
puts those samples on one cycle of ``n`` drive periods with a single origin (the
record's main impact onset, averaged over its cycles), in bins about one sample wide,
and averages each bin.  Nothing is aligned per cycle, so the onset's noise does not
smear the measured force jump; and where the cycles differ (a slowly decaying transient,
a sample grid that is not a multiple of the period), the measured and the simulated
force are smeared identically, because both go through the same operator at the same
sample times.  When the sampling is incommensurate with the period, the cycles' different
sub-sample phases give a finer phase grid instead of a smear.
"""

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ...numerics.memo import Memo
from ..data.contact_edges import _edge_params, _sampled_support
from ..data.impulse import Impulse

__all__ = ["Fold", "make_fold"]


@dataclass(frozen=True)
class Fold:
    """Samples of a record span folded onto one cycle.

    Attributes
    ----------
    idx : ndarray of int, shape (m,)
        Indices of the folded samples in the record.
    td : ndarray of shape (m,)
        Their drive-clock times [s].
    bins : ndarray of int, shape (m,)
        The bin of each sample (bins without samples are dropped).
    counts : ndarray of int, shape (k,)
        Samples per bin.
    phase : ndarray of shape (k,)
        Mean time since the origin of each bin's samples [s], increasing.
    origin : float
        Drive-clock time [s] of ``t* = 0`` in the span's first cycle.
    duration : float
        Cycle length ``n_periods * T`` [s].
    n_periods : int
    n_cycles : int
        Whole cycles in the span.
    """

    idx: np.ndarray
    td: np.ndarray
    bins: np.ndarray
    counts: np.ndarray
    phase: np.ndarray
    origin: float
    duration: float
    n_periods: int
    n_cycles: int

    @property
    def period(self):
        return self.duration / self.n_periods

    @property
    def end(self):
        """Drive-clock time [s] of the span's end."""
        return self.origin + self.n_cycles * self.duration

    def average(self, values):
        """Bin means of ``values`` (one per folded sample), ndarray of shape (k,); for a
        read-only array, kept (:meth:`_kept_for`)."""
        return self._kept_for("average", values, self._bin_means)

    def positive_phases(self, values):
        """The phase intervals ``(a, b)`` (first and last bin's phase) of each run of bins
        whose mean of ``values`` is positive, ndarray of shape (r, 2) (where a folded
        penetration says the bodies touch); for a read-only array, kept."""
        return self._kept_for("positive", values, self._positive_phases)

    def _bin_means(self, values):
        from ...numerics.sampled import bin_means  # (numba: not at import)

        return bin_means(
            np.ascontiguousarray(self.bins, dtype=np.int64),
            np.ascontiguousarray(values, dtype=float),
            np.ascontiguousarray(self.counts, dtype=np.int64),
        )

    def _positive_phases(self, values):
        on = self.average(values) > 0.0
        d = np.diff(np.concatenate([[0], on.astype(np.int8), [0]]))
        first, last = np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1
        return np.column_stack([self.phase[first], self.phase[last]]).reshape(-1, 2)

    @cached_property
    def _kept(self):
        return Memo(8)

    def _kept_for(self, what, values, compute):
        """``compute(values)``; for a read-only array (a block's recorded channels, a
        memoised simulation's) the result is kept, read-only, and the same object comes
        back when the same array is asked for again (the fitting loops ask for the recorded
        side at every evaluation).  The entry holds the array, so its id is not reused."""
        if not (isinstance(values, np.ndarray) and not values.flags.writeable):
            return compute(values)

        def computed():
            out = compute(values)
            out.setflags(write=False)
            return values, out

        kept, out = self._kept.get((what, id(values)), computed)
        # the entry is this very array's (a copied fold's entries could name another's id)
        return out if kept is values else compute(values)

    def __getstate__(self):
        # what the fold keeps stays in this process (a worker's arrays have other ids)
        state = dict(self.__dict__)
        state.pop("_kept", None)
        return state

    @cached_property
    def knots(self):
        """The folded cycle's times ``[0, phase..., duration]`` (read-only: every impulse
        of this fold shares them) and their edge rules (:func:`_edge_params`)."""
        tau = np.concatenate([[0.0], self.phase, [self.duration]])
        tau.setflags(write=False)
        return tau, _edge_params(tau, self.period)

    def impulse(self, values, *, threshold, noise, onset_record_time=None):
        """The folded cycle of ``values`` as an
        :class:`~discovery.vibroimpact.data.impulse.Impulse` whose
        support is found by the measurement's rules (threshold, smoothing), identical for a
        measured and a simulated history.

        Parameters
        ----------
        values : ndarray of shape (m,)
            A force history at the folded samples [N].
        threshold : float
            Contact threshold of the folded cycle [N].
        noise : float
            Noise of one record sample [N] (0 for an exact history); the folded cycle's
            noise is ``noise / sqrt(n_cycles)``, which decides the support's smoothing.
        onset_record_time : float, optional
            Record time of the origin (for :attr:`Impulse.onset`).

        Notes
        -----
        The support's edges are the threshold crossings of the (smoothed) folded force,
        never extrapolated along a slope: whether an edge counts as "steep" depends on the
        noise, and that binary decision made I4 jump between records of the same law.  A
        crossing moves smoothly with the noise, and the floor replicates reproduce it.
        """
        Fm = self.average(values)
        W = self.duration
        # the cycle's ends: the first bin's value at 0 (the right limit F(0+)) and the last
        # bin's at W (the left limit F(W-) = F(0-)); a force jump at the origin stays one
        tau, edges = self.knots
        F = np.concatenate([[Fm[0]], Fm, [Fm[-1]]])
        n_eff = max(self.n_cycles, 1)
        support = _sampled_support(
            tau,
            F,
            threshold,
            self.period,
            noise=noise / np.sqrt(n_eff),
            extrapolate=False,
            edges=edges,
        )
        onsets = support[:, 0].copy() if len(support) else np.zeros(1)
        return Impulse(
            t=tau,
            F=F,
            duration=W,
            support=support,
            n_periods=self.n_periods,
            onset=self.origin if onset_record_time is None else onset_record_time,
            threshold=threshold,
            noise=noise,
            n_cycles=n_eff,
            onsets=onsets,
        )


def make_fold(td_all, origin, n_periods, period, span):
    """Fold the whole cycles of a record within ``span = (t_first, t_last)`` (drive clock).

    Parameters
    ----------
    td_all : ndarray of shape (n,)
        Drive-clock times of every record sample [s].
    origin : float
        A drive-clock time [s] of ``t* = 0`` (any cycle's: it is moved by whole cycles to
        the first one starting at or after ``t_first``).
    n_periods : int
        Cycle length in drive periods.
    period : float
        Drive period [s].
    span : tuple of float
        ``(t_first, t_last)``: the span that can be used [s].

    Returns
    -------
    Fold or None
        ``None`` when not one whole cycle fits.
    """
    t_first, t_last = span
    W = n_periods * period
    o = origin + np.ceil((t_first - origin) / W - 1e-12) * W
    M = int(np.floor((t_last - o) / W + 1e-12))
    if M < 1:
        return None
    dt = float(np.median(np.diff(td_all)))
    lo, hi = np.searchsorted(td_all, [o, o + M * W])
    idx = np.arange(lo, hi)
    td = td_all[idx]
    ph = np.clip(td - o - np.floor((td - o) / W) * W, 0.0, np.nextafter(W, 0.0))
    nb = max(8, int(round(W / dt)))
    raw = np.minimum((ph / W * nb).astype(np.int64), nb - 1)
    counts = np.bincount(raw, minlength=nb)
    keep = counts > 0
    renum = np.cumsum(keep) - 1
    bins = renum[raw]
    counts = counts[keep]
    phase = np.bincount(bins, weights=ph, minlength=counts.size) / counts
    return Fold(
        idx=idx,
        td=td,
        bins=bins,
        counts=counts,
        phase=phase,
        origin=float(o),
        duration=W,
        n_periods=int(n_periods),
        n_cycles=M,
    )
