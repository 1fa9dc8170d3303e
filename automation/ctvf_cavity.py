"""Lid-driven cavity with CTVF, Adepu & Ramachandran (2021) section 4.2, Fig. 13.

Re = 100 at 150 x 150 to t = 25, with and without the correction terms
(``outputs/ctvf_fig13_cavity/nx150``, ``nx150_nocorr``).  Figure ``fig13_cavity_void.png``:
the particles of both runs at the end, coloured by speed, each titled with its largest
empty disc (:func:`sphgen.tools.probes.largest_empty_disc`, in dx, from ``results.json``);
``fig13.json`` holds the two numbers.  A run the blow-up guard stopped is drawn at its last
output, titled "stopped at t = ...", its empty disc None (only results.json has it).
``python -m automation.ctvf_cavity [outputs] [nx]`` draws the same from finished runs of
another resolution, without running anything.
"""
import json
import os
import sys

import numpy as np

from .ctvf_taylor_green import particle_plot
from .tasks import SphgenProblem, Simulation, pick, read_results, run_state, state_suffix, state_text

NX = 150
TF = 25.0


def case_params(nx=NX, tf=TF, corrections=True):
    """The ``sphgen run cavity`` options of one run (automan keyword form)."""
    p = dict(nx=nx, re=100, tf=tf, threads=1, pfreq=100000)
    if not corrections:
        p["no_corrections"] = None
    return p


def figure(sim_dir, out_dir, nx=NX):
    """fig13_cavity_void.png and fig13.json from the finished runs ``nx{nx}[_nocorr]``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from sphgen import io
    os.makedirs(out_dir, exist_ok=True)
    f, axes = plt.subplots(1, 2, figsize=(10, 4.8))
    out = {}
    for ax, (name, label) in zip(axes, ((f"nx{nx}", "with corrections"), (f"nx{nx}_nocorr", "without corrections"))):
        folder = os.path.join(sim_dir, name)
        res = read_results(folder, "its largest empty disc")
        files = io.output_files(folder, "cavity") if os.path.isdir(folder) else []
        if not files or (res is None and run_state(folder) != "stopped"):
            ax.set_title(f"{label}: {state_text(folder)}")
            continue
        data = io.load(files[-1])
        fl = data["arrays"]["fluid"]
        out[name] = pick(folder, res, ("t", "largest_empty_disc_over_dx"))
        void = out[name]["largest_empty_disc_over_dx"]
        particle_plot(f, ax, fl, np.hypot(fl.u, fl.v), "|u|",
                      f"{label}{state_suffix(folder)}, t = {data['solver_data']['t']:.3g}\nlargest empty disc "
                      + ("missing (no results.json)" if void is None else f"{void:.2f} dx"))
    f.suptitle(f"Fig. 13: cavity Re = 100, {nx} x {nx}")
    f.tight_layout()
    f.savefig(os.path.join(out_dir, "fig13_cavity_void.png"), dpi=120)
    plt.close(f)
    with open(os.path.join(out_dir, "fig13.json"), "w") as fh:
        json.dump(out, fh, indent=1)
    return out


class CTVFCavityVoid(SphgenProblem):
    """Adepu & Ramachandran (2021), Fig. 13."""

    nx = NX

    def get_name(self):
        return "ctvf_fig13_cavity"

    def setup(self):
        cmd = self.sphgen("cavity")
        self.cases = [Simulation(self.input_path(f"nx{self.nx}" + ("" if c else "_nocorr")), cmd,
                                 job_info=dict(n_core=1, n_thread=1), **case_params(self.nx, corrections=c))
                      for c in (True, False)]

    def run(self):
        self.make_output_dir()
        figure(self.input_path(), self.output_path(), self.nx)


if __name__ == "__main__":
    root = sys.argv[1] if len(sys.argv) > 1 else "outputs"
    nx = int(sys.argv[2]) if len(sys.argv) > 2 else NX
    print(figure(os.path.join(root, "ctvf_fig13_cavity"), os.path.join("manuscript", "figures", "ctvf_fig13_cavity"), nx))
