"""A fold keeps what it computes of read-only arrays: the same values as computed afresh,
the same object asked again, nothing for a writable array, nothing across a copy."""

import copy
import pickle

import numpy as np
import pytest

from discovery.vibroimpact.verify.fold import make_fold


@pytest.fixture
def fold():
    period = 0.04
    td = np.arange(0.0, 0.4, 1e-3) + 3e-4
    return make_fold(td, 0.011, 1, period, (td[0], td[-1]))


def _read_only(a):
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


def test_kept_values_equal_fresh_ones(fold):
    rng = np.random.default_rng(1)
    z = _read_only(rng.normal(size=fold.idx.size))
    fresh = fold._bin_means(z)
    a = fold.average(z)
    assert np.array_equal(a, fresh) and not a.flags.writeable
    assert fold.average(z) is a  # asked again: the kept object
    p = fold.positive_phases(z)
    assert fold.positive_phases(z) is p
    on = fresh > 0.0
    runs = np.diff(np.concatenate([[0], on.astype(np.int8), [0]]))
    first, last = np.flatnonzero(runs == 1), np.flatnonzero(runs == -1) - 1
    assert np.array_equal(p, np.column_stack([fold.phase[first], fold.phase[last]]))


def test_a_writable_array_is_computed_each_time(fold):
    z = np.linspace(-1.0, 1.0, fold.idx.size)
    a, b = fold.average(z), fold.average(z)
    assert a is not b and np.array_equal(a, b) and a.flags.writeable
    z[:] = 0.0  # changed in place: the next mean sees it
    assert np.all(fold.average(z) == 0.0)


def test_an_entry_answers_only_its_own_array(fold):
    z = _read_only(np.ones(fold.idx.size))
    fold.average(z)
    # an entry whose array is another one (as a copied fold's could be) is not used
    key = ("average", id(z))
    other = _read_only(np.zeros(fold.idx.size))
    fold._kept._d[("average", id(other))] = (z, fold._kept._d[key][1])
    assert np.all(fold.average(other) == 0.0)


def test_what_a_fold_keeps_stays_in_its_process(fold):
    z = _read_only(np.ones(fold.idx.size))
    fold.average(z)
    assert "_kept" in fold.__dict__
    for clone in (pickle.loads(pickle.dumps(fold)), copy.copy(fold)):
        assert "_kept" not in clone.__dict__
        assert np.array_equal(clone.average(z), fold.average(z))
