"""The thread parts of a generated module: every loop over an array (passes, stages, the
guard's sweeps) runs particles ``parts[k] .. parts[k+1]-1`` on thread k, cut so that each
part holds about the same neighbour candidates (plus a few per particle), not the same
number of particles: a free surface or a finer region leaves one side with fewer pairs."""
import numpy as np
import pytest

from sphgen.equation import Equation, Group
from sphgen.equations.basic import SummationDensity
from sphgen.scene import Scene

from conftest import lattice_cloud

WEIGHT = 4      # PART_WEIGHT of the template: a particle's own work, in candidates


def _scene(threads, with_wall=False):
    """An open 16 x 16 cloud whose second half (in index order: the right half) has h = 2 dx,
    so several times the neighbours of the first half."""
    fluid = lattice_cloud("fluid", nx=16, seed=4)
    fluid.h[fluid.n // 2:] *= 2.0
    arrays = [fluid]
    if with_wall:         # a strip above the fluid; no pass has it as destination: equal parts
        wall = lattice_cloud("wall", nx=16, seed=5)
        wall.y[:] += 1.0
        arrays.append(wall)
    sc = Scene(arrays, [Group([SummationDensity("fluid", [a.name for a in arrays])])], dim=2,
               threads=threads, outputs={"fluid": ["rho"]})
    sc.update_nnps()
    sc.compute(0, 0.0, 0.0)
    return sc


def _work(sc, lo, hi):
    """Candidates of the fluid's lists over particles lo..hi-1, plus WEIGHT per particle."""
    total = WEIGHT * (hi - lo)
    for src in [pa.name for pa in sc.arrays]:
        starts, ends, _, _ = sc.nnps.rows("fluid", src)
        total += int(np.sum(ends[lo:hi] - starts[lo:hi]))
    return total


@pytest.mark.parametrize("threads", [2, 3])
def test_parts_balance_the_candidates_not_the_particles(threads):
    sc = _scene(threads, with_wall=True)
    parts = sc.engine.parts("fluid")
    n = sc.by_name["fluid"].n
    assert len(parts) == threads + 1 and parts[0] == 0 and parts[-1] == n
    assert all(a < b for a, b in zip(parts, parts[1:]))
    work = [_work(sc, a, b) for a, b in zip(parts, parts[1:])]
    longest = max(_work(sc, i, i + 1) for i in range(n))
    assert max(work) - min(work) <= longest, work
    equal = [n * k // threads for k in range(threads + 1)]
    assert parts != equal                      # the dense half gets fewer particles
    equal_work = [_work(sc, a, b) for a, b in zip(equal, equal[1:])]
    assert max(equal_work) > 1.1 * max(work), (work, equal_work)   # equal counts: worse
    # an array no pass walks from is cut in equal counts
    wall_n = sc.by_name["wall"].n
    assert sc.engine.parts("wall") == [wall_n * k // threads for k in range(threads + 1)]


def test_parts_follow_the_thread_count_and_do_not_change_results():
    one, two = _scene(1), _scene(2)
    n = one.by_name["fluid"].n
    assert one.engine.parts("fluid") == [0, n]
    np.testing.assert_array_equal(one.by_name["fluid"].rho, two.by_name["fluid"].rho)
    two.set_threads(1)
    assert two.engine.parts("fluid") == [0, n]
    two.set_threads(2)
    assert two.engine.parts("fluid")[1] not in (0, n // 2, n)


class _Visit(Equation):
    """Counts the times a pass computes each particle (no initialize: every visit adds)."""

    def loop(self, d_idx, d_visits, s_idx, s_m, WIJ):
        d_visits[d_idx] += 0.0 * WIJ

    def post_loop(self, d_idx, d_visits):
        d_visits[d_idx] += 1.0


@pytest.mark.parametrize("threads", [2, 4])
def test_a_pass_computes_every_particle_once_whichever_thread_takes_it(threads):
    """Each thread takes its part CLAIM particles at a time, then what is left of the
    others' parts; with more threads than cores (parts finished out of turn: taken over)
    every particle is still computed exactly once per pass, and the sums are those of one
    thread."""
    clouds = [lattice_cloud("fluid", nx=40, seed=7, visits=np.zeros(1600)) for _ in range(2)]
    for c in clouds:
        c.h[c.n // 3:] *= 1.5                # uneven work along the index order
    eqs = [Group([SummationDensity("fluid", ["fluid"]), _Visit("fluid", ["fluid"])])]
    sc, ref = (Scene([c], eqs, dim=2, threads=th, outputs={"fluid": ["rho", "visits"]})
               for c, th in zip(clouds, (threads, 1)))
    fluid = clouds[0]
    for s in (sc, ref):
        s.update_nnps()
    for _ in range(200):
        sc.compute(0, 0.0, 0.0)
    ref.compute(0, 0.0, 0.0)
    np.testing.assert_array_equal(fluid.visits, np.full(fluid.n, 200.0))
    np.testing.assert_array_equal(fluid.rho, clouds[1].rho)
