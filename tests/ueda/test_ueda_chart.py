"""Regime charts of Ueda's oscillators (issue 9, part 2): periods beyond 8, the early
exit, the two-direction sweep and its coexisting attractors, the CLI.

Reference points (verified independently, see each test):

* negres ``B = 0.09 .. 0.095, nu = 1.02``: a stable P9 orbit (shooting: multipliers
  ~0.03); ``nu = 1.05``: P13 (multipliers ~0.008); ``B = 0.45, 0.55``: P1 (the large
  synchronised region, quenching);
* negres ``B = 0.5 .. 0.55, nu ~ 1.06 .. 1.08``: two coexisting P1 orbits (basins);
* duffing ``B = 0.1, nu = 1.0``: the jump phenomenon of the hardening resonance - a
  large P1 orbit (x ~ 0.92) and a small one (x ~ 0.10) coexist (and a P3); at
  ``B = 0.15`` the resonance's fold lies beyond ``nu = 1.5`` and the sweeps agree.
"""

import csv
import json

import numpy as np
import pytest

from discovery.errors import InputError
from discovery.ueda import UedaSystem, basins, classify, periodic_orbit, strobe_points
from discovery.ueda.regime_chart import KINDS, chart

NEGRES = UedaSystem.from_model("negres")
DUFFING = UedaSystem.from_model("duffing")
NU = np.linspace(1.0, 1.05, 6)
B = np.array([0.09, 0.0935, 0.095, 0.45, 0.55])


def _classes(ch, i, j):
    return KINDS[ch.kind[i, j]], int(ch.period[i, j])


@pytest.fixture(scope="module")
def small_chart():
    return chart(NEGRES, NU, B, workers=1)


def test_chart_finds_p1_and_subharmonics_above_8(small_chart):
    ch = small_chart
    assert ch.settings["max_period"] == 16
    for i in range(3):
        assert _classes(ch, i, 2) == ("Pn", 9)  # nu = 1.02
        assert _classes(ch, i, 5) == ("Pn", 13)  # nu = 1.05
    assert np.all(ch.kind[3:] == KINDS.index("P1")) and np.all(ch.period[3:] == 1)
    assert np.all(ch.lyapunov[3:] < -0.04)
    # periodic points stop early: far fewer periods than transient + periods (140)
    assert np.all(ch.periods_integrated[3:] < 60)
    assert ch.period_counts()[9] >= 3 and ch.as_dict()["periods_found"]["P13"] >= 3


def test_the_p9_orbit_is_confirmed_by_shooting(small_chart):
    """Independent of the chart: a long transient, then Newton on the 9-fold period map;
    the orbit converges, is stable, does not reduce to a shorter period, and its largest
    multiplier gives the chart's exponent log|m1| / (9 T)."""
    s = NEGRES.with_params(B=0.09, nu=1.02)
    pts, _ = strobe_points(s, None, 20, transient=1000)
    orb = periodic_orbit(s, pts[-1], 9)
    assert orb.converged and orb.stable and orb.n_periods == 9 and orb.residual < 1e-8
    big = float(np.max(np.abs(orb.multipliers)))
    assert big < 0.1
    assert abs(small_chart.lyapunov[0, 2] - np.log(big) / (9 * s.period)) < 2e-3
    orb13 = periodic_orbit(
        NEGRES.with_params(B=0.09, nu=1.05),
        strobe_points(NEGRES.with_params(B=0.09, nu=1.05), None, 20, transient=1000)[0][-1],
        13,
    )
    assert orb13.converged and orb13.stable and orb13.n_periods == 13


def test_max_period_8_misses_them_and_early_exit_keeps_the_classes(small_chart):
    """With max_period 8 (the old charts) the P9 and P13 points are beat; without the
    early exit (every point: full transient + variational run, the old procedure) the
    reference points keep their classes."""
    old = chart(NEGRES, NU, B, workers=1, max_period=8)
    for i in range(3):
        assert KINDS[old.kind[i, 2]] == "beat" and KINDS[old.kind[i, 5]] == "beat"
    full = chart(NEGRES, NU, B, workers=1, early_exit=False)
    for i in range(3):
        assert _classes(full, i, 2) == ("Pn", 9) and _classes(full, i, 5) == ("Pn", 13)
    assert np.all(full.kind[3:] == 0)
    assert np.all(full.periods_integrated >= 140)  # (+ n periods of monodromy if periodic)
    # the exponents of periodic points: Floquet (early exit) vs Benettin over 80 periods
    assert np.allclose(full.lyapunov[3:], small_chart.lyapunov[3:], atol=2e-3)


