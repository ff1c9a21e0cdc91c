"""The cells, rows and tables every report kind shares (criteria, coefficients, scenario,
provenance, figures), each computed from a run's document alone."""

from __future__ import annotations

import re
from pathlib import Path

from discovery.outputs import handed_off
from discovery.vibroimpact.verify.criteria import CRITERIA as _REGISTRY
from discovery.vibroimpact.verify.criteria import MOTION_DEFINITIONS, definition

from .lawtex import (
    law_equation,
    law_inline,
    law_of,
    term_tex,
    unit_tex,
    value_tex,
)
from .texenv import Tex, escape, interval, num, nums, scientific


def criterion_names(*mappings):
    """The criteria of the registry (its order, then the motion's: I5) found in any of
    ``mappings``; a name neither defines (an edited summary) is not shown."""
    return [
        k
        for k in (*_REGISTRY, *MOTION_DEFINITIONS)
        if any(isinstance(m, dict) and k in m for m in mappings)
    ]


def criterion_tex(name):
    """``$I_{2}$`` for the paper's criteria, the name in typewriter for any other."""
    name = str(name)
    if re.fullmatch(r"I\d", name):
        return Tex(f"$I_{{{name[1]}}}$")
    return Tex(r"\texttt{" + escape(name) + "}")


def criterion_definition(name):
    """The registry's formula and meaning of a criterion, as one table cell."""
    d = definition(name)
    formula = f"${d.latex}$: " if d.latex else ""
    return Tex(formula + escape(d.meaning or "--"))


FIGURE_CAPTIONS = {
    "verify": "Measured force (black) and the law's simulated force (red), folded on the "
    "drive phase over the record's span; with positions, the force-penetration loop and both "
    "penetrations over the contacts (what I5 compares).",
    "fit_impulse": "The measured contact force and the best models' simulated force, folded "
    "on the drive phase the same way (with positions, each from the machine's measured state "
    "over the record's last block of cycles, as the verdict compares them).",
    "fit_surface": Tex(
        r"The selected law over the ($\zeta$, $\dot\zeta_+$) plane with the contact samples."
    ),
    "fit_loop": "Loading and unloading branches, measured and modelled, for a few impacts.",
    "identification": "Identification: the path of the best law so far and the simulated "
    "force converging to the measured one.",
    "landscape": "Criteria over the two coefficients; the noise floor and the consistent "
    "region are marked.",
    "contact_models": "Each named contact model's criterion I2 (the fit's ranking criterion): "
    "consistent with the record(s) (green), inconsistent (red), or failed (hatched: the fit "
    "degenerated; the table names the parameter and why).",
    "discover": "Recovered equation: strobe points, coefficients with error bars and the "
    "verification by simulation.",
    "attractor": "Stroboscopic points and a trajectory of the attractor.",
    "basins": "Basins of the coexisting attractors.",
    "chart": "Regime chart over the forcing frequency and amplitude.",
    "calibrate": "The force each body's motion implies through its equation of motion, "
    "averaged over each test window: with the scenario's machine (orange circles) and the "
    "calibrated one (blue crosses), against the measured force (black); the first drive "
    "periods of the record.",
    "explain": "The missing effect: where the model disagrees before and after it is added.",
    "explain_loops": "The final model against the record: the force-penetration loop and both "
    "penetrations over the contacts (what I5 compares).",
    "recovery_noise": "Exact-support recovery against the force noise, per selection method "
    "and record length (Wilson 95 % intervals).",
    "recovery_map": "Recovery over force noise and record length, per selection method "
    "(recovered/runs in each cell).",
    "coverage": "Share of true coefficients inside their 95 % intervals (exact supports), "
    "against the nominal 95 %.",
    "inclusion": "How often each term was selected, per method and noise level.",
}


# the certificate's domain bounds by their symbols
_DOMAIN = {"zeta_max": Tex(r"$\zeta_{\max}$"), "zd_max": Tex(r"$\dot\zeta_{+,\max}$")}


