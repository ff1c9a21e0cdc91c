"""Measured (or synthetic) records: validated loading and writing of CSV files.

CSV format: a header row; ``t`` [s] and ``F`` [N] required; ``w1``, ``w2`` [m],
``v1``, ``v2`` [m/s] and ``a2`` [m/s^2] optional; other columns are ignored (with a
note).  Without ``F``, the force is taken from the moulding's acceleration,
``F = m2 (a2 + g)`` (its equation of motion), which needs the scenario.  The time
``t`` is the drive's clock: the drive is ``A sin(2 pi f t)``.

Files from real instruments (:meth:`Measurement.from_csv`):

* **Encoding.** UTF-8, with or without a byte-order mark (spreadsheet exports); a
  UTF-16 file with its byte-order mark is read too.  Anything else is refused with a
  line asking to re-save the file as UTF-8.
* **Separators.** ``,``, ``;`` or tab, sniffed from the header line.  With ``;`` or tab
  a decimal comma (``0,25``) is read as a decimal point (noted).  Lines starting with
  ``#`` and blank lines are skipped.
* **Other header names.** ``columns={"t": "time_s", "F": "force_N"}`` (CLI:
  ``--columns t=time_s,F=force_N``) maps our names to the file's.
* **Sampling.** The record must be uniformly sampled.  With ``med`` the median step,
  the jitter is ``max |dt - med| / med``: up to 0.1 % (rounding of written times) the
  record is used as it is; up to :data:`JITTER_LIMIT` (10 %) every column is resampled
  by linear interpolation onto the uniform grid ``t0 + k (t_end - t0) / (n - 1)`` (same
  number of samples, same ends) and a note says so; beyond it (gaps, dropped samples,
  irregular logging) the file is refused with a line saying what to do.
* **Values.** Every cell must be a finite number within :data:`LIMITS` (SI units: a
  value beyond them is a unit or column mix-up and would overflow the processing).
"""

import io
from dataclasses import dataclass, field, replace

import numpy as np

from ..._api._printing import fmt, readable
from ..._api._validate import Array, Text, check
from ..._files._csv import parse_column, read_csv_rows
from ..._files._io import atomic_write_text
from ...errors import InputError, NoContactError
from .contact_edges import _edge_params
from .impulse import impulse_from_samples
from .noise import estimate_noise

#: the most samples of one record a run makes or predicts (``vidi simulate``, a study's
#: records, field records, advise's predictions): a record of this length, with positions
#: and velocities, is about the largest CSV file the reader takes
#: (:data:`discovery._files._csv.MAX_RECORD_BYTES`)
MAX_SAMPLES = 2_000_000

__all__ = ["Measurement", "COLUMNS", "LIMITS", "JITTER_LIMIT", "STATE_COLUMNS"]

_OPTIONAL = ("w1", "v1", "w2", "v2", "a2")
_STATE = STATE_COLUMNS = ("w1", "v1", "w2", "v2")
COLUMNS = ("t", "F", *_OPTIONAL)
#: largest accepted magnitude and unit of each column (SI)
LIMITS = {
    "t": (1e7, "s"),
    "F": (1e12, "N"),
    "w1": (1e3, "m"),
    "w2": (1e3, "m"),
    "v1": (1e3, "m/s"),
    "v2": (1e3, "m/s"),
    "a2": (1e7, "m/s^2"),
}
#: relative sampling jitter below which a record is uniform as it is
UNIFORM_TOL = 1e-3
#: relative sampling jitter up to which a record is resampled onto a uniform grid
JITTER_LIMIT = 0.10


def _jitter(t):
    """``(max |dt - med| / med, med, min dt, max dt)`` of increasing times."""
    d = np.diff(t)
    med = float(np.median(d))
    return float(np.max(np.abs(d - med)) / med), med, float(d.min()), float(d.max())


def _fmt(x):
    return f"{float(x):.10g}"


