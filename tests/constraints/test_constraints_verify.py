"""Soundness of certify()/require(): good laws pass, bad laws are errors with the location."""

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize

from constraints import (
    DEFAULT_GRID,
    DEFAULT_TOLERANCE,
    Box,
    Certificate,
    CertificateError,
    bernstein_coefficients,
    certify,
    grid_minimum,
    require,
    to_physical,
)

BOX = Box(1e-3, 1.0)
ALL = ("non_adhesion", "dissipativity", "monotone_elastic")


def _physical(x, library):
    return to_physical(np.asarray(x, dtype=float), library, BOX)


def test_default_grid_has_a_million_points():
    assert DEFAULT_GRID**2 >= 1_000_000
    library = [(1.5, 0), (1.5, 1)]
    cert = certify(_physical([1.0, 0.3], library), library, BOX)
    assert "grid(1001x1001)" in cert.method
    for info in cert.conditions.values():
        assert info["grid_points"] >= 1_000_000


@pytest.mark.parametrize(
    ("library", "x"),
    [
        ([(1.5, 0), (1.5, 1)], [1e5, 3e4]),  # Hunt-Crossley
        ([(1, 0), (0, 1)], [2e4, 50.0]),  # Kelvin-Voigt
        ([(1, 0), (0, 1), (1, 1)], [1.0, 0.5, -0.5]),  # negative term, still dissipative
        ([(1.5, 0), (1, 0), (2, 0), (1, 1)], [1.0, 0.5, -0.4, 0.2]),  # non-monotone terms
    ],
)
def test_non_negative_laws_are_certified(library, x):
    cert = certify(_physical(x, library), library, BOX, ALL)
    assert cert.holds, cert.conditions
    assert cert.worst_violation == 0.0
    assert require(cert) is cert
    json.dumps(cert.as_dict())  # JSON-ready


def test_a_certificate_reads_back_from_its_dict():
    """``from_dict`` inverts ``as_dict``, also through JSON; a result's document (without
    the tolerance and the force scale, a number not finite as null) reads too."""
    library = [(1.5, 0), (1.5, 1)]
    cert = certify(_physical([1e5, 3e4], library), library, BOX, ALL, grid=21)
    assert Certificate.from_dict(cert.as_dict()) == cert
    assert Certificate.from_dict(json.loads(json.dumps(cert.as_dict()))) == cert
    doc = {k: v for k, v in cert.as_dict().items() if k not in ("tolerance", "force_scale")}
    back = Certificate.from_dict(json.loads(json.dumps({**doc, "worst_violation": None})))
    assert back.tolerance == DEFAULT_TOLERANCE and back.force_scale == 0.0
    assert np.isnan(back.worst_violation) and back.conditions == cert.conditions
    assert back.domain == cert.domain and back.holds is cert.holds


def test_interior_adhesion_is_found_and_located():
    # P = s * ((s - 0.5)**2 + (u - 0.5)**2 - 0.01) with s = zeta/Z, u = zd/V: negative in a
    # small disc around (0.5, 0.5), i.e. strictly inside the box.
    library = [(3, 0), (2, 0), (1, 2), (1, 1), (1, 0)]
    c = _physical([1.0, -1.0, 1.0, -1.0, 0.49], library)
    cert = certify(c, library, BOX, "non_adhesion")
    info = cert.conditions["non_adhesion"]
    assert not cert.holds and not info["holds"]
    assert info["bernstein_min"] < 0.0

    def p(v):
        return v[0] * ((v[0] - 0.5) ** 2 + (v[1] - 0.5) ** 2 - 0.01)

    best = minimize(p, [0.5, 0.5], method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-14})
    assert info["grid_min"] == pytest.approx(best.fun, rel=1e-4)
    # grid spacing 1e-3 of the box: location within two grid steps of the true minimiser
    assert info["location"]["zeta"] == pytest.approx(best.x[0] * BOX.zeta_max, abs=2e-6)
    assert info["location"]["zd"] == pytest.approx(best.x[1] * BOX.zd_max, abs=2e-3)
    assert cert.worst_violation == pytest.approx(-best.fun / cert.force_scale, rel=1e-4)
    with pytest.raises(CertificateError, match=r"non_adhesion violated: .* at zeta=0.00051") as e:
        require(cert)
    assert e.value.condition == "non_adhesion"
    assert e.value.violation == pytest.approx(cert.worst_violation)
    assert isinstance(e.value, ValueError)


