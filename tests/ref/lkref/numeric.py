"""Numbers for the linkage reference: precision-dependent constants and the
small numerical tools (plane vectors as tuples, dense LU, Illinois root
search, Gauss-Legendre rules, table interpolation). mpmath is at 30 digits
(set by the package's __init__) before anything here is computed."""
import mpmath as mp

MPF = mp.mpf
GRID = 720
G_STD = MPF("9.80665")
TOL = MPF(10) ** -20
KINK_GAP = MPF(10) ** -25         # one-sided values next to a load's kink


# ---- plane vectors as tuples ---------------------------------------------------
def add(a, b): return (a[0] + b[0], a[1] + b[1])
def sub(a, b): return (a[0] - b[0], a[1] - b[1])
def mul(k, a): return (k * a[0], k * a[1])
def dot(a, b): return a[0] * b[0] + a[1] * b[1]
def cross(a, b): return a[0] * b[1] - a[1] * b[0]
def perp(a): return (-a[1], a[0])
def rot(t, v): c, s = mp.cos(t), mp.sin(t); return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def lu_factor(rows, n):
    """Dense LU with partial pivoting of a square system given as dict rows."""
    a = [[r.get(c, MPF(0)) for c in range(n)] for r in rows]
    assert len(a) == n, "constraint count %d != unknowns %d" % (len(a), n)
    piv = list(range(n))
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(a[i][k]))
        if a[p][k] == 0:
            raise ArithmeticError("singular system (column %d)" % k)
        a[k], a[p], piv[k], piv[p] = a[p], a[k], piv[p], piv[k]
        for i in range(k + 1, n):
            f = a[i][k] / a[k][k]
            a[i][k] = f
            for j in range(k + 1, n):
                a[i][j] -= f * a[k][j]
    return a, piv


def lu_solve(lu, b):
    a, piv = lu
    n = len(a)
    y = [b[piv[i]] for i in range(n)]
    for i in range(n):
        y[i] -= sum((a[i][j] * y[j] for j in range(i)), MPF(0))
    for i in reversed(range(n)):
        y[i] = (y[i] - sum((a[i][j] * y[j] for j in range(i + 1, n)), MPF(0))) / a[i][i]
    return y


def illinois(f, a, b, fa=None, fb=None, tol=MPF(10) ** -27):
    """Root of f in the bracket [a, b] (regula falsi, Illinois variant)."""
    fa = f(a) if fa is None else fa
    fb = f(b) if fb is None else fb
    if fa == 0 or fb == 0:
        return a if fa == 0 else b
    if fa * fb > 0:
        raise ArithmeticError("no sign change in [%s, %s]" % (a, b))
    c_old = a
    for _ in range(300):
        c = (a * fb - b * fa) / (fb - fa)
        fc = f(c)
        if fc == 0 or abs(c - c_old) < tol:
            return c
        if fc * fb < 0:
            a, fa = b, fb
        else:
            fa /= 2
        b, fb, c_old = c, fc, c
    raise ArithmeticError("Illinois did not converge")


def gauss_legendre(n):
    """Nodes and weights on [-1, 1] (Newton on P_n from Chebyshev guesses)."""
    xs, ws = [], []
    for i in range(1, n + 1):
        x = mp.cos(mp.pi * (i - MPF(1) / 4) / (n + MPF(1) / 2))
        for _ in range(100):
            p0, p1 = MPF(1), x
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
            dp = n * (x * p1 - p0) / (x * x - 1)
            dx = p1 / dp
            x -= dx
            if abs(dx) < MPF(10) ** -28:
                break
        xs.append(x)
        ws.append(2 / ((1 - x * x) * dp * dp))
    return xs, ws


GL = {n: gauss_legendre(n) for n in (16, 24)}


def interp(rows, s):
    if s <= rows[0][0]:
        return rows[0][1]
    for (x0, y0), (x1, y1) in zip(rows, rows[1:]):
        if s <= x1:
            return y0 + (y1 - y0) * (s - x0) / (x1 - x0)
    return rows[-1][1]
