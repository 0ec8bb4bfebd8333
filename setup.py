"""Builds the imufit Python module with the project's CMake (driven by pyproject.toml's setuptools).

`pip install --no-build-isolation .` runs this: CMake configures the project in build-pip/ for
the interpreter running pip (Ninja and ccache when present; no tests, no benchmarks) and builds
the target imufit_python straight into the package folder setuptools assembles.
"""

import os
import pathlib
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


def project_version() -> str:
    """The version of CMakeLists.txt's project(), the one the command reports."""
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(imufit VERSION ([0-9.]+)", text).group(1)


class CMakeExtension(Extension):
    def __init__(self, name: str) -> None:
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext: Extension) -> None:
        package_dir = pathlib.Path(self.get_ext_fullpath(ext.name)).resolve().parent
        build_dir = pathlib.Path(self.build_temp).resolve() / "cmake"
        build_dir.mkdir(parents=True, exist_ok=True)
        configure = ["cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
                     "-DIMUFIT_BUILD_PYTHON=ON", "-DIMUFIT_BUILD_TESTS=OFF", "-DIMUFIT_BUILD_BENCH=OFF",
                     f"-DPython3_EXECUTABLE={sys.executable}", f"-DIMUFIT_PYTHON_PACKAGE_DIR={package_dir}"]
        if shutil.which("ninja"):
            configure += ["-G", "Ninja"]
        if shutil.which("ccache"):
            configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
            os.environ.setdefault("CCACHE_BASEDIR", str(ROOT))
        subprocess.check_call(configure)
        jobs = str(os.cpu_count() or 2)
        subprocess.check_call(["cmake", "--build", str(build_dir), "--target", "imufit_python", "-j", jobs])


setup(
    version=project_version(),
    ext_modules=[CMakeExtension("imufit._imufit")],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": "build-pip"}},
)
