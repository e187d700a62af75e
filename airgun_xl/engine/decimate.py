"""Thin a long series for a chart without losing its peaks."""
import numpy as np


def minmax_indices(y: np.ndarray, budget: int) -> np.ndarray:
    """Indices of at most ``budget`` points of ``y`` that keep every bucket's min and max.

    The series is cut into buckets of ``ceil(2 n / budget)`` consecutive points; each bucket
    contributes the index of its smallest and of its largest value, in time order. The global
    extremes, and every peak wider than a bucket, survive.

    Parameters
    ----------
    y : numpy.ndarray
    budget : int
        Most points to keep (at least 2).

    Returns
    -------
    numpy.ndarray of int
        Sorted indices; all of them when ``len(y) <= budget``.
    """
    n = len(y)
    if n <= budget:
        return np.arange(n)
    size = -(-2 * n // budget)
    buckets = -(-n // size)
    padded = np.empty(buckets * size)
    padded[:n] = y
    padded[n:] = y[-1]  # the last bucket's padding repeats a real value
    block = padded.reshape(buckets, size)
    nan = np.isnan(block)
    if nan.any():  # NaN marks empty cells: never pick them
        filled = ~nan.all(axis=1)  # a bucket of NaN only gives nothing
        lo = np.argmin(np.where(nan, np.inf, block), axis=1)
        hi = np.argmax(np.where(nan, -np.inf, block), axis=1)
    else:
        filled = np.ones(buckets, dtype=bool)
        lo, hi = np.argmin(block, axis=1), np.argmax(block, axis=1)
    base = np.arange(buckets) * size
    keep = np.concatenate((base[filled] + lo[filled], base[filled] + hi[filled]))
    return np.unique(np.minimum(keep, n - 1))
