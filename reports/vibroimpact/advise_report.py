"""The report of an ``advise`` run, from its typed result (see :mod:`reports.context`):
the candidates, the advised point, the ranked points with every pair's separation and every
candidate's regime, and the map."""

from __future__ import annotations

from ..lawtex import law_inline, law_of
from ..texenv import Tex, escape, num, nums

__all__ = ["advise_context", "CAPTION"]

CAPTION = (
    "Smallest pair separation over drive amplitude and frequency (1 is where the verdict "
    "starts to reject; the best over the moulding masses when they vary): the advised point "
    "starred, pairs that differ by regime ringed, points outside the safe region crossed."
)


def _f(v):
    """A number of the result (infinity, nan or None allowed; ``"inf"`` as a summary wrote
    it) as table text."""
    if v == "inf" or v == float("inf"):
        return Tex(r"$\infty$")
    return num(v) if v is not None else "--"


def _pair_cell(q):
    """A pair's separation; a pair separated outright (regime, physics) is marked, and
    ranks as if its separation were infinite (the table's note says so)."""
    tag = r" (regime$^\ast$)" if q.regime_change else ""
    if q.physics:
        tag = r" (physics$^\ast$)"
    return Tex(f"{_f(q.separation)}{tag}")


def _span(values, unit):
    """Bounds ``low -- high`` with their unit (``--`` without)."""
    if not values:
        return Tex("--")
    return Tex(" -- ".join(num(v) for v in values) + rf"\,{unit}")


def _bounded(v, unit):
    """A bound with its unit; ``none`` where the run set none."""
    return "none" if v is None else Tex(_f(v) + rf"\,{unit}")


def _judged_rows(adv):
    """At the advised point, each pair in each direction: the criteria of the law judged
    false against their limits (a criterion and its limit in one form), and their ratio."""
    rows = []
    for q in adv.pairs if adv is not None else ():
        i, j = q.pair
        for (true, judged), crit, lims in zip(((i, j), (j, i)), q.criteria, q.limits, strict=False):
            for k in sorted(crit):
                value, lim = crit.get(k), lims.get(k)
                v_tex, l_tex = nums(value, lim)
                ratio = value / lim if value is not None and lim else None
                rows.append(
                    [f"{i + 1}-{j + 1}", true + 1, judged + 1, Tex(f"$I_{{{k[1:]}}}$"), v_tex,
                     l_tex, _f(ratio)]
                )  # fmt: skip
    return rows


def _ranked_rows(r, limit=12):
    rows = []
    for rank, p in enumerate(r.ranked()[:limit], start=1):
        regimes = ", ".join(f"{pr.regime}/{pr.impacts}" for pr in p.predictions or ())
        rows.append(
            [
                rank,
                num(p.amplitude),
                num(p.frequency),
                "--" if p.m2 is None else num(p.m2),
                *[_pair_cell(q) for q in p.pairs or ()],
                regimes,
            ]
        )
    return rows


def _t(*parts):
    """A line of text and numbers: strings escaped, :class:`Tex` kept."""
    return Tex("".join(p if isinstance(p, Tex) else str(escape(str(p))) for p in parts))


def _conclusions(r):
    adv = r.best
    if adv is None:
        return [
            "No point of the bounds is usable (every one is outside the safe region or a "
            "candidate has no periodic orbit with contact there): widen the bounds."
        ]
    regime = [q for q in adv.pairs or () if q.regime_change]
    where = ["Take the next record at A = ", num(adv.amplitude), " N, f = "]
    where += [num(adv.frequency), " Hz"]
    if adv.m2 is not None:
        where += [", m2 = ", num(adv.m2), " kg"]
    out = [_t(*where, ".")]
    if r.separates:
        smallest = adv.smallest_separation(frozenset(r.inseparable))
        out.append(
            _t(
                "There the verdict rejects the false law of every pair whichever is true "
                "(smallest separation ",
                _f(smallest),
                "; 1 is the limit).",
            )
        )
    else:
        out.append(
            "Even there some pair stays within the verdict's limit (separation < 1): the "
            "record may leave them equivalent; widen the bounds or record longer."
        )
    if regime:
        out.append(
            f"{len(regime)} pair(s) predict different regimes there: they are separated "
            "outright by the regime, which a record near a regime boundary may not reach."
        )
    for q in r.inseparable:
        out.append(
            f"No point of the bounds separates candidates {q[0] + 1} and {q[1] + 1}: within "
            "the noise they are the same law there."
        )
    unsafe = sum(bool(p.unsafe) for p in r.points or ())
    if unsafe:
        out.append(f"{unsafe} point(s) were excluded by the safe region.")
    return out


def advise_context(doc, run_dir, figures):
    """The template context of an advise run (a :class:`~reports.run.RunDocument` of an
    :class:`~discovery.AdviseResult`); ``figures`` is :func:`reports.context._figures`."""
    r = doc.result
    laws = r.laws or ()
    n = len(laws)
    adv = r.best
    noise, knobs, safe = r.noise, r.knobs, r.safe
    pairs = [q.pair for q in (adv.pairs if adv is not None else ())] or [
        (i, j) for i in range(n) for j in range(i + 1, n)
    ]
    return {
        "title": "Where to take the next record",
        "candidates": [[k + 1, law_inline(law_of(t, "laws"))] for k, t in enumerate(laws)],
        "bounds": [
            ["drive amplitude", _span(knobs.amplitude, "N")],
            ["drive frequency", _span(knobs.frequency, "Hz")],
            ["moulding mass", "scenario's" if not knobs.m2 else _span(knobs.m2, "kg")],
            ["max peak force", _bounded(safe.max_force, "N")],
            ["max penetration", _bounded(safe.max_penetration, "m")],
            ["force noise", Tex(num(100 * (noise.relative or 0.0)) + r"\,\% of the peak")],
            [
                "position noise",
                "none (a force record: I2, I4)"
                if noise.position is None
                else Tex(
                    num(100 * noise.position) + r"\,\% of the largest penetration (I2, I4, I5)"
                ),
            ],
            ["noise from", noise.source or "--"],
        ],
        "pair_heads": [f"{i + 1}-{j + 1}" for i, j in pairs],
        "ranked": _ranked_rows(r),
        "judged": _judged_rows(adv),
        "n_points": len(r.points or ()),
        "conclusions": _conclusions(r),
        "figures": [dict(f, caption=CAPTION) for f in figures(run_dir, ["advise_map"])],
    }
