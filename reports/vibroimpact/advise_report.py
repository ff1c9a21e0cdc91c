"""The report of an ``advise`` run, from its ``summary.json`` alone (see
:mod:`reports.context`): the candidates, the advised point, the ranked points with every
pair's separation and every candidate's regime, and the map."""

from __future__ import annotations

from ..lawtex import law_inline, law_of
from ..texenv import Tex, escape, num

__all__ = ["advise_context", "CAPTION"]

CAPTION = (
    "Smallest pair separation over drive amplitude and frequency (1 is where the verdict "
    "starts to reject; the best over the moulding masses when they vary): the advised point "
    "starred, pairs that differ by regime ringed, points outside the safe region crossed."
)


def _f(v):
    """A summary number (``"inf"`` or None allowed) as table text."""
    if v == "inf":
        return Tex(r"$\infty$")
    return num(v) if v is not None else "--"


def _pair_cell(q):
    tag = " (regime)" if q.get("regime_change") else ""
    return Tex(f"{_f(q['separation'])}{tag}")


def _ranked_rows(s, n_laws, limit=12):
    points = s.get("points") or []
    rows = []
    for rank, k in enumerate((s.get("ranking") or [])[:limit], start=1):
        p = points[k]
        regimes = ", ".join(
            f"{pr.get('regime')}/{pr.get('impacts')}" for pr in p.get("predictions") or []
        )
        rows.append(
            [
                rank,
                num(p["amplitude"]),
                num(p["frequency"]),
                "--" if p.get("m2") is None else num(p["m2"]),
                *[_pair_cell(q) for q in p.get("pairs") or []],
                regimes,
            ]
        )
    return rows


def _t(*parts):
    """A line of text and numbers: strings escaped, :class:`Tex` kept."""
    return Tex("".join(p if isinstance(p, Tex) else str(escape(str(p))) for p in parts))


def _conclusions(s, n_laws):
    adv = s.get("advised")
    if not adv:
        return [
            "No point of the bounds is usable (every one is outside the safe region or a "
            "candidate has no periodic orbit with contact there): widen the bounds."
        ]
    pairs = adv.get("pairs") or []
    regime = [q for q in pairs if q.get("regime_change")]
    where = ["Take the next record at A = ", num(adv["amplitude"]), " N, f = "]
    where += [num(adv["frequency"]), " Hz"]
    if adv.get("m2") is not None:
        where += [", m2 = ", num(adv["m2"]), " kg"]
    out = [_t(*where, ".")]
    if s.get("separates"):
        out.append(
            _t(
                "There the verdict rejects the false law of every pair whichever is true "
                "(smallest separation ",
                _f(s.get("smallest_separation")),
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
    for q in s.get("inseparable") or []:
        out.append(
            f"No point of the bounds separates candidates {q[0] + 1} and {q[1] + 1}: within "
            "the noise they are the same law there."
        )
    unsafe = sum(bool(p.get("unsafe")) for p in s.get("points") or [])
    if unsafe:
        out.append(f"{unsafe} point(s) were excluded by the safe region.")
    return out


def advise_context(s, run_dir, figures):
    """The template context of an advise run; ``figures`` is :func:`reports.context._figures`."""
    laws = s.get("laws") or []
    n = len(laws)
    adv = s.get("advised") or {}
    noise = s.get("noise") or {}
    pair_heads = [
        f"{q['pair'][0] + 1}-{q['pair'][1] + 1}"
        for q in (adv.get("pairs") or [])
        or [{"pair": (i, j)} for i in range(n) for j in range(i + 1, n)]
    ]
    knobs = s.get("knobs") or {}
    return {
        "title": "Where to take the next record",
        "candidates": [[k + 1, law_inline(law_of(t, "laws"))] for k, t in enumerate(laws)],
        "bounds": [
            ["drive amplitude", Tex(" -- ".join(num(v) for v in knobs.get("amplitude") or []))],
            ["drive frequency", Tex(" -- ".join(num(v) for v in knobs.get("frequency") or []))],
            [
                "moulding mass",
                "scenario's"
                if not knobs.get("m2")
                else Tex(" -- ".join(num(v) for v in knobs["m2"])),
            ],
            ["max peak force", _f((s.get("safe") or {}).get("max_force"))],
            ["max penetration", _f((s.get("safe") or {}).get("max_penetration"))],
            ["force noise", Tex(num(100 * noise.get("relative", 0.0)) + r"\,\% of the peak")],
            [
                "position noise",
                "none (a force record: I2, I4)"
                if noise.get("position") is None
                else Tex(
                    num(100 * noise["position"]) + r"\,\% of the largest penetration (I2, I4, I5)"
                ),
            ],
            ["noise from", noise.get("source", "--")],
        ],
        "pair_heads": pair_heads,
        "ranked": _ranked_rows(s, n),
        "n_points": len(s.get("points") or []),
        "conclusions": _conclusions(s, n),
        "figures": [dict(f, caption=CAPTION) for f in figures(run_dir, ["advise_map"])],
    }
