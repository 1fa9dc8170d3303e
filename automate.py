#!/usr/bin/env python
"""Regenerate every figure: ``python automate.py`` (automan; see ``--help``).

Simulations go to ``outputs/``, figures to ``manuscript/figures/``.  Finished cases
(``info.json`` with ``completed: true``) are not run again.
"""
from automan.api import Automator

from automation.ctvf_cavity import CTVFCavityVoid
from automation.ctvf_taylor_green import CTVFTaylorGreen
from automation.taylor_green import TaylorGreenEDAC
from automation.superfluid import Superfluid, SuperfluidQuick
from automation.variational import VariationalDamBreak, VariationalEjection, VariationalEnergy, VariationalOrder

PROBLEMS = [TaylorGreenEDAC, CTVFTaylorGreen, CTVFCavityVoid, VariationalDamBreak, VariationalOrder,
            VariationalEnergy, VariationalEjection, Superfluid, SuperfluidQuick]

if __name__ == "__main__":
    Automator(simulation_dir="outputs", output_dir="manuscript/figures",
              all_problems=PROBLEMS).run()
