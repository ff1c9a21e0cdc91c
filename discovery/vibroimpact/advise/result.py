"""The outcome of ``advise``: every evaluated point, ranked, with its round trip to JSON."""

from dataclasses import dataclass, field

import numpy as np

from ..._api._printing import readable
from ..._api._result import Result
from ..model.law import ForceLaw
from .candidates import Knobs, NoiseModel, SafeRegion
from .refit import RefitSeparation
from .separation import Point, inseparable, rank_key

__all__ = ["AdviseResult"]


@readable
@dataclass(frozen=True, eq=False)
class AdviseResult(Result):
    """Where a next record separates the candidate laws.

    Attributes
    ----------
    laws : tuple of str
        The candidates (law texts, exact).
    scenario : dict
        The machine (``Scenario.as_dict()``) whose knobs were varied.
    knobs : Knobs
    safe : SafeRegion
    noise : NoiseModel
    points : tuple of Point
        Every evaluated point, coarse then refined.
    seconds : float
    settings : dict
        Versions-free settings (workers, ...); provenance is added by the CLI.
    refit : tuple of RefitSeparation
        The advised point's pairs with each rival refitted to the other's predicted record
        (:mod:`~discovery.vibroimpact.advise.refit`); empty when not asked.
    """

    KIND = "advise"
    _LOAD = {
        "laws": lambda d: tuple(d["laws"]),
        "scenario": lambda d: dict(d["scenario"]),
        "knobs": lambda d: Knobs.from_dict(d["knobs"]),
        "safe": lambda d: SafeRegion.from_dict(d["safe"]),
        "noise": lambda d: NoiseModel.from_dict(d["noise"]),
        "points": lambda d: tuple(Point.from_dict(p) for p in d["points"]),
        "seconds": lambda d: float(d["seconds"]),
        "settings": lambda d: dict(d["settings"]),
        "refit": lambda d: tuple(RefitSeparation.from_dict(r) for r in d.get("refit") or ()),
    }

    laws: tuple
    scenario: dict
    knobs: Knobs
    safe: SafeRegion
    noise: NoiseModel
    points: tuple
    seconds: float = 0.0
    settings: dict = field(default_factory=dict)
    refit: tuple = ()

    # ------------------------------------------------------------------ reading
    @property
    def candidates(self):
        """The candidates as :class:`ForceLaw`."""
        return tuple(ForceLaw.parse(t) for t in self.laws)

    @property
    def inseparable(self):
        """Pairs no point of the bounds separates (see
        :func:`~discovery.vibroimpact.advise.separation.inseparable`), sorted."""
        return sorted(inseparable(self.points))

    def ranked(self):
        """The usable points, best first (:func:`.separation.rank_key`): most pairs separated,
        then the largest smallest separation (a regime change counting as infinite), over
        the pairs some point separates."""
        ignore = frozenset(self.inseparable)
        usable = [p for p in self.points if p.usable]
        return sorted(usable, key=lambda p: rank_key(p, ignore))

    @property
    def best(self):
        """The advised point (``None`` when no point is usable)."""
        r = self.ranked()
        return r[0] if r else None

    @property
    def separates(self):
        """Whether the advised point separates every pair (by criteria or regime); false
        when a pair is :attr:`inseparable`."""
        b = self.best
        return b is not None and all(p.separated for p in b.pairs)

    def map(self):
        """The coarse/refined points on the amplitude x frequency plane.

        Returns
        -------
        dict
            ``amplitude``, ``frequency`` (ndarrays of shape (n,)), ``smallest`` (the
            smallest separation over the pairs some point separates, of the best point over
            ``m2`` at each (A, f); nan where excluded),
            ``unsafe`` and ``excluded`` (bool, every m2 excluded), ``regime`` (bool, the
            best point there separates by regime), ``physics`` (bool, a candidate's orbit
            there leaves its dissipative domain).
        """
        ignore = frozenset(self.inseparable)
        cells = {}
        for p in self.points:
            key = (p.amplitude, p.frequency)
            cells.setdefault(key, []).append(p)
        keys = sorted(cells)
        out = {
            "amplitude": np.array([k[0] for k in keys]),
            "frequency": np.array([k[1] for k in keys]),
        }
        smallest, unsafe, excl, regime, physics = [], [], [], [], []
        for k in keys:
            ps = [p for p in cells[k] if p.usable]
            best = min(ps, key=lambda p: rank_key(p, ignore)) if ps else None
            smallest.append(best.smallest_separation(ignore) if best else np.nan)
            regime.append(bool(best and any(q.regime_change for q in best.pairs)))
            physics.append(bool(best and any(pr.leaves_domain for pr in best.predictions)))
            unsafe.append(not ps and any(p.unsafe for p in cells[k]))
            excl.append(not ps)
        out.update(
            smallest=np.array(smallest, dtype=float),
            unsafe=np.array(unsafe),
            excluded=np.array(excl),
            regime=np.array(regime),
            physics=np.array(physics),
        )
        return out

    # ------------------------------------------------------------------ JSON
    def as_dict(self):
        """The result's keys of its document (:meth:`~discovery.Result.to_dict` adds the
        schema version and kind): plain floats, lists and strings, ``inf`` as ``"inf"``."""
        ranked = self.ranked()
        index = {id(p): k for k, p in enumerate(self.points)}
        return {
            "command": "advise",
            "laws": list(self.laws),
            "scenario": self.scenario,
            "knobs": self.knobs.to_dict(),
            "safe": self.safe.to_dict(),
            "noise": self.noise.to_dict(),
            "points": [p.to_dict() for p in self.points],
            "ranking": [index[id(p)] for p in ranked],
            "advised": None if not ranked else ranked[0].to_dict(),
            "inseparable": [list(q) for q in self.inseparable],
            "smallest_separation": None
            if not ranked
            else ranked[0].smallest_separation(frozenset(self.inseparable)),
            "separates": self.separates,
            "seconds": float(self.seconds),
            "settings": dict(self.settings),
            "refit": [r.to_dict() for r in self.refit],
        }

    def write_into(self, out):
        """``summary.json`` (the document) and ``advise.csv`` into an open
        :class:`~discovery._files._io.OutputDir` (``save(dir)`` stages both and puts them in
        place together)."""
        super().write_into(out)
        out.path("advise.csv").write_text(self.csv())

    def csv(self):
        """One row per point: knobs, stage, smallest separation, exclusion."""
        rows = ["amplitude,frequency,m2,stage,smallest_separation,regime_change,excluded"]
        for p in self.points:
            m2 = "" if p.m2 is None else f"{p.m2:.10g}"
            reg = int(any(q.regime_change for q in p.pairs))
            why = p.excluded.replace('"', "'")
            rows.append(
                f'{p.amplitude:.10g},{p.frequency:.10g},{m2},{p.stage},{p.smallest:.6g},{reg},"{why}"'
            )
        return "\n".join(rows) + "\n"

    # ------------------------------------------------------------------ print
    def pair_label(self, pair):
        return f"{pair[0] + 1}-{pair[1] + 1}"

    def _lines(self):
        out = ["candidates:"]
        out += [f"  {k + 1}. {ForceLaw.parse(t)}" for k, t in enumerate(self.laws)]
        usable = sum(p.usable for p in self.points)
        unsafe = sum(p.unsafe for p in self.points)
        out.append(
            f"{len(self.points)} point(s) evaluated, {usable} usable, {unsafe} outside the "
            f"safe region; noise {100 * self.noise.relative:.3g} % of the peak force"
        )
        out += _domain_lines(self)
        b = self.best
        if b is None:
            out.append("no usable point: widen the bounds or the safe region")
            return out
        out.append(f"advised: {_where(b)}")
        out += point_lines(b, self)
        out += refit_lines(self)
        left_out = len(self.inseparable) < len(b.pairs)
        for q in self.inseparable:
            out.append(
                f"  pair {self.pair_label(q)}: no point of the bounds separates them (the same "
                "law within the noise there)" + ("; left out of the ranking" if left_out else "")
            )
        if not self.separates:
            out.append(
                "  the advised point does not separate every pair (separation < 1): a record "
                "there may still leave them equivalent; widen the bounds or record longer"
            )
        return out


