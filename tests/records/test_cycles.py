"""Reversals and cycle counts of a displacement history, against hand-counted truth."""

import numpy as np
import pytest

from fvd_bridge.records.cycles import count_cycles, reversals


def test_reversals_are_the_extremes_moved_away_from_by_more_than_the_hysteresis():
    """A hand-made zigzag 0 -> 10 -> 2 -> 2.1 -> 1.9 -> 8 -> -5 with hysteresis 1 mm:
    the turn at 10 (index 2) and the one at 1.9 (index 5; the 0.1 mm wiggle
    before it is no reversal), then the one at 8 (index 6)."""
    d = np.array([0.0, 5.0, 10.0, 2.0, 2.1, 1.9, 8.0, -5.0])
    assert reversals(d, 1.0).tolist() == [2, 5, 6]
    assert reversals(d, 7.0).tolist() == [2]  # the 6.1 mm climb back is below 7 mm: one long fall
    assert reversals(np.zeros(5)).tolist() == []


def test_a_noisy_sine_has_two_reversals_a_cycle():
    """Five cycles of a 10 mm sine with 0.05 mm noise (the hysteresis
    is 2% of the 20 mm stroke): 10 reversals at the
    sine's extremes, 5 cycles counted."""
    t = np.arange(5000) * 0.001
    d = 10.0 * np.sin(2 * np.pi * t) + np.random.default_rng(0).normal(0.0, 0.05, t.size)
    r = reversals(d)
    assert len(r) == 10
    assert np.all(np.abs(np.abs(d[r]) - 10.0) < 0.5)
    assert count_cycles(d) == pytest.approx(5.0, abs=0.01)  # the ends: a quarter cycle each, to the noise
