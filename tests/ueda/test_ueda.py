"""Ueda's oscillators (issue 9): compiled kernels against scipy and closed forms, the
Lyapunov exponents (published value, two methods, tolerance convergence, trace
identity), the classification, basins, the chart and the CLI."""

import json

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from discovery.ueda import (
    UedaSystem,
    attractor,
    basins,
    classify,
    lyapunov,
    lyapunov_two_trajectory,
    strobe_points,
    trajectory,
)
from discovery.ueda.regime_chart import KINDS, chart
from discovery.vibroimpact.dynamics import Tolerances

NEGRES = UedaSystem.from_model("negres")
DUFFING = UedaSystem.from_model("duffing")


# ------------------------------------------------------------------ kernels vs scipy
@pytest.mark.parametrize("system", [NEGRES, DUFFING], ids=["negres", "duffing"])
def test_strobe_points_match_scipy(system):
    """The compiled map (steps landing on t = 2 pi k / nu) against DOP853 at 1e-13."""
    y0 = np.array([0.3, -0.2])
    n = 6
    pts, _ = strobe_points(system, y0, n, transient=0, tolerances=Tolerances(rtol=1e-11))
    T = system.period
    ref = solve_ivp(
        system.rhs,
        (0, n * T),
        y0,
        method="DOP853",
        rtol=1e-13,
        atol=1e-14,
        t_eval=T * np.arange(1, n + 1),
    ).y.T
    # chaotic divergence over 6 periods amplifies ~1e-11 local errors to ~1e-8 at most
    assert np.max(np.abs(pts - ref)) < 1e-7


def test_dense_trajectory_matches_scipy():
    t, x, v = trajectory(
        NEGRES,
        (0.1, 0.0),
        (0.0, 3 * NEGRES.period),
        n_samples=301,
        tolerances=Tolerances(rtol=1e-11),
    )
    ref = solve_ivp(
        NEGRES.rhs, (0, t[-1]), [0.1, 0.0], method="DOP853", rtol=1e-13, atol=1e-14, t_eval=t
    ).y
    # dense output is 4th order between steps: ~1e-9 at rtol 1e-11
    assert np.max(np.abs(x - ref[0])) < 1e-7 and np.max(np.abs(v - ref[1])) < 1e-7


def test_variational_equations_match_scipy_finite_time_exponents():
    """Finite-time exponents over 8 periods from one state: the compiled variational run
    against scipy's integration of the same equations with Gram-Schmidt every period."""
    s = NEGRES
    y0 = np.array([-0.5, 0.2])
    L = lyapunov(s, y0, transient=0, periods=8, batches=2, tolerances=Tolerances(rtol=1e-11))

    def f(t, z):
        J = s.jacobian(t, z[:2])
        return np.concatenate([s.rhs(t, z[:2]), J @ z[2:4], J @ z[4:6]])

    z = np.array([*y0, 1, 0, 0, 1.0])
    logs = np.zeros(2)
    T = s.period
    for k in range(8):
        z = solve_ivp(f, (k * T, (k + 1) * T), z, method="DOP853", rtol=1e-13, atol=1e-14).y[:, -1]
        Q, R = np.linalg.qr(np.column_stack([z[2:4], z[4:6]]))
        sg = np.sign(np.diag(R))
        logs += np.log(np.abs(np.diag(R)))
        Q = Q * sg
        z[2:4], z[4:6] = Q[:, 0], Q[:, 1]
    ref = logs / (8 * T)
    assert abs(L.value - ref[0]) < 1e-8 and abs(L.second - ref[1]) < 1e-8


def test_conservative_limit_keeps_the_energy():
    """Closed form: mu = k = B = 0 is x'' + x^3 = 0, energy v^2/2 + x^4/4 conserved."""
    s = UedaSystem.from_model("negres", mu=0.0, B=0.0)
    pts, _ = strobe_points(s, (1.0, 0.0), 200, transient=0, tolerances=Tolerances(rtol=1e-10))
    E = pts[:, 1] ** 2 / 2 + pts[:, 0] ** 4 / 4
    assert np.max(np.abs(E - 0.25)) < 1e-8


