"""Run-time choice of the Verlet skin: the one whose neighbour upkeep costs least per step.

A wider skin keeps the skin lists longer (fewer rebuilds) but gives every update more
candidates to cut.  Which wins depends on the case: how far particles move per step
against the support, how costly a rebuild is against a cut (docs/performance.md: 0.3
of the support ran the dam break with the Wendland C2 at h = 1.3 dx 9 % faster than 0.1,
and the colliding rings 10 % slower).  The rows handed to the passes are the exact lists
whatever the skin, so the choice never changes the results; only the rebuilds move.

:class:`SkinTuner` times each neighbour update and groups them by *generation*: the
updates from one rebuild to the next, all with the skin ``s`` (a fraction of the support)
of that rebuild.  A generation gives the cost of a cut ``c`` (the median update without a
rebuild), the extra cost of a rebuild ``b`` and its length ``L`` in updates.  In ``dim``
dimensions the candidates, so both costs, grow as ``(1 + s)**dim``, and the particles
exhaust the skin after a number of updates proportional to ``s``, so the upkeep per update
with a skin ``x`` is modelled as

    f(x) = (1 + x)**dim (c0 + b0 / (kappa x)),   c0, b0 = c, b / (1 + s)**dim,  kappa = L / s,

whose minimum solves ``dim c0 kappa x**2 + (dim - 1) b0 x - b0 = 0``.  The next rebuilds
take that skin (within ``lowest`` and ``highest``), from the medians of the last
``window`` generations.  Generations cut short by a rebuild that is not the skin's (a
spatial sort) are left out.
"""
import math
import statistics


def best_skin(b0, c0, kappa, dim):
    """The skin minimising ``(1 + x)**dim (c0 + b0 / (kappa x))`` (see the module's text)."""
    if b0 <= 0.0:
        return 0.0
    if c0 <= 0.0 or kappa <= 0.0:
        return math.inf
    qa, qb = dim * c0 * kappa, (dim - 1) * b0
    return (-qb + math.sqrt(qb * qb + 4.0 * qa * b0)) / (2.0 * qa)


class SkinTuner:
    """Chooses the skin (a fraction of the support) of the next rebuilds."""

    def __init__(self, skin=0.1, dim=2, lowest=0.025, highest=0.5, window=5):
        if not (0.0 < lowest <= skin <= highest):
            raise ValueError(f"SkinTuner: need 0 < lowest <= skin <= highest, got {lowest}, {skin}, {highest}")
        self.skin = float(skin)            # the skin of the next rebuilds
        self.dim, self.window = int(dim), int(window)
        self.lowest, self.highest = float(lowest), float(highest)
        self.samples = []                  # (b0, c0, kappa) of the last complete generations
        self.choices = []                  # (generation, skin) whenever the choice changes
        self.n_generations = 0
        self._open = None                  # [skin, seconds of its rebuild, seconds of its cuts]

    def record(self, seconds, rebuilt, built_with):
        """Account one update that took ``seconds`` (``rebuilt``: it rebuilt the skin lists,
        with the skin ``built_with``); returns the skin for the next rebuilds."""
        if rebuilt:
            self._close()
            self._open = [built_with, seconds, []]
        elif self._open is not None:
            self._open[2].append(seconds)
        return self.skin

    def interrupt(self):
        """The skin lists were rebuilt outside an update (a spatial sort): the open
        generation is not a whole one, and the next starts at the next rebuild."""
        self._open = None

    def _close(self):
        gen, self._open = self._open, None
        if gen is None or len(gen[2]) < 2 or gen[0] <= 0.0:
            return
        s, rebuild, cuts = gen
        c = statistics.median(cuts)
        grow = (1.0 + s) ** self.dim
        self.samples = (self.samples + [(max(rebuild - c, 0.0) / grow, c / grow, (len(cuts) + 1) / s)])[-self.window:]
        self.n_generations += 1
        if len(self.samples) < 3:
            return
        b0, c0, kappa = (statistics.median(v) for v in zip(*self.samples))
        new = min(self.highest, max(self.lowest, best_skin(b0, c0, kappa, self.dim)))
        if abs(new / self.skin - 1.0) > 0.05:
            self.skin = new
            self.choices.append((self.n_generations, new))
