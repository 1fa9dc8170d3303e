"""Errors people get: clear, early, naming the equation, array and property."""
import numpy as np
import pytest

from sphgen.codegen.build import CompileError
from sphgen.codegen.plan import SceneError
from sphgen.equation import Equation, Group, ParameterError
from sphgen.particles import ParticleArray, PropertyError
from sphgen.scene import Scene
from sphgen.equations.basic import SummationDensity
from sphgen.equations.edac import EDACPressureRate

from conftest import lattice_cloud


class Misspelt(Equation):
    def loop(self, d_idx, d_rhoo, s_idx, s_m, WIJ):
        d_rhoo[d_idx] += s_m[s_idx] * WIJ


def test_misspelt_property_names_equation_array_and_suggestion():
    pa = lattice_cloud()
    with pytest.raises(SceneError) as e:
        Scene([pa], [Misspelt("fluid", ["fluid"], keep=True)], dim=2, outputs={"fluid": ["rho"]})
    msg = str(e.value)
    assert "Misspelt[fluid<-fluid]" in msg and "'rhoo'" in msg and "array 'fluid'" in msg
    assert "did you mean 'rho'?" in msg


def test_property_read_but_never_set_is_an_error_before_compiling():
    pa = ParticleArray("fluid", x=np.zeros(4), h=np.ones(4))
    with pytest.raises(SceneError, match=r"SummationDensity\[fluid<-fluid\] reads property 'm' of "
                                         r"array 'fluid', but nothing sets it"):
        Scene([pa], [SummationDensity("fluid", ["fluid"])], dim=1, outputs={"fluid": ["rho"]})


def test_unknown_source_array():
    pa = lattice_cloud()
    with pytest.raises(SceneError, match=r"no particle array named 'fluids'; did you mean 'fluid'\?"):
        Scene([pa], [SummationDensity("fluid", ["fluids"])], dim=2, outputs={"fluid": ["rho"]})


def test_wrong_shape_and_non_finite_data():
    with pytest.raises(PropertyError, match=r"property 'sigma' has stride 9 so it needs 4x9 = 36 values; got 4"):
        ParticleArray("solid", x=np.zeros(4)).add_property("sigma", stride=9, data=np.zeros(4))
    with pytest.raises(PropertyError, match=r"property 'u' is not finite at particle 2"):
        ParticleArray("fluid", x=np.zeros(4), u=np.array([0, 1, np.nan, 2.0]))


@pytest.mark.parametrize("kw,match", [
    (dict(c0=-1.0, nu_edac=0.1), r"EDACPressureRate\(dest='fluid'\): parameter c0=-1.0 must be > 0"),
    (dict(c0=10.0, nu_edac=float("nan")), r"parameter nu_edac=nan is not finite"),
    (dict(c0=10.0), r"parameter 'nu_edac' is not set"),
])
def test_bad_parameters_are_refused_at_construction(kw, match):
    with pytest.raises(ParameterError, match=match):
        EDACPressureRate("fluid", ["fluid"], **kw)


class WritesSource(Equation):
    def loop(self, d_idx, d_rho, s_idx, s_rho, WIJ):
        s_rho[s_idx] += WIJ


def test_pair_loops_must_be_gather_only():
    pa = lattice_cloud()
    with pytest.raises(SceneError, match=r"WritesSource\[fluid<-fluid\]\.loop writes s_rho: pair "
                                         r"loops are gather-only"):
        Scene([pa], [WritesSource("fluid", ["fluid"])], dim=2, outputs={"fluid": ["rho"]})


class ReadsWhatGroupWrites(Equation):
    def loop(self, d_idx, d_p, s_idx, s_rho, WIJ):
        d_p[d_idx] += s_rho[s_idx] * WIJ


def test_reading_a_property_the_same_group_writes_is_refused():
    pa = lattice_cloud()
    pa.add_property("p")
    g = Group([SummationDensity("fluid", ["fluid"]), ReadsWhatGroupWrites("fluid", ["fluid"])])
    with pytest.raises(SceneError, match=r"reads s_rho of 'fluid' while this group writes 'rho' of "
                                         r"'fluid': split them into two Groups"):
        Scene([pa], [g], dim=2, outputs={"fluid": ["p"]})