def test_exponent_sum_equals_mean_trace_and_duffing_closed_form():
    """lambda1 + lambda2 = time average of the trace; for duffing the trace is -k."""
    L = lyapunov(DUFFING, periods=500)
    assert abs(L.trace_mean + DUFFING.k) < 1e-12
    assert abs(L.sum - L.trace_mean) < 1e-8
    Ln = lyapunov(NEGRES, periods=500)
    assert abs(Ln.sum - Ln.trace_mean) < 1e-8
    assert Ln.trace_mean < 0  # dissipative on average


# ------------------------------------------------------------------ exponents
def test_broken_egg_is_chaotic_with_a_positive_exponent():
    att = attractor(NEGRES, periods=2000, trajectory_periods=5)
    assert att.regime.regime == "chaotic"
    L = att.lyapunov
    # measured 0.097 +- 0.0013 over 5000 periods (rtol 1e-9)
    assert L.value > 0.05 and L.value > 10 * L.stderr
    d = att.as_dict()
    assert d["n_points"] == 2000
    assert -0.85 < d["strobe_x_range"][0] < d["strobe_x_range"][1] < 0.15


def test_duffing_exponent_matches_published_value():
    """Ueda's attractor, published largest exponent ~0.103 per unit time.  20000 periods
    give a batch-means standard error of ~0.001; the tolerance 0.005 is ~5 standard
    errors (the published value is itself a finite-time estimate given to 3 digits)."""
    L = lyapunov(DUFFING, periods=20000, batches=40)
    assert L.stderr < 0.0015
    assert abs(L.value - 0.103) < 0.005
    assert abs(L.second - (-0.05 - L.value)) < 1e-8


@pytest.mark.parametrize("system", [NEGRES, DUFFING], ids=["negres", "duffing"])
def test_variational_and_two_trajectory_agree(system):
    L = lyapunov(system, periods=10000, batches=20)
    lam2, se2 = lyapunov_two_trajectory(system, periods=10000, batches=20)
    # after a few hundred periods the two runs follow different chaotic trajectories:
    # independent estimates, so they agree within their combined standard error
    assert abs(L.value - lam2) < 4 * np.hypot(L.stderr, se2)


def test_exponent_converges_as_the_tolerance_tightens():
    """Finite-time exponent (10 periods from one state on the attractor, no step cap):
    the error against rtol 1e-12 shrinks by >= 5x per decade of rtol, and a loose
    tolerance biases it (measured: 0.08 at rtol 1e-3, 1.6e-5 at 1e-6, 1.3e-8 at 1e-9)."""
    _, y = strobe_points(DUFFING, None, 1, transient=300, tolerances=Tolerances(rtol=1e-12))

    def lam(rtol):
        return lyapunov(
            DUFFING,
            y,
            transient=0,
            periods=10,
            batches=2,
            tolerances=Tolerances(rtol=rtol, hmax_fraction=1.0),
        ).value

    ref = lam(1e-12)
    errs = [abs(lam(r) - ref) for r in (1e-5, 1e-6, 1e-7, 1e-8, 1e-9)]
    assert all(b < a / 5 for a, b in zip(errs, errs[1:], strict=False))
    assert errs[-1] < 1e-7
    assert abs(lam(1e-3) - ref) > 1e-2


# ------------------------------------------------------------------ classification
def test_entrained_case_is_p1():
    """B = 0.45, nu = 1.05: inside the large synchronised region of the chart (strong
    forcing: quenching of the self-oscillation); exponent ~ -0.045."""
    reg, L, _ = classify(UedaSystem.from_model("negres", B=0.45, nu=1.05))
    assert reg.regime == "P1" and reg.kind == "P1"
    assert L.value < -0.02


