"""The host's ceilings that benchmarks/roofline.py prints beside every thread measurement."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "benchmarks"))


def test_the_gathers_ceiling_keeps_what_numpy_keeps_on_one_and_two_threads():
    """keep_near_cores: each thread keeps, from its own row of indices, those whose records
    lie within the radius, as numpy says, in order; the count is summed over threads and
    repetitions (a loop that did not run, or read the other thread's data, would differ)."""
    import roofline
    mod = roofline._module()
    rng = np.random.default_rng(3)
    nbrs = rng.integers(0, 4096, size=(2, 20001)).astype(np.int32)
    rec = rng.random((2, 4 * 4096))
    for threads in (1, 2):
        out = np.full((2, 20001), -1, dtype=np.int32)
        kept = []
        for k in range(threads):
            r = rec[k].reshape(4096, 4)
            near = (r[:, 0] - 0.5) ** 2 + (r[:, 1] - 0.5) ** 2 < 0.232
            kept.append(nbrs[k][near[nbrs[k]]])
        assert mod.keep_near_cores(3, threads, nbrs, rec, out) == 3 * sum(len(kk) for kk in kept)
        for k in range(threads):
            assert np.array_equal(out[k, :len(kept[k])], kept[k])
