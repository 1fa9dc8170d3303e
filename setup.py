"""Build and install sphgen.

The top-level folders ``equations``, ``schemes`` and ``applications`` install as
``sphgen.equations``, ``sphgen.schemes`` and ``sphgen.applications``.  The only
extension built at install time is the neighbour search; everything physics-specific
is generated and compiled per scene at run time (see ``sphgen.codegen``).
"""
import sys

import numpy
from Cython.Build import cythonize
from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


def _openmp_flags(compiler):
    """Return (compile, link) OpenMP flags the compiler accepts, or empty lists."""
    import os
    import tempfile
    from setuptools._distutils.errors import CompileError, LinkError

    with tempfile.TemporaryDirectory() as tmp:
        src = os.path.join(tmp, "omp_probe.c")
        with open(src, "w") as f:
            f.write("#include <omp.h>\nint main(void){return omp_get_max_threads() < 1;}\n")
        try:
            objs = compiler.compile([src], output_dir=tmp, extra_postargs=["-fopenmp"])
            compiler.link_executable(objs, os.path.join(tmp, "probe"), extra_postargs=["-fopenmp"])
        except (CompileError, LinkError):
            return [], []
    return ["-fopenmp"], ["-fopenmp"]


class BuildExt(build_ext):
    def build_extensions(self):
        cflags, lflags = _openmp_flags(self.compiler)
        if not cflags:
            print("sphgen: the C compiler has no OpenMP; the neighbour search builds serial",
                  file=sys.stderr)
        for ext in self.extensions:
            # no multiply-add contracted, whatever CFLAGS say (-march=native enables FMA): the
            # distances of the build, the cut and the skin check must round as written
            ext.extra_compile_args += ["-O3", "-ffp-contract=off"] + cflags
            ext.extra_link_args += lflags
        super().build_extensions()


extensions = [
    Extension("sphgen.nnps._cell_list", ["sphgen/nnps/_cell_list.pyx"],
              include_dirs=[numpy.get_include(), "sphgen/nnps"],
              define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")]),
]

setup(
    name="sphgen",
    version="0.1.0",
    description="SPH equations in restricted Python, compiled per scene to Cython/OpenMP",
    python_requires=">=3.10",
    packages=["sphgen", "sphgen.codegen", "sphgen.codegen.passes", "sphgen.nnps", "sphgen.tools",
              "sphgen.equations", "sphgen.schemes", "sphgen.applications"],
    package_dir={"sphgen.equations": "equations", "sphgen.schemes": "schemes",
                 "sphgen.applications": "applications"},
    package_data={"sphgen.codegen": ["*.mako"], "sphgen.nnps": ["*.pyx", "*.h"],
                  "sphgen.tools": ["reference/*"]},
    ext_modules=cythonize(extensions, language_level=3),
    cmdclass={"build_ext": BuildExt},
    install_requires=["numpy>=2", "mako", "cython>=3", "compyle", "h5py", "automan",
                      "pytest", "pytest-xdist", "matplotlib", "tqdm", "setuptools"],
    entry_points={"console_scripts": ["sphgen = sphgen.app:main"]},
    zip_safe=False,
)
