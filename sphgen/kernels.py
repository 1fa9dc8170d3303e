"""Smoothing kernels as translatable code: w, dw/dr, h dw/dh, (h/r) d2w/(dr dh).

A kernel is a class whose methods ``w(rij, h)``, ``dwdr(rij, h)``, ``gradh(rij, h)`` and
``mixed(rij, h)`` are restricted Python.  Its attributes (``dim``, ``fac``) are folded into
the generated code as constants, so the compiled kernel is specialised on the dimension.
``methods`` go into every module; ``extra_methods`` only into a module whose equations ask
for a pair symbol that calls them (``MIXEDIJ``).
"""
from math import erf, exp, fabs, pi, sqrt


class Kernel:
    """Base class: ``radius_scale`` is the support radius in units of h."""

    radius_scale = 2.0
    name = "kernel"
    # translated into the scene module in this order (a method may call earlier ones)
    methods = ("w", "dwdr", "dwdr_over_r", "gradh")
    extra_methods = ()

    def __init__(self, dim):
        if dim not in (1, 2, 3):
            raise ValueError(f"kernel dimension must be 1, 2 or 3, got {dim!r}")
        self.dim = dim

    def sigma(self, h=1.0):
        """Normalisation fac / h^dim (fac: the kernel's constant for this dimension)."""
        hi = 1.0 / h
        s = self.fac * hi
        if self.dim > 1:
            s = s * hi
        if self.dim > 2:
            s = s * hi
        return s

    def dwdr_over_r(self, rij=1.0, h=1.0):
        """(1/r) dW/dr, so that grad W = dwdr_over_r x_ij; 0 at r = 0, where dW/dr = 0 (a
        kernel with a closed form that needs no division by r overrides this).  No branch:
        r is floored at 1e-12, so the pair loop can be vectorised."""
        return self.dwdr(rij, h) / (rij if rij > 1e-12 else 1e-12)

    def gradh(self, rij=1.0, h=1.0):
        """h dW/dh = -(d W + r dW/dr) (W = h^-d f(r/h))."""
        return -(self.dim * self.w(rij, h) + rij * self.dwdr(rij, h))

    def mixed(self, rij=1.0, h=1.0):
        """(h/r) d2W/(dr dh) = -((d + 1) W'/r + W''); the gradient of h dW/dh is this times x_ij.

        At r -> 0, W'/r -> W''(0), so the value there is -(d + 2) W''(0).  Needs ``d2wdr2``."""
        if rij < 1e-12 * h:
            return -(self.dim + 2.0) * self.d2wdr2(0.0, h)
        return -((self.dim + 1.0) * self.dwdr(rij, h) / rij + self.d2wdr2(rij, h))

    def constants(self):
        """Attributes folded into the generated code."""
        return {"dim": self.dim, "fac": self.fac}

    def __repr__(self):
        return f"{type(self).__name__}(dim={self.dim})"


class QuinticSpline(Kernel):
    """Quintic spline, support 3h (Adepu & Ramachandran (2024), sec. 2.2; Morris et al. 1997)."""

    radius_scale = 3.0
    name = "quintic"
    methods = ("sigma", "w", "dwdr", "dwdr_over_r", "gradh")
    extra_methods = ("d2wdr2", "mixed")

    def __init__(self, dim):
        super().__init__(dim)
        self.fac = {1: 1.0 / 120.0, 2: 7.0 / (478.0 * pi), 3: 1.0 / (120.0 * pi)}[dim]

    def w(self, rij=1.0, h=1.0):
        """W(r, h) = sigma/h^d [(3-q)+^5 - 6(2-q)+^5 + 15(1-q)+^5], q = r/h, (x)+ = max(x, 0).

        No branch on the piece of q: (x)+ = (x + |x|)/2 exactly, and a piece that is off adds an
        exact 0 (a neighbour's piece is random, so branches on it are mispredicted)."""
        q = rij * (1.0 / h)
        t3 = 0.5 * (3.0 - q + fabs(3.0 - q))
        t2 = 0.5 * (2.0 - q + fabs(2.0 - q))
        t1 = 0.5 * (1.0 - q + fabs(1.0 - q))
        t3s = t3 * t3
        t2s = t2 * t2
        t1s = t1 * t1
        val = t3s * t3s * t3 - 6.0 * t2s * t2s * t2 + 15.0 * t1s * t1s * t1
        return self.sigma(h) * val

    def dwdr(self, rij=1.0, h=1.0):
        """dW/dr = -5 sigma/h^(d+1) [(3-q)+^4 - 6(2-q)+^4 + 15(1-q)+^4], branch-free as w."""
        hi = 1.0 / h
        q = rij * hi
        a = 0.5 * (3.0 - q + fabs(3.0 - q))
        b = 0.5 * (2.0 - q + fabs(2.0 - q))
        c = 0.5 * (1.0 - q + fabs(1.0 - q))
        a2 = a * a
        b2 = b * b
        c2 = c * c
        val = a2 * a2 - 6.0 * b2 * b2 + 15.0 * c2 * c2
        return -5.0 * self.sigma(h) * val * hi

    def d2wdr2(self, rij=1.0, h=1.0):
        """d2W/dr2 = 20 sigma/h^(d+2) [(3-q)^3 - 6(2-q)^3 + 15(1-q)^3] on the pieces of q."""
        q = rij / h
        a = 3.0 - q
        b = 2.0 - q
        c = 1.0 - q
        val = 0.0
        if q < 1.0:
            val = a * a * a - 6.0 * b * b * b + 15.0 * c * c * c
        elif q < 2.0:
            val = a * a * a - 6.0 * b * b * b
        elif q < 3.0:
            val = a * a * a
        return 20.0 * self.sigma(h) * val / (h * h)