def test_beat_case_is_quasi_periodic():
    """B = 0.03, nu = 1.0: weak forcing far from the natural frequency - the forced
    self-oscillation beats (an invariant closed curve): no period up to 40, exponent 0
    within its standard error (measured -4e-5 +- 7e-5), points turning monotonically
    around their centre with rotation number ~0.43."""
    s = UedaSystem.from_model("negres", B=0.03, nu=1.0)
    reg, L, _ = classify(s, transient=500, periods=1500, max_period=40)
    assert reg.regime == "beat"
    assert abs(L.value) < 0.002
    assert reg.evidence["monotone_fraction"] == 1.0
    assert 0.40 < reg.evidence["rotation_number"] < 0.46


def test_phase_locked_subharmonic_is_found_when_looked_for():
    """B = 0.06, nu = 0.8 is locked at period 15 (rotation 4/15): a beat with max_period 8,
    P15 with max_period 40 (a documented limit of charts)."""
    s = UedaSystem.from_model("negres", B=0.06, nu=0.8)
    reg, _, _ = classify(s, transient=1000, periods=200, max_period=40)
    assert reg.regime == "P15" and reg.kind == "Pn"


def test_basins_of_the_broken_egg():
    bas = basins(NEGRES, n=4, transient=200, periods=150)
    fr = sum(a["fraction"] for a in bas.attractors)
    assert abs(fr - 1) < 1e-12
    assert bas.attractors[0]["regime"] == "chaotic" and bas.attractors[0]["fraction"] >= 0.75


def test_chart_is_independent_of_workers():
    nu, B = np.linspace(0.9, 1.1, 5), np.array([0.05, 0.35, 0.55])
    c1 = chart(NEGRES, nu, B, workers=1)
    c2 = chart(NEGRES, nu, B, workers=2)
    assert np.array_equal(c1.kind, c2.kind) and np.allclose(c1.lyapunov, c2.lyapunov)
    assert set(np.unique(c1.kind)) <= set(range(len(KINDS)))
    assert KINDS[c1.kind[1, 3]] == "chaotic"  # the broken egg's neighbourhood
    assert KINDS[c1.kind[2, 4]] == "P1"


def test_system_validation():
    with pytest.raises(ValueError):
        UedaSystem.from_model("negres", nu=0.0)
    with pytest.raises(ValueError):
        UedaSystem.from_model("vanderpol")
    s = UedaSystem.from_model("duffing", B=5.0)
    assert s.k == 0.05 and s.B == 5.0 and s.mu == 0.0


# ------------------------------------------------------------------ CLI
@pytest.fixture
def vidi(monkeypatch):
    import discovery.cli as C

    assert "ueda" in C.COMMANDS
    return C.main


def test_cli_attractor_and_chart(vidi, tmp_path):
    out = tmp_path / "att"
    assert (
        vidi(
            [
                "ueda",
                "attractor",
                "--model",
                "duffing",
                "--periods",
                "300",
                "--transient",
                "100",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    s = json.loads((out / "summary.json").read_text())
    assert set(s["lyapunov"]) >= {"value", "stderr", "second"}
    assert s["n_points"] == 300 and len(s["strobe_x_range"]) == 2
    assert s["regime"] == "chaotic" and "versions" in s and "settings" in s
    assert (out / "attractor.png").exists()
    ch = tmp_path / "chart"
    assert (
        vidi(
            [
                "ueda",
                "chart",
                "--nu",
                "0.9:1.1:4",
                "--B",
                "0.1:0.5:3",
                "--workers",
                "1",
                "--out",
                str(ch),
            ]
        )
        == 0
    )
    s = json.loads((ch / "summary.json").read_text())
    assert s["points"] == 12 and abs(sum(s["fractions"].values()) - 1) < 1e-12
    assert len((ch / "chart.csv").read_text().splitlines()) == 13
    assert vidi(["ueda", "chart", "--nu", "1.2:0.8:10", "--out", str(tmp_path / "x")]) == 2
    assert vidi(["ueda", "attractor", "--nu", "0", "--out", str(tmp_path / "y")]) == 2