@readable
@dataclass(frozen=True)
class Measurement:
    """A force record, optionally with the bodies' positions and velocities.

    Attributes
    ----------
    t : ndarray of shape (n,)
        Strictly increasing, uniformly spaced sample times [s] (jitter up to
        :data:`JITTER_LIMIT` of a step is tolerated; :meth:`from_csv` resamples it).
    F : ndarray of shape (n,)
        Contact force [N].
    channels : dict
        Optional ``w1, v1, w2, v2`` arrays of shape (n,).
    source : str
        File it came from.
    notes : tuple of str
        What was ignored or assumed while loading.
    """

    t: np.ndarray
    F: np.ndarray
    channels: dict = field(default_factory=dict)
    source: str = ""
    notes: tuple = ()

    def __post_init__(self):
        check("Measurement: t", self.t, Array(1))
        check("Measurement: F", self.F, Array(1))
        check("Measurement: channels", self.channels, dict)
        for name, arr in self.channels.items():
            check("Measurement: a channel name", name, Text(100))
            check(f"Measurement: channel {name}", arr, Array(1))
        check("Measurement: source", self.source, Text(4096, empty=True))
        t = np.asarray(self.t, dtype=float)
        F = np.asarray(self.F, dtype=float)
        where = f" in {self.source}" if self.source else ""
        if t.ndim != 1 or t.shape != F.shape or t.size < 4:
            raise InputError(
                f"t and F must be 1-D of equal length >= 4{where}; a record needs "
                "at least 4 samples"
            )
        for name, arr in (("t", t), ("F", F), *self.channels.items()):
            arr = np.asarray(arr, dtype=float)
            if arr.shape != t.shape:
                raise InputError(
                    f"channel {name}{where} has {arr.size} samples but t has "
                    f"{t.size}; give every channel at every time"
                )
            bad = np.flatnonzero(~np.isfinite(arr))
            if bad.size:
                raise InputError(
                    f"column {name}{where} has a missing or non-finite value at "
                    f"data row {bad[0] + 1}; remove or fill it"
                )
            lim, unit = LIMITS.get(name, (np.inf, ""))
            big = np.flatnonzero(np.abs(arr) > lim)
            if big.size:
                raise InputError(
                    f"column {name}{where} has the value {_fmt(arr[big[0]])} at "
                    f"data row {big[0] + 1}, beyond the accepted |{name}| <= "
                    f"{lim:g} {unit}; check the column and its units (SI)"
                )
        d = np.diff(t)
        if np.any(d == 0):
            k = int(np.flatnonzero(d == 0)[0])
            raise InputError(
                f"duplicate time t = {_fmt(t[k])}{where} (data rows {k + 1}, "
                f"{k + 2}); each sample needs its own time"
            )
        if np.any(d < 0):
            k = int(np.flatnonzero(d < 0)[0])
            raise InputError(
                f"times are not increasing{where} at data row {k + 2}; sort the file by t"
            )
        jit, med, lo, hi = _jitter(t)
        if jit > JITTER_LIMIT:
            raise InputError(_nonuniform_message(where, jit, med, lo, hi))
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "F", F)
        object.__setattr__(
            self, "channels", {k: np.asarray(v, dtype=float) for k, v in self.channels.items()}
        )

    @property
    def fs(self):
        """Sampling rate [Hz] (median)."""
        return 1.0 / float(np.median(np.diff(self.t)))

    @classmethod
    def from_csv(cls, path, scenario=None, columns=None):
        """Load and validate a CSV file (see the module docstring for the dialects).

        Parameters
        ----------
        path : str or Path
        scenario : Scenario, optional
            Needed only when the file has ``a2`` but no ``F``.
        columns : dict, optional
            ``{our name: the file's header}``, e.g. ``{"t": "time_s", "F": "force_N"}``;
            our names are ``t, F, w1, v1, w2, v2, a2``.  Unmapped names are looked up as
            they are.

        Raises
        ------
        InputError
            One line naming the problem (file, column, line) and the fix.
        """
        name = str(path)
        rows = read_csv_rows(path, "t and F")
        body = rows.body
        src, from_a2, extra_notes = _column_sources(rows.header, columns, name, scenario)
        notes = rows.notes + extra_notes
        cols = {key: parse_column(rows, key, j, name=name, limits=LIMITS) for key, j in src.items()}
        t = cols["t"]
        d = np.diff(t)
        if np.any(d == 0):
            k = int(np.flatnonzero(d == 0)[0])
            raise InputError(
                f"data file {name!r}: duplicate time t = {_fmt(t[k])} at lines "
                f"{body[k][0]} and {body[k + 1][0]}; each sample needs its own time"
            )
        if np.any(d < 0):
            k = int(np.flatnonzero(d < 0)[0])
            raise InputError(
                f"data file {name!r}: times are not increasing at line "
                f"{body[k + 1][0]}; sort the file by t"
            )
        if t.size >= 3:
            jit, med, lo, hi = _jitter(t)
            if jit > JITTER_LIMIT:
                raise InputError(_nonuniform_message(f" in {name!r}", jit, med, lo, hi))
            if jit > UNIFORM_TOL:
                grid = np.linspace(t[0], t[-1], t.size)
                cols = {k: (grid if k == "t" else np.interp(grid, t, v)) for k, v in cols.items()}
                notes += (
                    f"resampled onto a uniform grid (step {_fmt(grid[1] - grid[0])} s) by "
                    f"linear interpolation: the sampling jitter was {100 * jit:.3g} % of "
                    "a step",
                )
        channels = {k: cols[k] for k in _OPTIONAL if k in cols}
        if from_a2:
            cols["F"] = scenario.m2 * (cols["a2"] + scenario.g)
            notes += ("F formed from the moulding's acceleration: F = m2 (a2 + g)",)
        return cls(cols["t"], cols["F"], channels, name, notes)

    def to_csv_text(self):
        """The record as CSV text (``t, F`` then the optional channels, ``%.12g``)."""
        names = ["t", "F", *[k for k in _OPTIONAL if k in self.channels]]
        data = np.column_stack([self.t, self.F, *[self.channels[k] for k in names[2:]]])
        buf = io.StringIO()
        buf.write(",".join(names) + "\n")
        np.savetxt(buf, data, delimiter=",", fmt="%.12g")
        return buf.getvalue()

    def to_csv(self, path):
        """Write atomically as CSV (``t, F`` then the optional channels); mode 0666 minus
        the umask."""
        atomic_write_text(path, self.to_csv_text())

    def unlagged(self, tau):
        """The record as a force sensor without its first-order lag of time constant
        ``tau`` [s] would have read it: ``F + tau dF/dt`` (the lag's inverse, the
        derivative by central differences; noisier than the record, unbiased), the other
        channels as they are.  What a regression of the force on the penetration sees
        when the lag is known (:func:`discovery.discover`'s ``sensor_lag``)."""
        if not tau:
            return self
        return replace(self, F=self.F + tau * np.gradient(self.F, self.t))

    @property
    def zeta(self):
        """Interpenetration ``w1 - w2`` [m] if both positions were recorded, else None."""
        if "w1" in self.channels and "w2" in self.channels:
            return self.channels["w1"] - self.channels["w2"]
        return None

    def state_at_strobe(self, period, time_offset=0.0):
        """The bodies' state at a late strobe time of the record (drive phase 0).

        The latest time ``t + time_offset = k T`` with a window of samples on both sides
        and, preferably, no contact force in it; positions (and velocities, when
        recorded; otherwise the slope of the position fit) from a local quadratic fit
        over +-1 % of a period, which averages the sensor noise down.

        Returns
        -------
        state : ndarray of shape (4,)
            ``w1, v1, w2, v2``.
        t_drive : float
            The strobe time on the drive's clock [s].
        """
        ch = self.channels
        if "w1" not in ch or "w2" not in ch:
            raise InputError("the state needs the positions w1 and w2 in the data")
        t = self.t
        dt = float(np.median(np.diff(t)))
        m = max(3, int(0.01 * period / dt))
        k_hi = int(np.floor((t[-1 - m] + time_offset) / period))
        k_lo = int(np.ceil((t[m] + time_offset) / period))
        if k_hi < k_lo:
            raise InputError("the record is shorter than one drive period")
        thr = 5.0 * estimate_noise(self.F)
        best = None
        for k in range(k_hi, max(k_lo, k_hi - 8) - 1, -1):
            i = int(np.searchsorted(t, k * period - time_offset))
            free = bool(np.all(self.F[max(i - m, 0) : i + m + 1] <= max(thr, 0.0)))
            if best is None or free:
                best = (k, i)
            if free:
                break
        k, i = best
        return self.state_near(k * period - time_offset, period), float(k * period)

    def state_near(self, t_k, period):
        """The bodies' state ``w1, v1, w2, v2`` at record time ``t_k`` from a local
        quadratic fit of each channel over +-1 % of a period (velocities from the fit's
        slope when they were not recorded)."""
        ch, t = self.channels, self.t
        if "w1" not in ch or "w2" not in ch:
            raise InputError("the state needs the positions w1 and w2 in the data")
        dt = float(np.median(np.diff(t)))
        m = max(3, int(0.01 * period / dt))
        i = int(np.searchsorted(t, t_k))
        sl = slice(max(i - m, 0), min(i + m + 1, t.size))
        x = t[sl] - t_k

        def fit(y):
            return np.polyfit(x, y[sl], 2)

        state = []
        for w, v in (("w1", "v1"), ("w2", "v2")):
            cw = fit(ch[w])
            state.append(np.polyval(cw, 0.0))
            state.append(np.polyval(fit(ch[v]), 0.0) if v in ch else cw[1])
        return np.array(state, dtype=float)

    def impulse(self, period, **kwargs):
        """Period-averaged steady-state impulse (see :func:`impulse_from_samples`);
        the onset comes from ``zeta`` when positions were recorded."""
        try:
            return impulse_from_samples(self.t, self.F, period, zeta=self.zeta, **kwargs)
        except NoContactError:
            raise NoContactError(
                no_contact_message(self.t, self.F, period, self.source, kwargs.get("threshold"))
            ) from None

    def _lines(self):
        n = self.t.size
        span = float(self.t[-1] - self.t[0]) if n > 1 else 0.0
        rate = (n - 1) / span if span > 0 else None
        channels = ", ".join(self.channels) or "none"
        out = [
            f"record of {n} samples over {fmt(span)} s ({fmt(rate)} Hz): force "
            f"{fmt(np.min(self.F) if n else None)} to {fmt(np.max(self.F) if n else None)} N, "
            f"channels {channels}"
        ]
        if self.source:
            out.append(f"  from {self.source}")
        out += [f"  note: {x}" for x in self.notes]
        return out


