"""Build hook: compile geardyn's numba kernels into the built package, so an install ships them compiled.

After the package's files are copied into the build directory, ``python -m geardyn._precompile`` runs on that
copy (see its docstring): the numba cache it writes beside the kernels goes into the wheel, keyed on the
sources' contents, and a user's first run reads it instead of compiling.  Set ``GEARDYN_NO_PRECOMPILE=1`` to
skip it; an editable install skips it (its sources change).  A failure here never fails the install.
"""

import os
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py


class BuildPyCompiled(build_py):
    def run(self):
        super().run()
        if self.dry_run or getattr(self, "editable_mode", False) or os.environ.get("GEARDYN_NO_PRECOMPILE"):
            return
        # the built copy first, then what pip's isolated build environment puts on the path (its packages)
        path = [os.path.abspath(self.build_lib), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(path))
        env.pop("NUMBA_CACHE_DIR", None)
        cmd = [sys.executable, "-m", "geardyn._precompile", "--examples", os.path.abspath("examples")]
        try:
            subprocess.run(cmd, env=env, check=False, timeout=3600)
        except (OSError, subprocess.SubprocessError) as exc:
            print(f"geardyn: kernels not compiled at install ({exc}); the first run compiles them", file=sys.stderr)


setup(cmdclass={"build_py": BuildPyCompiled})
