"""Contact between separate bodies: a normal force that pushes and never pulls.

Two solid bodies held in separate arrays see each other only through this force, so a
contact that opens carries no tension (the bodies part freely after a rebound).  The
paper (Adepu & Ramachandran 2021, section 4.6) does not say how its rings interact; the
choice is documented in docs/ctvf.md ("Colliding rings").
"""
from sphgen.equation import Equation


class ContactForce(Equation):
    """du_a/dt += k max(0, d0 - r_ab) x_ab / (r_ab m_a) for particles b of another body: a
    linear normal spring without tension or damping (the normal spring of Cundall & Strack
    1979).  ``d0``: contact distance (the particle spacing); ``k``: stiffness, force per
    unit overlap (per unit depth in 2D).  Antisymmetric pair by pair (linear momentum is
    conserved) and conservative: its energy is sum over pairs of k (d0 - r)^2 / 2
    (:func:`contact_energy`).  Adds to ``au, av, aw``: after the equation that initialises
    them."""

    positive = ("k", "d0")

    def __init__(self, dest, sources, k=1.0, d0=1.0):
        super().__init__(dest, sources, k=k, d0=d0)

    def loop(self, d_idx, d_au, d_av, d_aw, d_m, s_idx, XIJ, RIJ):
        if RIJ < self.d0 and RIJ > 1e-12 * self.d0:
            f = self.k * (self.d0 - RIJ) / (RIJ * d_m[d_idx])
            d_au[d_idx] += f * XIJ[0]
            d_av[d_idx] += f * XIJ[1]
            d_aw[d_idx] += f * XIJ[2]


def _box_distance(x, lo, hi):
    """Distance of each point of ``x`` (n, dim) to the box [lo, hi]."""
    import numpy as np
    return np.linalg.norm(np.clip(lo - x, 0.0, None) + np.clip(x - hi, 0.0, None), axis=1)


def contact_energy(xa, xb, k, d0, block=512):
    """(energy, gap): the sum over pairs (a in body A, b in body B) with r_ab < d0 of
    k (d0 - r_ab)^2 / 2, and the smallest distance between the two bodies (numpy; ``xa``,
    ``xb``: (n, dim) positions).  Exact: only particles closer to the other body's bounding
    box than an upper bound of the gap (and than d0) can be in either, the others are
    skipped."""
    import numpy as np
    xa, xb = np.asarray(xa, float), np.asarray(xb, float)
    da = _box_distance(xa, xb.min(axis=0), xb.max(axis=0))
    db = _box_distance(xb, xa.min(axis=0), xa.max(axis=0))
    a0 = xa[np.argmin(da)]
    bound = max(float(np.min(np.linalg.norm(xb - a0, axis=1))), d0)
    near_a, near_b = xa[da <= bound], xb[db <= bound]
    energy, gap = 0.0, float("inf")
    for start in range(0, len(near_a), block):
        r = np.linalg.norm(near_a[start:start + block, None, :] - near_b[None, :, :], axis=-1)
        gap = min(gap, float(r.min()))
        over = np.clip(d0 - r, 0.0, None)
        energy += 0.5 * k * float(np.sum(over * over))
    return energy, gap
