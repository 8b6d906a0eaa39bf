"""`pip install .`: the Python package vines (docs/python.md).

The extension vines._vines is built by the project's CMake build (target
_vines, sim_host/python), in build/pip unless VINES_BUILD_DIR names a
configured build tree to reuse (e.g. build/release); the package's Python
files are sim_host/python/vines. No pyproject.toml on purpose: pip then
builds with the setuptools, wheel and pybind11 of the system (Debian's
python3-setuptools, python3-wheel, pybind11-dev) and needs no package index.
"""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(vines VERSION ([0-9.]+)", text).group(1)


class CMakeBuild(build_ext):
    """Builds _vines with CMake and puts it where setuptools expects it."""

    def build_extension(self, ext):
        build = Path(os.environ.get("VINES_BUILD_DIR", ROOT / "build" / "pip")).resolve()
        if not (build / "CMakeCache.txt").exists():
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                            "-DVINES_PYTHON=ON", "-DPython_EXECUTABLE=" + sys.executable], check=True)
        jobs = str(os.cpu_count() or 1)
        subprocess.run(["cmake", "--build", str(build), "--target", "_vines", "-j", jobs], check=True)
        built = sorted((build / "python" / "vines").glob("_vines*.so"))
        if not built:
            sys.exit("setup.py: the build made no vines/_vines*.so in %s" % build)
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[-1], target)


setup(
    name="vines",
    version=version(),
    description="Vibro-impact nonlinear energy sink on a shear frame: the vines firmware core from Python",
    python_requires=">=3.9",
    install_requires=["numpy"],
    packages=["vines"],
    package_dir={"vines": "sim_host/python/vines"},
    package_data={"vines": ["py.typed", "*.pyi"]},
    ext_modules=[Extension("vines._vines", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
