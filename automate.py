#!/usr/bin/env python
"""Regenerate every figure: ``python automate.py`` (automan; see ``--help``).

``python automate.py variational`` (or ``ctvf``, ``ctvf_solids_quick``, ``edac``, ``superfluid``,
``superfluid_quick``, ``thermo``, ``thermo_quick``, ``shtc``,
``shtc_quick``) regenerates one paper's figures;
automan's own names work too: a problem's class name (``VariationalOrder``) or its output
folder name (``ctvf_fig13_cavity``).  Simulations go to ``outputs/``, figures to
``manuscript/figures/``.  Finished cases (``info.json`` with ``completed: true``) and cases
the blow-up guard stopped (``stopped: true``) are not run again.
"""
import sys

from automan.api import Automator

from automation.ctvf_cavity import CTVFCavityVoid
from automation.ctvf_solids import PAPER_PROBLEMS as CTVF_SOLIDS, QUICK_PROBLEMS as CTVF_SOLIDS_QUICK
from automation.ctvf_taylor_green import CTVFTaylorGreen
from automation.taylor_green import TaylorGreenEDAC
from automation.shtc import PAPER_PROBLEMS as SHTC, QUICK_PROBLEMS as SHTC_QUICK
from automation.superfluid import Superfluid, SuperfluidQuick
from automation.thermo import PAPER_PROBLEMS as THERMO, QUICK_PROBLEMS as THERMO_QUICK
from automation.variational import VariationalDamBreak, VariationalEjection, VariationalEnergy, VariationalOrder

# one entry per paper: the group name a user types
PAPERS = {
    "edac": [TaylorGreenEDAC],
    "ctvf": [CTVFTaylorGreen, CTVFCavityVoid, *CTVF_SOLIDS],
    "ctvf_solids_quick": CTVF_SOLIDS_QUICK,
    "variational": [VariationalDamBreak, VariationalOrder, VariationalEnergy, VariationalEjection],
    "superfluid": [Superfluid],
    "superfluid_quick": [SuperfluidQuick],
    "thermo": THERMO,
    "thermo_quick": THERMO_QUICK,
    "shtc": SHTC,
    "shtc_quick": SHTC_QUICK,
}
PROBLEMS = [cls for group in PAPERS.values() for cls in group]


def problem_names(argv, papers=PAPERS):
    """argv with paper names and output-folder names replaced by automan's class names."""
    by_folder = {cls("outputs", "manuscript/figures").get_name(): cls.__name__ for group in papers.values() for cls in group}
    out = []
    for arg in argv:
        if arg in papers:
            out += [cls.__name__ for cls in papers[arg]]
        else:
            out.append(by_folder.get(arg, arg))
    return out


if __name__ == "__main__":
    Automator(simulation_dir="outputs", output_dir="manuscript/figures",
              all_problems=PROBLEMS).run(problem_names(sys.argv[1:]))
