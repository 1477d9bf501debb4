"""Tests of inertialab.learn.subclust (spec 000 §8.1.4)."""

from __future__ import annotations

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.learn.subclust import SubtractiveClustering


def _matlab_transcription(X, radii, squash, accept, reject):
    """Direct, loop-based transcription of MATLAB subclust (Chiu 1994) on data already
    normalised to [0, 1]; an independent implementation for the comparison test."""
    n, d = X.shape
    pot = np.zeros(n)
    for i in range(n):
        for j in range(n):
            s = 0.0
            for k in range(d):
                s += ((X[i, k] - X[j, k]) / radii[k]) ** 2
            pot[i] += np.exp(-4.0 * s)
    ref = pot.max()
    centers = []
    find_more = True
    max_idx = int(np.argmax(pot))
    max_pot = pot[max_idx]
    while find_more and max_pot > 0:
        find_more = False
        ratio = max_pot / ref
        if ratio > accept:
            find_more = True
        elif ratio > reject:
            dmin = min(np.sqrt(sum(((X[max_idx, k] - c[k]) / radii[k]) ** 2 for k in range(d)))
                       for c in centers)
            if dmin + ratio >= 1:
                find_more = True
            else:
                pot[max_idx] = 0.0
                max_idx = int(np.argmax(pot))
                max_pot = pot[max_idx]
                find_more = True
                continue
        if find_more:
            c = X[max_idx].copy()
            centers.append(c)
            for i in range(n):
                s = sum(((X[i, k] - c[k]) / (squash * radii[k])) ** 2 for k in range(d))
                pot[i] = max(pot[i] - max_pot * np.exp(-4.0 * s), 0.0)
            max_idx = int(np.argmax(pot))
            max_pot = pot[max_idx]
    return np.array(centers)


def test_three_blobs_give_three_centres_near_the_means():
    rng = np.random.default_rng(1)
    means = np.array([[0.15, 0.2], [0.8, 0.25], [0.45, 0.85]])
    Z = np.vstack([m + 0.03 * rng.standard_normal((60, 2)) for m in means])
    sc = SubtractiveClustering(radius=0.5).fit(Z)
    assert sc.n_clusters_ == 3
    lo, span = Z.min(axis=0), np.ptp(Z, axis=0)
    found = (sc.centers_ - lo) / span
    true = (means - lo) / span
    # each true mean has a centre within 0.05 scaled units (spec 8.1.4); a centre is a data
    # point, and the blob spread is 0.03/0.8 ~ 0.04 scaled, so the densest point is this close.
    for t in true:
        assert np.min(np.linalg.norm(found - t, axis=1)) < 0.05


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_equals_direct_matlab_transcription(seed):
    rng = np.random.default_rng(seed)
    X = rng.random((70, 3))
    X[0] = 0.0
    X[1] = 1.0  # bounds are then exactly [0, 1]
    radii = np.array([0.3, 0.4, 0.5])
    ref = _matlab_transcription(X, radii, 1.25, 0.5, 0.15)
    sc = SubtractiveClustering(radius=radii, bounds=[[0, 0, 0], [1, 1, 1]]).fit(X)
    assert sc.centers_.shape == ref.shape
    np.testing.assert_allclose(sc.centers_, ref, rtol=0, atol=1e-12)


def _grey_zone_case(dx):
    """Two tight groups: 30 points at 0 and 10 points at dx (1-D, bounds [0, 1]).

    With radius 0.5 the second group's potential ratio after subtracting the first
    centre lies between reject and accept for these dx, so the d_min + ratio >= 1 test
    decides."""
    return np.r_[np.zeros(30), np.full(10, dx), 1.0][:, None]


def test_grey_zone_branch_accepts_when_far_and_rejects_when_near():
    far = SubtractiveClustering(radius=0.5, accept=0.9, reject=0.05,
                                bounds=[[0.0], [1.0]]).fit(_grey_zone_case(0.7))
    near = SubtractiveClustering(radius=0.5, accept=0.9, reject=0.05,
                                 bounds=[[0.0], [1.0]]).fit(_grey_zone_case(0.35))
    # far: group 2 potential ratio ~ 10/30 = 0.33 (< accept), distance 0.7/0.5 = 1.4 -> accepted
    assert np.any(np.isclose(far.centers_[:, 0], 0.7))
    # near: ratio after subtraction ~ 0.2 and distance 0.7 in radius units: 0.9 < 1 -> rejected
    assert not np.any(np.isclose(near.centers_[:, 0], 0.35))
    # the rejected candidate's potential was zeroed without subtraction, so the lone
    # point at 1.0 (ratio ~ 1/30 < reject) is never accepted either
    assert near.n_clusters_ == 1


def test_sigma_is_radius_times_range_over_sqrt8():
    rng = np.random.default_rng(3)
    Z = rng.random((50, 2)) * [10.0, 2.0] + [5.0, -1.0]
    sc = SubtractiveClustering(radius=[0.4, 0.6]).fit(Z)
    np.testing.assert_allclose(sc.sigmas_, np.array([0.4, 0.6]) * np.ptp(Z, axis=0) / np.sqrt(8))


def test_bad_parameters_raise():
    with pytest.raises(InputError):
        SubtractiveClustering(accept=0.1, reject=0.5).fit(np.random.default_rng(0).random((5, 2)))
    with pytest.raises(InputError):
        SubtractiveClustering(radius=[0.5, 0.5, 0.5]).fit(np.zeros((5, 2)))
    with pytest.raises(InputError):
        SubtractiveClustering().fit(np.array([[0.0, np.nan]]))
