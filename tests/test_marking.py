"""Marking strategies select exactly the sets their definitions describe (ties, theta = 0, 1),
and the peaks of a marked estimate are the vertices where it adds up most."""

import numpy as np
import pytest

from ngdual.marking import mark, mark_dorfler, mark_fraction, mark_max, peak_vertices
from ngdual.scene import SceneError

INDICATORS = np.array([1.0, 3.0, 2.0, 3.0, 0.5, 0.0])


def test_max_marks_everything_within_theta_of_the_maximum():
    np.testing.assert_array_equal(mark_max(INDICATORS, 0.5),
                                  [False, True, True, True, False, False])
    # ties with the maximum are all marked, whatever their position
    np.testing.assert_array_equal(mark_max(INDICATORS, 1.0),
                                  [False, True, False, True, False, False])
    assert mark_max(INDICATORS, 0.0).all()
    assert mark_max(np.zeros(4), 0.7).all()  # all equal: every element attains the maximum


def test_fraction_marks_the_theta_share_with_the_largest_indicators():
    indicators = np.array([5.0, 1.0, 4.0, 2.0, 3.0, 0.0, 6.0, 7.0, 8.0, 9.0])
    marked = mark_fraction(indicators, 0.2)
    np.testing.assert_array_equal(np.flatnonzero(marked), [8, 9])
    # ceil(theta N): 0.25 of 10 elements is 3 elements
    assert mark_fraction(indicators, 0.25).sum() == 3
    assert not mark_fraction(indicators, 0.0).any()
    assert mark_fraction(indicators, 1.0).all()


def test_fraction_marks_ties_with_the_last_marked_value():
    # ceil(0.25 * 4) = 1 element, but the largest value is shared by three
    np.testing.assert_array_equal(mark_fraction(np.array([3.0, 1.0, 3.0, 3.0]), 0.25),
                                  [True, False, True, True])
    # ceil(0.2 * 6) = 2: exactly the two elements with 3.0
    np.testing.assert_array_equal(mark_fraction(INDICATORS, 0.2), [False, True, False, True, False,
                                                            False])


def test_dorfler_takes_the_smallest_set_carrying_theta_of_the_bulk():
    indicators = np.sqrt(np.array([50.0, 30.0, 15.0, 5.0]))  # squares sum to 100
    np.testing.assert_array_equal(mark_dorfler(indicators, 0.5), [True, False, False, False])
    np.testing.assert_array_equal(mark_dorfler(indicators, 0.51), [True, True, False, False])
    np.testing.assert_array_equal(mark_dorfler(indicators, 0.8), [True, True, False, False])
    np.testing.assert_array_equal(mark_dorfler(indicators, 0.9), [True, True, True, False])
    # the set is minimal: dropping its smallest element loses the bulk property
    for theta in np.linspace(0.05, 1.0, 20):
        marked = mark_dorfler(indicators, theta)
        assert np.sum(indicators[marked] ** 2) >= theta * np.sum(indicators**2) * (1 - 1e-14)
        smaller = marked.copy()
        smaller[np.flatnonzero(marked)[np.argmin(indicators[marked])]] = False
        assert np.sum(indicators[smaller] ** 2) < theta * np.sum(indicators**2)


def test_dorfler_limits_and_ties():
    assert not mark_dorfler(INDICATORS, 0.0).any()
    # theta = 1 needs every element carrying part of the sum, not the zero one
    np.testing.assert_array_equal(mark_dorfler(INDICATORS, 1.0), INDICATORS > 0)
    # 3^2 = 9 of 23.25 already exceeds 0.3 of the bulk; its tie 3.0 comes with it
    np.testing.assert_array_equal(mark_dorfler(INDICATORS, 0.3), [False, True, False, True, False,
                                                           False])
    assert not mark_dorfler(np.zeros(3), 0.5).any()


@pytest.mark.parametrize("strategy", ["max", "fraction", "dorfler"])
def test_empty_input_gives_an_empty_mark(strategy):
    marked = mark(np.zeros(0), 0.5, strategy)
    assert marked.dtype == bool and marked.shape == (0,)


@pytest.mark.parametrize("strategy", ["max", "fraction", "dorfler"])
def test_marks_do_not_depend_on_the_element_numbering(strategy):
    rng = np.random.default_rng(3)
    indicators = rng.choice([0.5, 1.0, 2.0, 4.0], size=40)
    perm = rng.permutation(40)
    for theta in (0.1, 0.3, 0.6, 0.9):
        np.testing.assert_array_equal(mark(indicators, theta, strategy)[perm],
                                      mark(indicators[perm], theta, strategy))


def test_invalid_input_is_rejected_naming_the_argument():
    with pytest.raises(ValueError, match="theta"):
        mark_max(INDICATORS, 1.5)
    with pytest.raises(SceneError, match=">= 0") as found:
        mark_dorfler(-INDICATORS, 0.5)
    assert found.value.field == "indicators"
    with pytest.raises(ValueError, match="unknown marking"):
        mark(INDICATORS, 0.5, "bulk")


def test_the_indicators_are_passed_by_their_name():
    np.testing.assert_array_equal(mark(indicators=INDICATORS, theta=1.0, strategy="max"),
                                  INDICATORS == INDICATORS.max())



# a fan of six triangles around vertex 0 (a corner singularity) and two more away from it
FAN = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5], [0, 5, 6], [0, 6, 1],
                [1, 2, 7], [4, 5, 8]])


def test_the_peak_of_a_corner_singularity_is_its_vertex_and_by_default_its_ring():
    indicators = np.array([4.0, 4.0, 4.0, 4.0, 4.0, 4.0, 1.0, 1.0])
    marked = mark_dorfler(indicators, 0.9)
    np.testing.assert_array_equal(marked, indicators == 4.0)
    # vertex 0 carries the six marked triangles, each vertex of the ring two: a third of it
    np.testing.assert_array_equal(np.flatnonzero(peak_vertices(FAN, indicators, marked, 0.5)),
                                  [0])
    np.testing.assert_array_equal(np.flatnonzero(peak_vertices(FAN, indicators, marked)),
                                  [0, 1, 2, 3, 4, 5, 6])


def test_the_peaks_are_the_vertices_carrying_their_share_of_the_largest_weight():
    rng = np.random.default_rng(7)
    indicators = rng.pareto(1.0, size=len(FAN))
    marked = mark_dorfler(indicators, 0.9)
    weight = np.zeros(9)
    for triangle, eta in zip(FAN[marked], indicators[marked]):
        weight[triangle] += eta**2
    for share in (0.0, 0.25, 0.5, 1.0):
        np.testing.assert_array_equal(peak_vertices(FAN, indicators, marked, share),
                                      weight >= share * weight.max())
    # the unmarked triangles' indicators do not count
    quiet = np.where(marked, indicators, 100.0)
    np.testing.assert_array_equal(peak_vertices(FAN, quiet, marked),
                                  peak_vertices(FAN, indicators, marked))


def test_nothing_marked_has_no_peaks():
    assert not peak_vertices(FAN, np.ones(len(FAN)), np.zeros(len(FAN), bool)).any()
    assert not peak_vertices(FAN, np.zeros(len(FAN)), np.ones(len(FAN), bool)).any()


def test_peaks_reject_arrays_of_other_lengths():
    with pytest.raises(ValueError, match="one of each per triangle"):
        peak_vertices(FAN, np.ones(3), np.ones(3, bool))
    with pytest.raises(ValueError, match="share"):
        peak_vertices(FAN, np.ones(len(FAN)), np.ones(len(FAN), bool), 1.5)