class WendlandQuinticC2(Kernel):
    """Wendland C2 ("quintic"), support 2h: W = a_d/h^d (1 - q/2)^4 (1 + 2q)
    (Wendland 1995; Kincl et al. (2025), sec. 2, with the (1 + 2q) factor that
    normalises, where the thesis' eq. 1.6 prints (1 + 4q))."""

    radius_scale = 2.0
    name = "wendland"
    methods = ("sigma", "w", "dwdr", "dwdr_over_r", "gradh")
    extra_methods = ("mixed",)

    def __init__(self, dim):
        super().__init__(dim)
        self.fac = {1: 0.75, 2: 7.0 / (4.0 * pi), 3: 21.0 / (16.0 * pi)}[dim]

    def w(self, rij=1.0, h=1.0):
        """W(r, h) = a_d/h^d (1 - q/2)^4 (1 + 2q) for q = r/h < 2."""
        q = rij * (1.0 / h)
        val = 0.0
        if q < 2.0:
            t = 1.0 - 0.5 * q
            val = t * t * t * t * (1.0 + 2.0 * q)
        return self.sigma(h) * val

    def dwdr(self, rij=1.0, h=1.0):
        """dW/dr = -5 a_d/h^(d+1) q (1 - q/2)^3 for q < 2."""
        hi = 1.0 / h
        q = rij * hi
        val = 0.0
        if q < 2.0:
            t = 1.0 - 0.5 * q
            val = -5.0 * q * t * t * t
        return self.sigma(h) * val * hi

    def dwdr_over_r(self, rij=1.0, h=1.0):
        """(1/r) dW/dr = -5 a_d/h^(d+2) (1 - q/2)^3 for q < 2: smooth, no division by r (the q
        of dW/dr cancels), so grad W = dwdr_over_r x_ij with one reciprocal of h per pair."""
        hi = 1.0 / h
        q = rij * hi
        val = 0.0
        if q < 2.0:
            t = 1.0 - 0.5 * q
            val = -5.0 * t * t * t
        return self.sigma(h) * val * hi * hi

    def mixed(self, rij=1.0, h=1.0):
        """(h/r) d2W/(dr dh) = 5 a_d/h^(d+2) (1 - q/2)^2 ((d + 2) - (d + 5) q/2) for q < 2.

        The gradient of h dW/dh is this times x_ij, so no division by r is needed.  In 2D it
        is -35/(8 pi h^4) (1 - q/2)^2 (7q - 8): Kincl et al. (2023), sec. 3.5, print 35/(4 pi h^4),
        twice too large; their 3D formula -105/(16 pi h^5) (1 - q/2)^2 (4q - 5) agrees with this.
        """
        hi = 1.0 / h
        q = rij * hi
        val = 0.0
        if q < 2.0:
            t = 1.0 - 0.5 * q
            val = 5.0 * t * t * ((self.dim + 2.0) - 0.5 * (self.dim + 5.0) * q)
        return self.sigma(h) * val * hi * hi


GAUSSIAN_CUT = 3.0
"""Support of the truncated Gaussian in units of h: W is shifted by its value exp(-9) there."""


