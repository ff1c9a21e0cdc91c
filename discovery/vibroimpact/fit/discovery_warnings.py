"""Why the record(s) may not identify the discovered law: the warnings of a discovery."""


def _stability_warning(stab, selected):
    if not stab:
        return None
    names = set(selected.law.names)
    weak = [t for t in names if stab.get(t, 0.0) < 0.5]
    strong = [t for t, f in stab.items() if f >= 0.5 and t not in names]
    if not weak and not strong:
        return None
    parts = []
    if weak:
        parts.append(
            "selected but chosen in < 50 % of resamples: "
            + ", ".join(f"{t} ({stab.get(t, 0.0):.2f})" for t in sorted(weak))
        )
    if strong:
        parts.append(
            "chosen in >= 50 % of resamples but not selected: "
            + ", ".join(f"{t} ({stab[t]:.2f})" for t in sorted(strong))
        )
    return (
        "stability selection disagrees with the selected support ("
        + "; ".join(parts)
        + "): the record may not identify these terms"
    )


def _impact_warnings(pairs, parts, refs):
    out = []
    for k, ((sc, meas), s, (_, ref)) in enumerate(zip(pairs, parts, refs, strict=True)):
        E = ref.impulse
        span = float(meas.t[-1] - meas.t[0])
        expected = span / (E.n_periods * sc.period) * ref.impacts
        n = s.n_impacts
        if expected >= 2 and not (0.6 * expected - 1 <= n <= 1.15 * expected + 1):
            label = f"record {k + 1}" if len(pairs) > 1 else "the record"
            out.append(
                f"{label} gives {n} impacts for the contact samples, but its "
                f"{span / sc.period:.0f} periods of a {ref.regime} cycle with "
                f"{ref.impacts} contact(s) hold about {expected:.0f}: contacts are "
                "split or merged (noisy positions?); check the record, record the "
                "velocities, or lower the position noise"
            )
    return out


def _warnings(selected, by_score, stab, evidence, refine):
    """The warnings of a discovery that selected ``selected`` (``by_score``: the shortlist
    in the regression's order, ``stab``: stability selection's term frequencies,
    ``evidence``: the records as fitted)."""
    samples = evidence.samples
    out = []
    w = _stability_warning(stab, selected)
    if w:
        out.append(w)
    failing = [m for m in by_score[:3] if not m.criteria]
    if failing:
        out.append(
            f"{len(failing)} of the 3 best candidates by the regression score have no "
            "periodic steady state with contact ("
            + "; ".join(f"{' + '.join(m.law.names)}: {m.evaluation.status}" for m in failing)
            + "): the regression alone would mislead here"
        )
    out.extend(_impact_warnings(evidence.pairs, evidence.parts, evidence.refs))
    if (
        not selected.consistent
        and selected.criteria
        and all(ev.consistent or ev.only_i4 for ev in selected.evaluations)
    ):
        out.append(
            "the selected model fails the consistency rule by I4 alone (the contact "
            "supports; I2 is within its noise floor): I4 is noise-sensitive on flat "
            "force tails and short contacts, so this may be the right law; compare the "
            "contact ends in fit_impulse before trying a larger library"
        )
    elif not selected.consistent:
        out.append(
            "no shortlisted model is consistent with the record(s) within the noise "
            "floor: the record may hold an effect no polynomial law has (damping while "
            "unloading, a permanent set, a sensor lag, ...), which `vidi explain` names; "
            "else try a larger library (e.g. poly:3+hc), a longer shortlist, or check the "
            "scenario (masses, supports, drive)"
        )
    if samples.derivative != "velocities" and not refine:
        out.append(
            f"dzeta was obtained by {samples.derivative} from noisy positions: the "
            "regression coefficients are biased (errors in variables); use the "
            "refinement by simulation"
        )
    ref = selected.refinement
    if ref is not None and selected.standard_errors:
        reg = selected.candidate.extra.get("regression_coefficients", {})
        moved = []
        for t, c in selected.law.as_dict().items():
            se = selected.standard_errors.get(t, 0.0)
            c0 = reg.get(t)
            if c0 is not None and se > 0 and abs(c - c0) > max(3 * se, 0.1 * abs(c)):
                moved.append(f"{t} {c0:.3g} -> {c:.3g} ({abs(c - c0) / se:.0f} standard errors)")
        if moved:
            out.append(
                "the refinement by simulation moved regression coefficients far beyond "
                "their uncertainty (" + "; ".join(moved) + "): the regression is biased "
                "by noisy penetration or velocity; the refined values are reported"
            )
    return out


def _defects_warning(selected, physics):
    """The warning that the selected law is no contact law."""
    return (
        "the selected law is no contact law ("
        + "; ".join(selected.defects)
        + "): "
        + (
            "no candidate was one; widen the library or --require z"
            if physics
            else "ranked by the records alone (--allow-unphysical)"
        )
    )