def test_two_direction_sweep_finds_the_jump_phenomenon():
    """Duffing's hardening resonance: sweeping nu up follows the large orbit, sweeping
    back down the small one; between the folds the sweeps disagree (coexisting).  The
    two orbits at nu = 1.0 are confirmed by two classify runs from different initial
    states."""
    nu = np.linspace(0.6, 1.5, 10)
    ch = chart(DUFFING, nu, [0.1, 0.15], sweeps=2, workers=1)
    assert ch.sweeps == 2
    j = 4  # nu = 1.0
    assert ch.coexisting[0, j]
    assert KINDS[ch.kind[0, j]] == "P1" and KINDS[ch.kind_down[0, j]] == "P1"
    assert not ch.coexisting[1].any()  # B = 0.15: the fold is beyond the range
    assert 3 <= ch.coexisting[0].sum() <= 7
    d = ch.as_dict()
    assert d["coexisting_points"] == int(ch.coexisting.sum()) and "fractions_down" in d
    rows = list(ch.rows())
    assert len(rows) == 20 and len(rows[0]) == len(ch.columns) == 11
    assert ch.columns[-1] == "coexisting" and rows[j][-1] == 1
    s = DUFFING.with_params(B=0.1, nu=1.0)
    big, _, pb = classify(s, (1.0, 0.8), transient=300, periods=100)
    small, _, ps = classify(s, (-0.1, 0.0), transient=300, periods=100)
    assert big.regime == small.regime == "P1"
    assert np.max(np.abs(pb[-1])) > 0.8 and np.max(np.abs(ps[-1])) < 0.15


def test_negres_resonance_hysteresis_at_large_forcing():
    """negres at B = 0.5-0.55 near nu = 1.06-1.1: two P1 orbits coexist (the
    synchronised orbit the up-sweep follows, and a second one the down-sweep lands on -
    a Duffing-like jump).  Confirmed by the basins of a 5x5 grid of initial states at
    B = 0.55, nu = 1.08: two P1 attractors with different centres (measured 92 % / 8 %,
    exponents -0.114 and -0.063)."""
    ch = chart(NEGRES, np.linspace(1.0, 1.2, 11), [0.5, 0.55], sweeps=2, workers=1)
    for i, j in ((0, 3), (1, 4)):  # (B 0.5, nu 1.06), (B 0.55, nu 1.08)
        assert ch.coexisting[i, j]
        assert KINDS[ch.kind[i, j]] == KINDS[ch.kind_down[i, j]] == "P1"
        assert abs(ch.lyapunov[i, j] - ch.lyapunov_down[i, j]) > 0.02
    assert not ch.coexisting[:, :3].any()  # nu <= 1.04: one P1
    bas = basins(
        NEGRES.with_params(B=0.55, nu=1.08),
        (-1.5, 1.5),
        (-1.5, 1.5),
        n=5,
        transient=300,
        periods=100,
    )
    p1 = [a for a in bas.attractors if a["regime"] == "P1"]
    assert len(p1) >= 2
    assert np.max(np.abs(np.subtract(p1[0]["centre"], p1[1]["centre"]))) > 0.1


def test_chart_validation():
    with pytest.raises(InputError, match="at least 4 x max_period"):
        chart(NEGRES, NU, B, max_period=24)
    with pytest.raises(InputError, match="sweeps"):
        chart(NEGRES, NU, B, sweeps=3)
    with pytest.raises(InputError, match="max_period"):
        chart(NEGRES, NU, B, max_period=0)


@pytest.fixture
def vidi(monkeypatch):
    import discovery.cli as C

    assert "ueda" in C.COMMANDS
    return C.main


def test_cli_chart_both_directions_and_bad_input(vidi, tmp_path, capsys):
    out = tmp_path / "ch"
    assert (
        vidi(
            [
                "ueda",
                "chart",
                "--model",
                "duffing",
                "--nu",
                "0.6:1.5:10",
                "--B",
                "0.1:0.15:2",
                "--both-directions",
                "--workers",
                "1",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    s = json.loads((out / "summary.json").read_text())
    assert s["sweeps"] == 2 and s["coexisting_points"] >= 3
    assert s["settings"]["max_period"] == 16 and "P1" in s["periods_found"]
    with open(out / "chart.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][-5:] == [
        "regime_down",
        "period_down",
        "lyapunov_down",
        "rotation_number_down",
        "coexisting",
    ]
    assert len(rows) == 21 and (out / "chart.png").exists()
    capsys.readouterr()
    for bad in (["--max-period", "0"], ["--max-period", "30"], ["--max-period", "x"]):
        assert vidi(["ueda", "chart", *bad, "--out", str(tmp_path / "bad")]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and "--max-period" in err
    with pytest.raises(SystemExit):
        from discovery.cli import _parser

        _parser().parse_args(["ueda", "chart", "--help"])
    text = capsys.readouterr().out
    assert "(default: 16)" in " ".join(text.split()) and "--both-directions" in text
