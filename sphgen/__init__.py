"""sphgen: SPH equations in restricted Python, compiled per scene to Cython/OpenMP."""
import os

# OpenMP threads spin a short while at barriers, then sleep.  The GNU default spins for
# ~300k iterations, which on a shared or oversubscribed machine turns every parallel
# region into a scheduler time slice (milliseconds).  Must be set before libgomp loads.
os.environ.setdefault("GOMP_SPINCOUNT", "10000")

__version__ = "0.1.0"
