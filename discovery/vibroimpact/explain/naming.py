"""The evidence of an iteration that names an effect: why the winner is named (its gap, its
score test and its rank, the phases where the residual is largest, the lower refits passed
over, the law refitted alone it beat by the verdict) and what the other refits reached."""

import numpy as np


def _score_rank(trials, s):
    """``", k-th largest of n"`` of the named effect's score among the refitted effects' (the
    refit decides, so a lower-ranked score is said, not hidden); empty when it is the
    largest or alone."""
    lms = sorted((t.score["lm"] for t in trials if t.score.get("lm") is not None), reverse=True)
    if len(lms) < 2 or s["lm"] >= lms[0]:
        return ""
    k = 1 + sum(v > s["lm"] for v in lms)
    return f", {k}{_ordinal(k)} largest of the {len(lms)} refitted"


def _ordinal(k):
    return {1: "st", 2: "nd", 3: "rd"}.get(k if k < 20 else k % 10, "th")


def _others(trials, named, key):
    """The clause naming the other refitted effects by their criterion after the refit (the
    decision is the refit's, not the score's), best first; empty when there are none."""
    rest = sorted(
        (t.score["criteria_after"][key], t.score["effect"])
        for t in trials
        if t.key == key
        and t.score["effect"] != named
        and np.isfinite(t.score.get("criteria_after", {}).get(key, np.nan))
    )
    if not rest:
        return ""
    shown = ", ".join(f"{e} {v:.3g}" for v, e in rest[:4])
    more = f" and {len(rest) - 4} more" if len(rest) > 4 else ""
    return f"; the other effects refitted reach {key} {shown}{more}"


def name_effect(run, step, good, winner, trials):
    """The winner (``good[0]`` polished: ``winner``) is named: the iteration records its
    evidence (with the other refits' criteria, ``trials``) and the effects as good."""
    s, key = good[0].score, good[0].key
    before, floor, screening = step.before, step.floor, step.screening
    value = s["criteria_after"][key]
    tol_eq = floor.get(key, 0.0)
    equivalent = [
        x.score["effect"]
        for x in good[1:]
        if x.key == key and x.score["criteria_after"][key] <= value + tol_eq
    ]
    score = (
        f"its score test is significant (LM = {s['lm']:.3g}, p = {s['p']:.2g} < "
        f"{screening.level:.2g}{_score_rank(trials, s)})"
        if s["lm"] is not None and s["significant"]
        else f"its score test is not significant (LM = {s['lm']:.3g}, p = {s['p']:.2g}): "
        "it was refitted after the significant effects' refits named nothing"
        if s["lm"] is not None
        else "it has no score test (a small step of it changes the regime)"
    )
    phases = ", ".join(screening.top_phases)
    lower = [
        f"{x.score['effect']} {x.score['criteria_after'][key]:.3g}"
        for x in good[1:]
        if x.key == key and x.score["criteria_after"][key] < value
    ]
    why = (
        f"its refit lowers {key} the most"
        if not lower
        else f"its refit is consistent with the record(s) and the lower ones within the noise "
        f"floor ({', '.join(lower)}) are not"
    )
    evidence = (
        f"named because {why}: {before[key]:.3g} -> {value:.3g} "
        f"(the noise floor of the model before: {floor.get(key, float('nan')):.3g}); {score}; "
        f"the residual is largest at the {phases}"
        + (
            ", where this effect acts"
            if s["signature_agrees"]
            else ", not where this effect acts most (the phases are a hint; an effect that "
            "changes the whole impact moves the residual everywhere, and the refit decides)"
        )
        + by_verdict(s, key)
        + _others(trials, s["effect"], key)
    )
    run.iterations.append(
        step.iteration(
            model_after=winner.model,
            criteria_after=s["criteria_after"],
            effect=s["effect"],
            evidence=evidence,
            equivalent=equivalent,
            simulated_after=winner.evaluations[0].simulated,
        )
    )
    run.model = winner.model
    if winner.result is not None:
        run.uncertainties = dict(winner.result.standard_errors)


def by_verdict(score, key):
    """The evidence's clause for an effect named over the law refitted alone by the verdict
    (:meth:`.trials._Trial.judge`), else ""."""
    law = score.get("law_alone_inconsistent")
    if law is None:
        return ""
    return (
        f"; the law refitted alone reached {key} {law:.3g}, within the noise floor of this "
        "refit, but is not consistent with the record(s), where this refit is"
    )
