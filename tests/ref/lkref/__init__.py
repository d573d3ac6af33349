"""The modules of tests/ref/linkage_ref.py, the general linkage's mpmath reference.

numeric     precision, grid and tolerances; plane vectors, LU, root search,
            Gauss-Legendre, table interpolation
model       units and the YAML description read into bodies, points, joints,
            groups, masses and loads (class Mechanism)
kinematics  the constraint equations, Newton on them, the transfer functions,
            the closed-form seed of the branch (class Kinematics)
dynamics    torque by virtual power and by Newton-Euler, reactions, frame and
            shaking forces; the grid over the cycle, kinks, extrema, means
            (class Linkage)
cli         the JSON output, analyse, the selftest, main

Importing the package sets mpmath to 30 digits before any module computes a
constant.
"""
import mpmath as mp

mp.mp.dps = 30
