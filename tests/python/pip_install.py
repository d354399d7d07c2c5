"""`pip install .` the way docs/python.md says, with Debian's interpreter and with another one.

Each case makes a venv, installs the source tree with pip through the in-tree build backend
(python/build_backend: standard library only, so no setuptools, `wheel` or index is needed),
imports the installed package from outside the source and build trees and scores a graph
against itself. The other interpreter is the first CPython >= 3.9 found that is not Debian's
(pyenv, conda, python.org builds) and has the build's extension ABI, so the build folder is
reused; numpy comes from Debian's packages through a .pth file, as docs/python.md describes.
"""
import glob
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import unittest

SOURCE = os.environ["NSG_SOURCE_DIR"]
BUILD = os.environ["NSG_BINARY_DIR"]
DEBIAN_DIST_PACKAGES = "/usr/lib/python3/dist-packages"
PROBE = (
    "import json, sys, nsgraph\n"
    "g = {'nodes': [[10.0, 10.0], [10.0, 60.0], [60.0, 60.0]], 'edges': [[0, 1], [1, 2]]}\n"
    "doc = {'schema_version': '1', 'tiles': {'t': g}}\n"
    "report = nsgraph.score(doc, doc)\n"
    "print(json.dumps({'file': nsgraph.__file__, 'version': nsgraph.__version__,\n"
    "                  'python': sys.version.split()[0], 'apls': report['aggregate']['mean']['apls']}))\n")
INTERPRETER_FACTS = (
    "import json, sys, sysconfig\n"
    "print(json.dumps({'implementation': sys.implementation.name, 'version': list(sys.version_info[:2]),\n"
    "                  'ext_suffix': sysconfig.get_config_var('EXT_SUFFIX'),\n"
    "                  'base': __import__('os').path.realpath(sys._base_executable if hasattr(sys, '_base_executable') "
    "else sys.executable)}))\n")


def run(argv, **kwargs):
    result = subprocess.run(argv, capture_output=True, text=True, **kwargs)
    if result.returncode != 0:
        raise AssertionError(f"{' '.join(argv)} exited {result.returncode}\n{result.stdout}\n{result.stderr}")
    return result.stdout


def interpreter_facts(python):
    try:
        out = subprocess.run([python, "-c", INTERPRETER_FACTS], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return json.loads(out.stdout) if out.returncode == 0 else None


def candidate_interpreters():
    """Executables that may be a CPython: on PATH by name, and pyenv's installed versions."""
    names = ["python3"] + [f"python3.{minor}" for minor in range(9, 15)]
    found = [shutil.which(n) for n in names]
    pyenv_root = os.environ.get("PYENV_ROOT", os.path.expanduser("~/.pyenv"))
    found += sorted(glob.glob(os.path.join(pyenv_root, "versions", "*", "bin", "python3")))
    return [f for f in dict.fromkeys(found) if f]


def other_interpreter():
    """(path, facts) of a non-Debian CPython >= 3.9 with the build's ABI, and the ones skipped."""
    debian = os.path.realpath(sys.executable)
    mine = sysconfig.get_config_var("EXT_SUFFIX")
    skipped = []
    for path in candidate_interpreters():
        facts = interpreter_facts(path)
        if not facts or facts["implementation"] != "cpython" or facts["base"] == debian:
            continue
        if tuple(facts["version"]) < (3, 9):
            continue
        if facts["ext_suffix"] != mine:
            skipped.append(f"{path} ({facts['ext_suffix']})")
            continue
        return path, facts, skipped
    return None, None, skipped


class PipInstall(unittest.TestCase):
    def setUp(self):
        self.scratch = tempfile.mkdtemp(prefix="nsg-pip-", dir=os.environ.get("NSG_TEST_TMP", "/tmp"))

    def tearDown(self):
        shutil.rmtree(self.scratch, ignore_errors=True)

    def install_and_probe(self, python, debian_numpy_pth):
        venv = os.path.join(self.scratch, "venv")
        run([python, "-m", "venv", "--system-site-packages", venv])
        if debian_numpy_pth:
            site = run([os.path.join(venv, "bin", "python"), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"])
            with open(os.path.join(site.strip(), "debian-dist-packages.pth"), "w", encoding="utf-8") as f:
                f.write(DEBIAN_DIST_PACKAGES + "\n")
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        env.update(NSGRAPH_BUILD_DIR=BUILD, PIP_DISABLE_PIP_VERSION_CHECK="1")
        run([os.path.join(venv, "bin", "python"), "-m", "pip", "install", "--no-index", SOURCE], env=env,
            cwd=self.scratch)
        got = json.loads(run([os.path.join(venv, "bin", "python"), "-c", PROBE], env=env, cwd=self.scratch))
        self.assertTrue(os.path.realpath(got["file"]).startswith(os.path.realpath(venv)),
                        f"nsgraph imported from {got['file']}, not from the venv {venv}")
        with open(os.path.join(SOURCE, "CMakeLists.txt"), encoding="utf-8") as f:
            self.assertIn(f"project(nsgraph VERSION {got['version']} ", f.read())
        self.assertAlmostEqual(got["apls"], 1.0, delta=1e-12)
        return got

    def test_debian_interpreter(self):
        got = self.install_and_probe(sys.executable, debian_numpy_pth=False)
        print(f"Debian's Python {got['python']}: installed {got['file']}; self-score APLS 1")

    def test_another_interpreter(self):
        python, facts, other_abis = other_interpreter()
        if python is None:
            self.skipTest("optional interpreter: no CPython >= 3.9 other than Debian's with the extension ABI "
                          f"{sysconfig.get_config_var('EXT_SUFFIX')} on this machine"
                          + (f" (other ABIs, each needing its own library build: {', '.join(other_abis)})"
                             if other_abis else ""))
        got = self.install_and_probe(python, debian_numpy_pth=True)
        print(f"{python} (Python {got['python']}): installed {got['file']}; self-score APLS 1")

    # PYTHONPATH=build/python under an interpreter without numpy: the error names numpy and the ways.
    def test_an_interpreter_without_numpy_is_told_so(self):
        for python in candidate_interpreters():
            facts = interpreter_facts(python)
            if not facts or facts["base"] == os.path.realpath(sys.executable):
                continue
            env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
            if subprocess.run([python, "-c", "import numpy"], capture_output=True, env=env).returncode == 0:
                continue
            env["PYTHONPATH"] = os.path.join(BUILD, "python")
            result = subprocess.run([python, "-c", "import nsgraph"], capture_output=True, text=True, env=env,
                                    cwd=self.scratch)
            self.assertNotEqual(result.returncode, 0)
            self.assertIn("nsgraph needs numpy", result.stderr)
            self.assertIn("docs/python.md", result.stderr)
            return
        self.skipTest("optional interpreter: every interpreter found here has numpy")


if __name__ == "__main__":
    unittest.main(verbosity=2)
