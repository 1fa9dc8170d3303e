"""Taylor-Green vortex, EDAC reference scheme (uncorrected baseline of Adepu & Ramachandran (2024), sec. 3.1).

Figures (named after Adepu & Ramachandran (2024) Fig. 6, which shows the corrected scheme; these are the
uncorrected EDAC baseline with SPST): ``tg_edac_decay.png`` (max |u| against the exact
decay for nx = 25, 50, 100) and ``tg_edac_l1.png`` (L1 error of |u|, eq. 66, over time); a run
the blow-up guard stopped is drawn up to its stop, labelled "stopped at t = ...".
"""
import numpy as np
from automan.api import mdict

from .tasks import SphgenProblem, Simulation, state_suffix


class TaylorGreenEDAC(SphgenProblem):
    re = 100
    tf = 2.5

    def get_name(self):
        return "taylor_green_edac"

    def setup(self):
        cmd = self.sphgen("taylor_green")
        self.cases = [
            Simulation(self.input_path(f"nx_{p['nx']}"), cmd, job_info=dict(n_core=1, n_thread=2),
                       nx=p["nx"], re=self.re, tf=self.tf, disable_output=None)
            for p in mdict(nx=[25, 50, 100])
        ]

    def run(self):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        self.make_output_dir()
        fig1, a1 = plt.subplots(figsize=(5, 4))
        fig2, a2 = plt.subplots(figsize=(5, 4))
        exact = None
        for case in self.cases:
            rows = np.array(self.history(case)["rows"])
            t, umax, uex, l1 = rows.T
            label = f"nx = {case.params['nx']}{state_suffix(case)}"
            a1.semilogy(t, umax, label=label)
            a2.plot(t, l1, label=label)
            if exact is None or t[-1] > exact[0][-1]:
                exact = (t, uex)                        # the longest run's (one stopped early is shorter)
        a1.semilogy(*exact, "k--", label="exact")
        for a, y in ((a1, "max |u|"), (a2, "$L_1$ error of |u|")):
            a.set_xlabel("t")
            a.set_ylabel(y)
            a.legend()
        fig1.tight_layout()
        fig2.tight_layout()
        fig1.savefig(self.output_path("tg_edac_decay.png"), dpi=150)
        fig2.savefig(self.output_path("tg_edac_l1.png"), dpi=150)
        plt.close(fig1)
        plt.close(fig2)
