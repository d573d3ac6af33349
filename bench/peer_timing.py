"""Timing shared by the Python peers (bench/peer_*.py)."""
import timeit


def timed(fn):
    """Median seconds per call over 5 repeats (timeit's autorange sets the calls per repeat), and fn's value."""
    t = timeit.Timer(fn)
    number, _ = t.autorange()
    runs = sorted(t.repeat(repeat=5, number=number))
    return runs[2] / number, fn()