# the most of the text height a figure may take: every figure is drawn at the text width
# and at most this tall (less the 0.1 in of white round it), so LaTeX prints it at its own
# size or larger (its text 7-8 pt as drawn) and never shrinks it to fit
FIGURE_HEIGHT = "0.75"


def _model_tex(value, where):
    """The equation of a law rebuilt from its text or coefficients (never read as LaTeX);
    ``--`` when the summary has none."""
    if value is None or (isinstance(value, str | dict) and not value):
        return Tex("--")
    return law_equation(law_of(value, where))


def _provenance(s, run_dir):
    v = s.get("versions") or {}
    git = s.get("git") or {}
    rows = [
        ["command", Tex(r"\texttt{vidi " + escape(s.get("command", "?")) + "}")],
        ["created", s.get("created", "--")],
        ["vidi", v.get("vibroimpact-discovery", "--")],
        [
            "git commit",
            (git.get("commit") or "--")[:12]
            + (" (uncommitted changes)" if git.get("dirty") else ""),
        ],
        ["platform", s.get("platform", "--")],
        [
            "libraries",
            ", ".join(f"{k} {val}" for k, val in v.items() if k != "vibroimpact-discovery"),
        ],
    ]
    for name, inp in (s.get("inputs") or {}).items():
        if isinstance(inp, dict):
            rows.append(
                [
                    f"input {name}",
                    f"{inp.get('path', '')} (sha256 {str(inp.get('sha256', ''))[:16]}...)",
                ]
            )
    settings = s.get("settings") or {}
    shown = {
        k: val
        for k, val in settings.items()
        if k not in ("command", "func", "out", "ueda_command") and val not in (None, False)
    }
    rows.append(
        [
            "settings",
            Tex("; ".join(escape(k) + "=" + value_tex(val) for k, val in shown.items()) or "--"),
        ]
    )
    return rows


def _scenario_rows(sc):
    if not sc:
        return []
    units = {
        "m1": "kg",
        "m2": "kg",
        "k1": "N/m",
        "c1": "N s/m",
        "A": "N",
        "frequency": "Hz",
        "g": "m/s^2",
        "k3": "N/m^3",
        "mass_loss": "per impact",
    }
    rows = [["name", sc.get("name", "--")]]
    for k, unit in units.items():
        if k in sc and not (k in ("k3", "mass_loss") and not sc[k]):
            rows.append([k, Tex(num(sc[k]) + r"\ " + unit_tex(unit))])
    if sc.get("law"):
        rows.append(["reference law", law_inline(law_of(sc["law"], "scenario.law"))])
    return rows


def _scenarios_table(scenarios):
    """Every scenario of a run side by side: one column per scenario."""
    scs = [sc for sc in scenarios if isinstance(sc, dict)]
    if not scs:
        return None
    per = [_scenario_rows(sc) for sc in scs]
    labels = [r[0] for r in per[0]]
    rows = []
    for i, label in enumerate(labels):
        rows.append([label, *(p[i][1] if i < len(p) and p[i][0] == label else "--" for p in per)])
    return rows


def _criteria_table(criteria, floor, limits=None):
    """Rows: criterion, value, noise floor, limit (when judged: ``--`` for a criterion the
    consistency rule does not judge), its formula and meaning (the criteria registry)."""
    rows = []
    for k in criterion_names(criteria):
        lim = (limits or {}).get(k)
        value, fl, limit = nums(criteria[k], (floor or {}).get(k), lim)
        rows.append(
            [
                criterion_tex(k),
                value,
                fl,
                limit if lim is not None else Tex("--"),
                criterion_definition(k),
            ]
        )
    return rows