def test_dissipativity_violation_at_corner():
    # D = P(z, zd) - P(z, 0) = u (0.5 - s) < 0 for s > 0.5; worst at the far corner.
    library = [(1, 0), (0, 1), (1, 1)]
    cert = certify(_physical([1.0, 0.5, -1.0], library), library, BOX)
    assert cert.conditions["non_adhesion"]["holds"]
    info = cert.conditions["dissipativity"]
    assert not info["holds"]
    assert info["grid_min"] == pytest.approx(-0.5)
    assert info["location"] == {"zeta": BOX.zeta_max, "zd": BOX.zd_max}
    with pytest.raises(CertificateError, match="dissipativity violated") as e:
        require(cert)
    assert e.value.location == (BOX.zeta_max, BOX.zd_max)


def test_margin_and_monotone_violations():
    library = [(1, 0), (2, 0), (0, 1)]
    c = _physical([1.0, -0.8, 10.0], library)  # dP/dzeta(., 0) < 0 for s > 0.625
    cert = certify(c, library, BOX, ALL, margin=9.0)  # Q = 10 N s/m >= 9
    assert cert.conditions["dissipativity"]["holds"]
    assert not cert.conditions["monotone_elastic"]["holds"]
    assert cert.conditions["monotone_elastic"]["location"]["zeta"] == pytest.approx(BOX.zeta_max)
    with pytest.raises(CertificateError, match="monotone_elastic violated"):
        require(cert)
    cert = certify(c, library, BOX, "dissipativity", margin=11.0)  # Q = 10 < 11
    assert cert.conditions["dissipativity"]["grid_min"] == pytest.approx(-1.0)


def test_inconclusive_bernstein_is_an_error_too():
    # (s - u)**2 >= 0 vanishes on the diagonal: the grid finds no violation but no finite
    # elevation certifies it, and an uncertified law is rejected.
    library = [(2, 0), (1, 1), (0, 2)]
    c = _physical([1.0, -2.0, 1.0], library)
    cert = certify(c, library, BOX, "non_adhesion", elevation=6)
    info = cert.conditions["non_adhesion"]
    assert info["grid_min"] >= -1e-12 and info["bernstein_min"] < 0.0
    assert not cert.holds and cert.worst_violation <= 1e-15  # round-off only
    with pytest.raises(CertificateError, match="non_adhesion not certified"):
        require(cert)


def test_chunking_does_not_change_the_result():
    library = [(3, 0), (2, 0), (1, 2), (1, 1), (1, 0)]
    c = _physical([1.0, -1.0, 1.0, -1.0, 0.49], library)
    whole = grid_minimum(c, library, BOX, grid=(301, 211), chunk_rows=1000)
    chunked = grid_minimum(c, library, BOX, grid=(301, 211), chunk_rows=7)
    assert whole == chunked


def test_bad_arguments():
    library = [(1, 0)]
    with pytest.raises(ValueError, match="unknown condition"):
        certify([1.0], library, BOX, ("positivity",))
    with pytest.raises(ValueError, match="grid"):
        certify([1.0], library, BOX, grid=1)
    with pytest.raises(ValueError, match="shape"):
        certify([1.0, 2.0], library, BOX)


@settings(max_examples=40, deadline=None)
@given(
    x=st.lists(st.floats(-1e3, 1e3), min_size=5, max_size=5),
    elevation=st.integers(0, 4),
    condition=st.sampled_from(ALL),
)
def test_bernstein_minimum_is_a_lower_bound(x, elevation, condition):
    # soundness of the certificate: min Bernstein coefficient <= min of the polynomial
    library = [(1, 0), (1.5, 0), (0, 1), (1.5, 1), (0.5, 2)]
    c = _physical(x, library)
    bern = bernstein_coefficients(c, library, BOX, condition, elevation=elevation)
    value, _ = grid_minimum(c, library, BOX, condition, grid=(101, 101))
    assert bern.min() <= value + 1e-9 * (1.0 + np.sum(np.abs(x)))