def _nonuniform_message(where, jit, med, lo, hi):
    return (
        f"the record{where} is not uniformly sampled: time steps from {_fmt(lo)} to "
        f"{_fmt(hi)} s around the median {_fmt(med)} s ({100 * jit:.3g} % off; up to "
        f"{100 * JITTER_LIMIT:g} % is resampled); resample it onto a uniform time grid "
        "(e.g. numpy.interp) or cut it at the gap, then load it again"
    )


def _recurring(starts, period):
    """Whether runs starting at ``starts`` [s] recur with the drive: at least three, each
    a whole number of periods (one or more) after the one before, within a tenth of one."""
    if starts.size < 3:
        return False
    gaps = np.diff(starts) / period
    whole = np.round(gaps)
    return bool(np.all(whole >= 1) and np.all(np.abs(gaps - whole) <= 0.1))


def no_contact_message(t, F, period, source="", threshold=None):
    """Why a record yields no complete contact: no sample above the threshold, samples
    above it only in runs cut off at the record's start or end, or only noise spikes."""
    t = np.asarray(t, dtype=float)
    F = np.asarray(F, dtype=float)
    where = f" in {source}" if source else ""
    sigma = estimate_noise(F)
    thr = max(5.0 * sigma, 1e-3 * float(np.max(F))) if threshold is None else float(threshold)
    above = F > thr
    n_above = int(above.sum())
    if n_above == 0:
        return (
            f"no contact found in the force record{where}: no sample exceeds the threshold "
            f"{thr:.3g} N (5 x the noise {sigma:.3g} N, at least 1e-3 of max F); check the "
            "F column and its units"
        )
    min_len = _edge_params(t, period)[0]
    edges = np.flatnonzero(np.diff(np.concatenate([[0], above.astype(np.int8), [0]])))
    runs = []
    for a, b in zip(edges[::2], edges[1::2], strict=True):
        if runs and a - runs[-1][1] < min_len:
            runs[-1][1] = b
        else:
            runs.append([a, b])
    long_runs = [(a, b) for a, b in runs if b - a >= min_len]
    if long_runs and all(a == 0 or b == F.size for a, b in long_runs):
        at = [("start" if a == 0 else "end") for a, b in long_runs]
        n_cut = sum(b - a for a, b in long_runs)
        side = " and ".join(dict.fromkeys(at))
        return (
            f"the only contact{where} ({n_cut} samples above the threshold {thr:.3g} N) is "
            f"cut off at the record's {side}: a contact must begin and end inside the "
            "record; record a few drive periods more (whole contacts)"
        )
    if not long_runs:
        longest = max(b - a for a, b in runs)
        if _recurring(t[[a for a, _ in runs]], period):
            rate = (1.0 / float(np.median(np.diff(t)))) * min_len / longest
            return (
                f"no contact found in the force record{where}: {len(runs)} runs above the "
                f"threshold {thr:.3g} N recur with the drive period, but the longest lasts "
                f"{longest} sample(s) and a contact needs {min_len} (1 % of a drive "
                "period): the contacts are too short for this sampling rate; record at "
                f"{rate:.3g} Hz or more"
            )
        return (
            f"no contact found in the force record{where}: {n_above} samples exceed the "
            f"threshold {thr:.3g} N but no run lasts {min_len} samples (1 % of a drive "
            "period) and they do not recur with the drive period: they look like noise "
            "spikes; check the F column, its units and the sampling rate"
        )
    return (
        f"no contact found in the force record{where}: the runs above the threshold "
        f"{thr:.3g} N peak below 3 x the threshold, which is read as noise; check the F "
        "column and its units, or record with less noise"
    )