class TruncatedGaussian(Kernel):
    """Gaussian of Kincl's thesis (2023), eq. 1.5, truncated at 3h: W = a_d/h^d (exp(-q^2) -
    exp(-9)) for q = r/h < 3, 0 beyond; a_d normalises the truncated kernel in 1, 2 and 3D.

    The thesis prints (2 pi h^2)^(-d/2) exp(+r^2/h^2): the sign of the exponent is lost and that
    prefactor normalises exp(-r^2/(2 h^2)).  This keeps the printed exponent's scale (exp(-r^2/h^2),
    the width of the Gaussian of Monaghan & Gingold (1983), which the thesis cites) with its sign
    and a normalisation that fits it; the thesis' infinite support is cut at 3h (the tail beyond
    holds 2e-5 (1D) to 4e-4 (3D) of the mass), and the shift by exp(-9) makes W continuous
    there (docs/shtc.md, "Thesis sec. 1.4 integrators and kernels")."""

    radius_scale = GAUSSIAN_CUT
    name = "gaussian"
    methods = ("sigma", "w", "dwdr", "dwdr_over_r", "gradh")
    extra_methods = ("mixed",)

    def __init__(self, dim):
        super().__init__(dim)
        tail = exp(-GAUSSIAN_CUT ** 2)
        mass = {1: sqrt(pi) * erf(3.0) - 6.0 * tail,
                2: pi * (1.0 - 10.0 * tail),
                3: pi ** 1.5 * erf(3.0) - 42.0 * pi * tail}[dim]
        self.fac = 1.0 / mass

    def w(self, rij=1.0, h=1.0):
        """W = a_d/h^d (exp(-q^2) - exp(-9)) for q < 3 (1.2340980408667956e-4 = exp(-9))."""
        q = rij * (1.0 / h)
        val = 0.0
        if q < 3.0:
            val = exp(-q * q) - 1.2340980408667956e-4
        return self.sigma(h) * val

    def dwdr(self, rij=1.0, h=1.0):
        """dW/dr = -2 a_d/h^(d+1) q exp(-q^2) for q < 3."""
        hi = 1.0 / h
        q = rij * hi
        val = 0.0
        if q < 3.0:
            val = -2.0 * q * exp(-q * q)
        return self.sigma(h) * val * hi

    def dwdr_over_r(self, rij=1.0, h=1.0):
        """(1/r) dW/dr = -2 a_d/h^(d+2) exp(-q^2) for q < 3: no division by r."""
        hi = 1.0 / h
        q = rij * hi
        val = 0.0
        if q < 3.0:
            val = -2.0 * exp(-q * q)
        return self.sigma(h) * val * hi * hi

    def mixed(self, rij=1.0, h=1.0):
        """(h/r) d2W/(dr dh) = a_d/h^(d+2) exp(-q^2) (2d + 4 - 4q^2) for q < 3."""
        hi = 1.0 / h
        q = rij * hi
        val = 0.0
        if q < 3.0:
            val = exp(-q * q) * (2.0 * self.dim + 4.0 - 4.0 * q * q)
        return self.sigma(h) * val * hi * hi


class QuarticSpline(Kernel):
    """M5 quartic spline of Kincl's thesis (2023), eqs. 1.8-1.9 (Monaghan 1985), support 2.5h:
    W = a_d/h^d [(5/2 - q)+^4 - 5 (3/2 - q)+^4 + 10 (1/2 - q)+^4], a_d = 1/24, 96/(1199 pi),
    1/(20 pi) in 1, 2, 3D (as printed)."""

    radius_scale = 2.5
    name = "quartic"
    methods = ("sigma", "w", "dwdr", "dwdr_over_r", "gradh")
    extra_methods = ("d2wdr2", "mixed")

    def __init__(self, dim):
        super().__init__(dim)
        self.fac = {1: 1.0 / 24.0, 2: 96.0 / (1199.0 * pi), 3: 1.0 / (20.0 * pi)}[dim]

    def w(self, rij=1.0, h=1.0):
        """W on the three pieces of eq. 1.8 at once, branch-free as the quintic: (x)+ = (x + |x|)/2."""
        q = rij * (1.0 / h)
        a = 0.5 * (2.5 - q + fabs(2.5 - q))
        b = 0.5 * (1.5 - q + fabs(1.5 - q))
        c = 0.5 * (0.5 - q + fabs(0.5 - q))
        a2 = a * a
        b2 = b * b
        c2 = c * c
        return self.sigma(h) * (a2 * a2 - 5.0 * b2 * b2 + 10.0 * c2 * c2)

    def dwdr(self, rij=1.0, h=1.0):
        """dW/dr = -4 a_d/h^(d+1) [(5/2 - q)+^3 - 5 (3/2 - q)+^3 + 10 (1/2 - q)+^3]."""
        hi = 1.0 / h
        q = rij * hi
        a = 0.5 * (2.5 - q + fabs(2.5 - q))
        b = 0.5 * (1.5 - q + fabs(1.5 - q))
        c = 0.5 * (0.5 - q + fabs(0.5 - q))
        return -4.0 * self.sigma(h) * (a * a * a - 5.0 * b * b * b + 10.0 * c * c * c) * hi

    def d2wdr2(self, rij=1.0, h=1.0):
        """d2W/dr2 = 12 a_d/h^(d+2) [(5/2 - q)+^2 - 5 (3/2 - q)+^2 + 10 (1/2 - q)+^2]."""
        hi = 1.0 / h
        q = rij * hi
        a = 0.5 * (2.5 - q + fabs(2.5 - q))
        b = 0.5 * (1.5 - q + fabs(1.5 - q))
        c = 0.5 * (0.5 - q + fabs(0.5 - q))
        return 12.0 * self.sigma(h) * (a * a - 5.0 * b * b + 10.0 * c * c) * hi * hi


KERNELS = {"quintic": QuinticSpline, "wendland": WendlandQuinticC2, "gaussian": TruncatedGaussian,
           "quartic": QuarticSpline}


def get_kernel(name, dim):
    """Kernel by name, e.g. ``get_kernel('quintic', 2)``."""
    try:
        return KERNELS[name](dim)
    except KeyError:
        raise ValueError(f"unknown kernel {name!r}; known: {', '.join(KERNELS)}") from None