def refit_lines(result):
    """The advised point's pairs with each rival refitted to the other's predicted record."""
    out = []
    for r in result.refit:
        sep = r.separation
        verdict = (
            "still separated"
            if sep > 1
            else "the refitted rival absorbs the difference: a fit with the new record may "
            "still leave them equivalent"
        )
        i, j = (k + 1 for k in r.pair)
        nested = [
            f"candidate {a} holds every term of {b} and reduces to it on {b}'s record (told "
            f"apart by its extra terms' intervals, not by a rejection)"
            for (a, b), n in zip(((j, i), (i, j)), r.nested, strict=True)
            if n
        ]
        out.append(
            f"  pair {i}-{j} with each rival refitted to the other's predicted record: "
            f"separation {sep:.3g} (directions {r.directions[0]:.3g}, {r.directions[1]:.3g}): "
            f"{verdict}" + "".join(f"; {t}" for t in nested)
        )
    return out


def _domain_lines(self):
    """One line per candidate whose predicted orbit leaves its dissipative domain at some
    usable point: where a record rejects it on physics."""
    out = []
    usable = [p for p in self.points if p.usable]
    for k in range(len(self.laws)):
        left = [p for p in usable if p.predictions[k].leaves_domain]
        if left:
            out.append(
                f"candidate {k + 1} is dissipative (condition (6)) only up to a penetration "
                f"rate of {left[0].predictions[k].domain:.3g} m/s; at {len(left)} of "
                f"{len(usable)} usable point(s) the rates there go beyond (its orbit's, or "
                "the others' where it has none), and a record rejects it on physics (ringed "
                "in red on the map)"
            )
    return out


