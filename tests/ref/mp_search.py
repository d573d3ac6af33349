"""Searches shared by the mpmath references in tests/ref/ (plain, no model)."""
import mpmath as mp


def golden_min(fun, lo, hi, iters):
    """Golden-section search for the minimiser of a unimodal fun on [lo, hi]."""
    gr = (mp.sqrt(5) - 1) / 2
    x1, x2 = hi - gr * (hi - lo), lo + gr * (hi - lo)
    f1, f2 = fun(x1), fun(x2)
    for _ in range(iters):
        if f1 < f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - gr * (hi - lo)
            f1 = fun(x1)
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + gr * (hi - lo)
            f2 = fun(x2)
    return (lo + hi) / 2


def max_on_interval(fn, a, b, points=60):
    """Maximum of fn on [a, b]: the best of `points` + 1 grid values, an
    interior one refined by a root of fn' (numerical derivative)."""
    xs = [a + (b - a) * i / points for i in range(points + 1)]
    ys = [fn(x) for x in xs]
    j = max(range(points + 1), key=lambda i: ys[i])
    if 0 < j < points:
        return fn(mp.findroot(lambda x: mp.diff(fn, x), (xs[j - 1], xs[j + 1]), solver="anderson"))
    return ys[j]