def _mapped_columns(header, columns, name, named):
    """``{our name: column index}`` of a user's column mapping ``{our name: header}``."""
    if not isinstance(columns, dict):
        raise InputError(
            "columns must map our names to the file's headers, e.g. {'t': 'time_s', 'F': 'force_N'}"
        )
    src = {}
    for key, col in columns.items():
        if key not in COLUMNS:
            raise InputError(
                f"column mapping: unknown name {key!r}; map the names "
                f"{', '.join(COLUMNS)} to the file's headers, e.g. "
                "t=time_s,F=force_N"
            )
        col = col.strip() if isinstance(col, str) else col
        if not isinstance(col, str) or not col:
            raise InputError(
                f"column mapping {key}=: give the header of the file's "
                f"column for {key}, e.g. {key}=time_s"
            )
        if col not in header:
            raise InputError(
                f"column mapping {key}={col}: data file {name!r} has no column "
                f"{col!r} (found {', '.join(named) or 'no names'})"
            )
        src[key] = header.index(col)
    if len(set(src.values())) != len(src):
        raise InputError(
            "column mapping: two names are mapped to the same column; map "
            "each of the file's columns once"
        )
    return src


def _column_sources(header, columns, name, scenario):
    """``{our name: column index}``, whether F comes from a2, and notes."""
    named = [h for h in header if h]
    dups = sorted({h for h in named if named.count(h) > 1})
    if dups:
        raise InputError(
            f"data file {name!r}: column name(s) {', '.join(dups)} appear more "
            "than once in the header; rename them"
        )
    src, notes = {}, ()
    if columns:
        src = _mapped_columns(header, columns, name, named)
        notes += ("columns mapped: " + ", ".join(f"{k} <- {header[j]}" for k, j in src.items()),)
    used = set(src.values())
    for key in COLUMNS:
        if key not in src and key in header and header.index(key) not in used:
            src[key] = header.index(key)
    from_a2 = "F" not in src and "a2" in src
    if from_a2 and scenario is None:
        raise InputError(
            f"data file {name!r} has a2 but no F; give the scenario so that "
            "F = m2 (a2 + g) can be formed"
        )
    missing = [c for c in ("t", "F") if c not in src and not (c == "F" and from_a2)]
    for c in missing:
        if c in header:  # its column was mapped to another name
            other = next(k for k, j in src.items() if j == header.index(c))
            raise InputError(
                f"column mapping {other}={c} takes the file's column {c}, so "
                f"nothing is left for {c}; map {c} to another column as well, "
                f"e.g. {c}=NAME"
            )
    if missing:
        raise InputError(
            f"data file {name!r} has no column {' or '.join(missing)} (found "
            f"{', '.join(named) or 'no names'}); name them t [s] and F [N] in the "
            "header, or map yours: --columns t=NAME,F=NAME (API: columns=)"
        )
    ignored = [h for j, h in enumerate(header) if h and j not in src.values()]
    if ignored:
        notes += (f"ignored column(s): {', '.join(ignored)}",)
    return src, from_a2, notes
