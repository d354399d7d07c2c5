"""`pip install .` the way docs/python.md says: a venv with Debian's packages visible, Debian's
setuptools as the build backend (no build isolation, no index: nothing is downloaded), then
the installed package imported from outside the source and build trees and used once."""
import json
import os
import shutil
import subprocess
import sys
import tempfile

SOURCE = os.environ["NSG_SOURCE_DIR"]
BUILD = os.environ["NSG_BINARY_DIR"]


def run(argv, **kwargs):
    result = subprocess.run(argv, capture_output=True, text=True, **kwargs)
    if result.returncode != 0:
        sys.exit(f"{' '.join(argv)} exited {result.returncode}\n{result.stdout}\n{result.stderr}")
    return result.stdout


def main():
    scratch = tempfile.mkdtemp(prefix="nsg-pip-", dir=os.environ.get("NSG_TEST_TMP", "/tmp"))
    try:
        venv = os.path.join(scratch, "venv")
        run([sys.executable, "-m", "venv", "--system-site-packages", venv])
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        env.update(NSGRAPH_BUILD_DIR=BUILD, NSGRAPH_PIP_BUILD_BASE=os.path.join(scratch, "build"),
                   PIP_DISABLE_PIP_VERSION_CHECK="1")
        run([os.path.join(venv, "bin", "pip"), "install", "--no-build-isolation", "--no-index", SOURCE],
            env=env, cwd=scratch)
        probe = (
            "import json, nsgraph\n"
            "g = {'nodes': [[10.0, 10.0], [10.0, 60.0], [60.0, 60.0]], 'edges': [[0, 1], [1, 2]]}\n"
            "doc = {'schema_version': '1', 'tiles': {'t': g}}\n"
            "report = nsgraph.score(doc, doc)\n"
            "print(json.dumps({'file': nsgraph.__file__, 'version': nsgraph.__version__,\n"
            "                  'apls': report['aggregate']['mean']['apls']}))\n")
        got = json.loads(run([os.path.join(venv, "bin", "python"), "-c", probe], env=env, cwd=scratch))
        site = os.path.realpath(venv)
        if not os.path.realpath(got["file"]).startswith(site):
            sys.exit(f"nsgraph imported from {got['file']}, not from the venv {venv}")
        with open(os.path.join(SOURCE, "CMakeLists.txt"), encoding="utf-8") as f:
            if f"project(nsgraph VERSION {got['version']} " not in f.read():
                sys.exit(f"installed version {got['version']} is not CMakeLists.txt's project version")
        if abs(got["apls"] - 1.0) > 1e-12:
            sys.exit(f"a graph scored against itself gave APLS {got['apls']}, expected 1")
        print(f"installed {got['file']} (version {got['version']}); self-score APLS 1")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    main()