def _measured_rows(m, records=None):
    if not m:
        return []
    noise = m.get("noise")
    noise_f = noise.get("F") if isinstance(noise, dict) else noise
    noise_tex, peak_tex = nums(noise_f, m.get("peak"))  # two forces: one form
    rows = [
        ["drive periods per cycle", m.get("n_periods", "--")],
        ["cycles averaged in the folded cycle", m.get("n_cycles", "--")],
        ["contacts per cycle", m.get("impacts", "--")],
        ["force noise (sd)", Tex(noise_tex + r"\,N")],
        ["peak force", Tex(peak_tex + r"\,N")],
        ["contact time", Tex(num(m.get("contact_time")) + r"\,s")],
    ]
    if isinstance(noise, dict) and "dt" in noise:
        rows.insert(0, ["sampling step", Tex(num(noise["dt"]) + r"\,s")])
    return rows


def _figures(run_dir, order):
    """The run's PDF figures whose names begin with each of ``order``, in that order: those
    written and those a forked process is writing (not waited for here: the report waits
    for each figure it shows, :func:`reports.document.render`)."""
    printing = {p.name for p in handed_off(run_dir) if p.suffix == ".pdf"}
    figs = []
    for stem in order:
        found = {p.name for p in Path(run_dir).glob(f"{stem}*.pdf")}
        found |= {n for n in printing if n.startswith(stem)}
        for p in (Path(run_dir) / n for n in sorted(found)):
            if p.stem in ("report", "model"):
                continue
            base = p.stem.split("_")[0] if p.stem not in FIGURE_CAPTIONS else p.stem
            figs.append(
                {
                    "file": p.name,
                    "caption": FIGURE_CAPTIONS.get(p.stem, FIGURE_CAPTIONS.get(base, p.stem)),
                    "height": Tex(FIGURE_HEIGHT),
                }
            )
    seen, out = set(), []
    for f in figs:
        if f["file"] not in seen:
            seen.add(f["file"])
            out.append(f)
    return out


def _transient(verdict):
    """Whether a verdict says the law was judged over the record's span because its
    trajectory from the measured state had not settled (earlier runs said "transient")."""
    v = verdict or ""
    return "judged against the record's own span" in v or "transient" in v


def _coef_rows(coefs, errors=None, intervals=None, start=None, term=term_tex):
    """Rows: term, coefficient, standard error, 95 % interval (and the start value): the
    numbers of a row in one form (:func:`~reports.texenv.scientific`)."""
    rows = []
    for k, v in coefs.items():
        lo_hi = (intervals or {}).get(k)
        err = (errors or {}).get(k)
        first = (start or {}).get(k)
        sci = scientific(v, err, first, *(lo_hi or ()))
        rows.append(
            [
                term(k),
                num(v, 4, sci=sci),
                num(err, 2, sci=sci),
                interval(*lo_hi, sci=sci) if lo_hi else Tex("--"),
            ]
            + ([num(first, 3, sci=sci)] if start is not None else [])
        )
    return rows


def _machine_rows(machine):
    """The calibration's table (a ``summary.json``'s ``machine``, or a ``calibrate`` run's
    summary): parameter, the sheet's value, the record's with its 95 % interval, and which
    one the run used; ``None`` without a calibration."""
    if not isinstance(machine, dict) or not machine.get("calibrated"):
        return None
    rows = []
    for name, p in (machine.get("parameters") or {}).items():
        if not isinstance(p, dict):
            continue
        ranged = p.get("low") is not None and p.get("low") != p.get("high")
        sci = scientific(p.get("sheet"), p.get("record"), *((p.get("low"), p.get("high")) * ranged))
        interval = (
            Tex(f"[{num(p.get('low'), sci=sci)}, {num(p.get('high'), sci=sci)}]")
            if ranged
            else Tex("")
        )
        used = "record" if p.get("determined") else ("sheet (held)" if p.get("held") else "sheet")
        rows.append(
            [
                Tex(escape(name) + r" [" + unit_tex(p.get("unit", "")) + "]"),
                num(p.get("sheet"), sci=sci),
                Tex(num(p.get("record"), sci=sci) + " " + interval),
                used,
            ]
        )
    return rows or None