class BadCode(Equation):
    def initialize(self, d_idx, d_p):
        d_p[d_idx] = undefined_function(3.0)  # noqa: F821


def test_compile_failure_names_equation_class_and_source_line(tmp_cache):
    pa = lattice_cloud()
    pa.add_property("p")
    with pytest.raises(CompileError) as e:
        Scene([pa], [BadCode("fluid")], dim=2, outputs={"fluid": ["p"]})
    import inspect
    line = inspect.getsourcelines(BadCode.initialize)[1] + 1
    assert f"BadCode.initialize ({__file__}:{line})" in str(e.value)
    assert "undefined_function" in str(e.value) or "undeclared name" in str(e.value)


def test_unknown_application_option_is_refused(capsys):
    from sphgen.app import main
    with pytest.raises(SystemExit):
        main(["run", "taylor_green", "--nxx", "10"])
    assert "unrecognized arguments: --nxx 10" in capsys.readouterr().err


@pytest.mark.parametrize("args,match", [
    (["--tf", "-1"], "must be a non-negative finite number"),
    (["--dt", "nan"], "must be a positive finite number"),
    (["--re", "inf"], "--re must be a positive finite number"),
])
def test_bad_option_values(args, match, capsys):
    from sphgen.app import main
    with pytest.raises(SystemExit) as e:
        main(["run", "taylor_green", "--disable-output"] + args)
    assert match in (capsys.readouterr().err + str(e.value.code))


def test_python_dash_m_sphgen_answers_a_mistake_in_one_line():
    """``python -m sphgen`` is the same command line as ``sphgen``."""
    import subprocess
    import sys
    r = subprocess.run([sys.executable, "-m", "sphgen", "run", "taylor_green", "--nx", "0"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.strip() == "sphgen: --nx must be at least 4, got 0"


def test_module_hash_ignores_where_the_project_lives():
    """Two clones of the project generate the same code but different '# @src' paths: the
    compile cache serves both; a different line (or code) is a different module."""
    from sphgen.codegen.build import module_hash
    src = "def f():\n    # @src {}/equations/basic.py:{}\n    return 1\n"
    a = module_hash(src.format("/work/main", 12))
    assert a == module_hash(src.format("/tmp/ci_clone", 12))
    assert a != module_hash(src.format("/work/main", 13))
    assert a != module_hash(src.format("/work/main", 12).replace("return 1", "return 2"))


def test_generated_modules_carry_no_debug_information(tmp_cache):
    """Python's own CFLAGS add -g, which made gcc take 39 s instead of 6.5 s on SHTC's
    Taylor-Couette module: the build turns it off (-g0), so the shared object has no
    .debug_info section (docs/performance.md, "Compile time")."""
    from sphgen.codegen.build import load_or_build
    mod, seconds = load_or_build("def twice(double x):\n    return 2.0 * x\n")
    assert mod.twice(1.5) == 3.0 and seconds > 0
    with open(mod.__file__, "rb") as f:
        assert b".debug_info" not in f.read()


@pytest.mark.parametrize("command", ["run", "stress", "precision"])
def test_unknown_application_is_one_line_with_the_nearest_names(command, capsys):
    import os
    from sphgen.app import main
    n_apps = len([f for f in os.listdir(os.path.join(os.path.dirname(__file__), "..", "applications"))
                  if f.endswith(".py") and not f.startswith("_")])
    with pytest.raises(SystemExit) as e:
        main([command, "taylr_green"])
    said = (capsys.readouterr().err + (e.value.code if isinstance(e.value.code, str) else "")).strip()
    assert e.value.code not in (0, None)
    assert said == (f"sphgen: no application 'taylr_green'; did you mean 'taylor_green' or 'taylor_couette'? "
                    f"('sphgen list' names all {n_apps})"), said


def test_unknown_application_counts_the_applications_there_are(monkeypatch):
    from sphgen import app
    from sphgen.errors import InputError
    monkeypatch.setattr(app, "list_applications", lambda: ["cavity", "couette", "poiseuille"])
    with pytest.raises(InputError) as e:
        app.load_application("zzz")
    assert str(e.value) == "no application 'zzz' ('sphgen list' names all 3)"
    with pytest.raises(InputError, match=r"did you mean 'cavity'\? \('sphgen list' names all 3\)$"):
        app.load_application("cavty")
