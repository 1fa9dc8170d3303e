"""Plane Couette flow: the top plate moves at U, EDAC with Adami walls, periodic in x.

The channel of :mod:`sphgen.applications.poiseuille` (plates at y = 0 and y = d = 1, three
layers of wall particles each, periodic over d, ``--ny`` particles across, h = dx,
c0 = 10 U, rho0 = 1, nu = U d / Re with ``--re`` default 1) without body force: the top
wall carries the prescribed velocity ``uw = U`` (a *moving* wall in the sense of
:mod:`sphgen.equations.walls`; the bottom wall is at rest and has no velocity arrays in
the generated code).  The fluid starts at rest; the exact transient is
u(y, t) = U y/d + sum_n 2U (-1)^n/(n pi) sin(n pi y/d) e^{-n^2 pi^2 nu t/d^2}
(Morris, Fox & Zhu 1997 eq. 22 with the sign of their series for a top plate moving at U),
which reaches the linear profile to 1e-4 U after t = 0.9 d^2/nu; default final time
1.5.  ``results.json`` holds the largest deviation of the row-mean u from the linear
profile (and from the transient) relative to U; ``profile.png`` plots them.
"""
from math import pi

import numpy as np

from sphgen.app import Application

from .poiseuille import D, UMAX, ChannelFlow


class Couette(ChannelFlow, Application):
    """Couette flow, moving top wall, EDAC with Adami no-slip walls, periodic in x."""

    tf = 1.5   # d^2/nu at the default Re = 1
    moving_top = True

    def steady(self, y):
        return UMAX * y / D

    def exact(self, y, t, terms=200):
        u = self.steady(y)
        for n in range(1, terms + 1):
            u = u + 2.0 * UMAX * (-1) ** n / (n * pi) * np.sin(n * pi * y / D) * \
                np.exp(-n * n * pi * pi * self.nu * t / (D * D))
        return u
