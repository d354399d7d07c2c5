"""Builds the `nsgraph` Python package through the project's CMake build.

The package is what CMake assembles in <build>/python/nsgraph: the pure-Python modules, the
pybind11 extension _nsgraph and the schemas the submission checks need. This script
configures that build if needed (NSGRAPH_BUILD_DIR, default ./build, the folder `make`
uses), builds the one target `nsgraph_python` (a no-op after `make`) and copies the folder
into the wheel. Nothing is downloaded: the C++ dependencies are Debian packages
(cmake/debian-packages.txt; `make deps` installs them).
"""
import os
import re
import shutil
import subprocess
import sys

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

ROOT = os.path.dirname(os.path.abspath(__file__))


def project_version():
    """The version of CMakeLists.txt's project(): one number for the library and the package."""
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(nsgraph VERSION ([0-9.]+)", f.read())
    if not match:
        sys.exit("setup.py: CMakeLists.txt: expected `project(nsgraph VERSION x.y.z ...)`")
    return match.group(1)


class BuildWithCMake(build_py):
    """Builds <build>/python/nsgraph with CMake and copies it into the package's build folder."""

    def run(self):
        build_dir = os.path.abspath(os.environ.get("NSGRAPH_BUILD_DIR", os.path.join(ROOT, "build")))
        if not os.path.exists(os.path.join(build_dir, "CMakeCache.txt")):
            self.spawn(["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                        "-DNSG_BUILD_TESTS=OFF", "-DNSG_BUILD_BENCH=OFF"])
        jobs = os.environ.get("NSGRAPH_BUILD_JOBS", str(os.cpu_count() or 1))
        self.spawn(["cmake", "--build", build_dir, "--target", "nsgraph_python", "-j", jobs])
        package = os.path.join(build_dir, "python", "nsgraph")
        if not any(name.startswith("_nsgraph") for name in os.listdir(package)):
            sys.exit(f"setup.py: {package}: the build made no _nsgraph extension")
        target = os.path.join(self.build_lib, "nsgraph")
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(package, target, ignore=shutil.ignore_patterns("__pycache__"))


class BinaryDistribution(Distribution):
    """The wheel holds a compiled extension: tag it for this platform and interpreter."""

    def has_ext_modules(self):
        return True


setup(
    version=project_version(),
    packages=["nsgraph"],
    package_dir={"nsgraph": "python/nsgraph"},
    cmdclass={"build_py": BuildWithCMake},
    distclass=BinaryDistribution,
    options={"build": {"build_base": os.environ.get("NSGRAPH_PIP_BUILD_BASE", "build-pip")}},
    zip_safe=False,
)
