"""What several figures of the vibro-impact system share: units and labels of coefficients
and forces, laws and term names as matplotlib mathtext, and the contact window of a cycle."""

import numpy as np

__all__ = [
    "term_unit",
    "coefficient_label",
    "monomial_math",
    "law_math",
    "terms_math",
    "plain",
    "force_unit",
    "contact_view",
]


def _exp(p):
    return str(int(p)) if float(p).is_integer() else f"{float(p):g}"


def term_unit(name):
    """SI unit of the coefficient of the term ``name`` (``z^a*zd^b``): N m^-a (m/s)^-b,
    as matplotlib mathtext, e.g. ``'z*zd'`` -> ``N m$^{-1}$ (m/s)$^{-1}$``."""
    from discovery.vibroimpact.model.law import Term

    try:
        t = Term.parse(name)
    except Exception:  # not a single term: say what the coefficient multiplies
        return f"N per unit of {name}"
    unit = "N"
    if t.a:
        unit += f" m$^{{-{_exp(t.a)}}}$"
    if t.b:
        unit += f" (m/s)$^{{-{_exp(t.b)}}}$"
    return unit


def coefficient_label(name):
    """Axis label of a coefficient with its unit, e.g. ``coefficient of z [N m^-1]``."""
    return f"coefficient of {name} [{term_unit(name)}]"


def monomial_math(term, unloading=False):
    """A term ``zeta^a zeta_dot^b`` as mathtext (``|zeta_dot|`` in an unloading term)."""
    zd = r"|\dot{\zeta}|" if unloading else r"\dot{\zeta}_{+}"
    parts = []
    if term.a:
        parts.append(r"\zeta" if term.a == 1 else rf"\zeta^{{{_exp(term.a)}}}")
    if term.b:
        parts.append(zd if term.b == 1 else rf"{zd}^{{{_exp(term.b)}}}")
    return r"\,".join(parts)


def law_math(law):
    r"""A law as matplotlib mathtext: ``$F = 2.06\cdot 10^{8}\,\zeta + ...$`` (the
    unloading terms after a semicolon)."""
    from reports.lawtex import sci

    def poly(coefs, terms, unloading=False):
        out = [
            ("-" if c < 0 else "+") + rf" {sci(abs(c))}\,{monomial_math(t, unloading)}"
            for c, t in zip(coefs, terms, strict=True)
        ]
        text = " ".join(out)
        return text[2:] if text.startswith("+ ") else text

    text = f"$P = {poly(law.coefficients, law.terms)}$"
    if law.unloading:
        text += f"; unloading $Q = {poly(law.unloading_coefficients, law.unloading, True)}$"
    if law.permanent_set:
        text += f"; set {law.permanent_set:.3g}"
    return text


def terms_math(text):
    """User or label text with its term names (``z^2*zd``) as mathtext, the rest plain."""
    from discovery.vibroimpact.model.law import Term
    from reports.lawtex import _TERMISH

    text = plain(text)
    out, pos = [], 0
    for m in _TERMISH.finditer(text):
        try:
            term = Term.parse(m.group(0))
        except Exception:  # not a term after all
            continue
        out.append(text[pos : m.start()] + f"${monomial_math(term)}$")
        pos = m.end()
    return "".join(out) + text[pos:]


def plain(text):
    """User text (a file or scenario name) for a figure: matplotlib would read ``$...$`` as
    mathtext (and fail on a broken one)."""
    return str(text).replace("$", r"\$")


def force_unit(peak):
    """``(scale, unit)`` to draw forces without an offset label: N, kN or MN."""
    peak = abs(float(peak)) if np.isfinite(peak) else 0.0
    if peak >= 1e6:
        return 1e-6, "MN"
    if peak >= 1e3:
        return 1e-3, "kN"
    return 1.0, "N"


def contact_view(t, period, *forces, threshold=0.0):
    """Times of a folded cycle re-based on the contact: ``(t', order, (lo, hi))`` with
    ``t'`` the time since the first sample of the contact (the end of the longest stretch
    where every force is at most ``threshold``), wrapped so the contact is not cut by the
    fold, and the x-range around it (the whole cycle when contact fills most of it)."""
    t = np.asarray(t, dtype=float)
    active = np.zeros(t.size, dtype=bool)
    for f in forces:
        active |= np.abs(np.asarray(f, dtype=float)) > threshold
    # a noise spike is not a contact: keep only runs of at least 3 samples
    active &= (
        (np.roll(active, 1) & np.roll(active, -1))
        | (np.roll(active, 1) & np.roll(active, 2))
        | (np.roll(active, -1) & np.roll(active, -2))
    )
    n = t.size
    if not active.any() or active.all():
        return t - t[0], np.arange(n), (0.0, float(period))
    # the longest run of inactive samples on the circle
    doubled = np.concatenate([~active, ~active])
    best_len, best_end, run = 0, 0, 0
    for i, free in enumerate(doubled):
        run = run + 1 if free else 0
        if run > best_len and run <= n:
            best_len, best_end = run, i
    start = (best_end + 1) % n  # first active sample after the longest gap
    tr = np.mod(t - t[start], period)
    span = float(period) * (n - best_len) / n
    margin = 0.15 * span
    tr = np.where(tr > period - margin, tr - period, tr)
    order = np.argsort(tr)
    if span > 0.6 * period:
        return tr, order, (float(tr.min()), float(tr.max()))
    return tr, order, (-margin, span + 2.0 * margin)
