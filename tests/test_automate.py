"""automate.py: a paper's name regenerates that paper's figures (names only; nothing is run)."""
import pytest
from automan.api import Automator

import automate


def test_paper_and_folder_names_become_automan_class_names():
    names = automate.problem_names(["variational", "ctvf_fig13_cavity", "TaylorGreenEDAC", "--help"])
    assert names == ["VariationalDamBreak", "VariationalOrder", "VariationalEnergy", "VariationalEjection",
                     "CTVFCavityVoid", "TaylorGreenEDAC", "--help"]


@pytest.mark.parametrize("paper", sorted(automate.PAPERS))
def test_automan_accepts_every_paper_name(paper, tmp_path):
    auto = Automator(simulation_dir=str(tmp_path / "outputs"), output_dir=str(tmp_path / "figures"),
                     all_problems=automate.PROBLEMS)
    auto._setup_argparse()
    auto._check_positional_arguments(automate.problem_names([paper]))   # exits on an unknown name
    assert {c.__name__ for c in auto._select_problem_classes(automate.problem_names([paper]))} == \
        {c.__name__ for c in automate.PAPERS[paper]}


def test_an_unknown_name_is_refused_by_automan(tmp_path):
    auto = Automator(simulation_dir=str(tmp_path / "o"), output_dir=str(tmp_path / "f"), all_problems=automate.PROBLEMS)
    auto._setup_argparse()
    with pytest.raises(SystemExit):
        auto._check_positional_arguments(automate.problem_names(["no_such_paper"]))