def _where(p):
    m2 = "" if p.m2 is None else f", m2 = {p.m2:.4g} kg"
    return f"A = {p.amplitude:.4g} N, f = {p.frequency:.4g} Hz{m2}"


def point_lines(p, result):
    """The pairs' separations and the candidates' regimes at a point."""
    out = []
    for q in p.pairs:
        tag = " (regime change: separated outright)" if q.regime_change else ""
        if q.physics:
            tag = " (a candidate leaves its dissipative domain: separated on physics)"
        out.append(
            f"  pair {result.pair_label(q.pair)}: separation {q.separation:.3g} "
            f"(directions {q.directions[0]:.3g}, {q.directions[1]:.3g}){tag}"
        )
    for k, pr in enumerate(p.predictions):
        if pr.status != "ok":
            out.append(
                f"  candidate {k + 1}: no periodic orbit ({pr.status})"
                + (
                    f": the other candidates' orbits reach a penetration rate of "
                    f"{pr.max_rate:.3g} m/s, beyond the {pr.domain:.3g} m/s up to which it is "
                    "dissipative (condition (6)): a record here rejects it on physics"
                    if pr.leaves_domain
                    else ""
                )
            )
            continue
        out.append(
            f"  candidate {k + 1}: {pr.regime} with {pr.impacts} contact(s), peak force "
            f"{pr.peak_force:.3g} N, penetration {pr.max_penetration:.3g} m"
            + (
                f"; its orbit reaches a penetration rate of {pr.max_rate:.3g} m/s, beyond "
                f"the {pr.domain:.3g} m/s up to which it is dissipative (condition (6)): a "
                "record here rejects it on physics"
                if pr.leaves_domain
                else ""
            )
        )
    return out
