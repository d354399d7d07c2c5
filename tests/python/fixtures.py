"""The e2e dataset for the Python tests: tests/data/synth/e2e.json synthesized and
generated with tests/data/generate/e2e.json (tar and folder layouts), made once per nsgraph
build under <build>/test-cache and shared by the test processes (like the C++ fixtures)."""
import hashlib
import json
import os
import shutil
import subprocess
import tempfile

SOURCE_DIR = os.environ.get("NSG_SOURCE_DIR", os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
BINARY_DIR = os.environ.get("NSG_BINARY_DIR", os.path.join(SOURCE_DIR, "build"))
NSG_EXE = os.environ.get("NSG_EXE", os.path.join(BINARY_DIR, "tools", "nsgraph", "nsgraph"))
SYNTH_CONFIG = os.path.join(SOURCE_DIR, "tests", "data", "synth", "e2e.json")
GENERATE_CONFIG = os.path.join(SOURCE_DIR, "tests", "data", "generate", "e2e.json")


def run_nsgraph(*args, check=True):
    r = subprocess.run([NSG_EXE, *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise RuntimeError(f"nsgraph {' '.join(map(str, args))} exited {r.returncode}: {r.stderr}")
    return r


def read_json(path):
    with open(path) as f:
        return json.load(f)


def _build_key(*files):
    st = os.stat(NSG_EXE)
    h = hashlib.sha256(f"{st.st_size}-{st.st_mtime_ns}".encode())
    for f in files:
        with open(f, "rb") as fh:
            h.update(fh.read())
    return h.hexdigest()[:16]


def _cached(name, key, produce):
    root = os.path.join(BINARY_DIR, "test-cache")
    done = os.path.join(root, f"{name}-{key}")
    if os.path.isdir(done):
        return done
    os.makedirs(root, exist_ok=True)
    work = tempfile.mkdtemp(prefix=f"{name}-{key}.tmp-", dir=root)
    try:
        produce(work)
        os.rename(work, done)
    except OSError:
        if not os.path.isdir(done):
            raise
    finally:
        shutil.rmtree(work, ignore_errors=True)  # lost a race, or failed
    for other in os.listdir(root):  # older builds' copies are stale
        if other.startswith(name + "-") and ".tmp-" not in other and other != os.path.basename(done):
            shutil.rmtree(os.path.join(root, other), ignore_errors=True)
    return done


def e2e_release():
    return _cached("py_release_e2e", _build_key(SYNTH_CONFIG),
                   lambda d: run_nsgraph("synth", "--quiet", "--config", SYNTH_CONFIG, "--out", d))


def e2e_dataset(layout="tar"):
    release = e2e_release()
    return _cached(f"py_dataset_e2e_{layout}", _build_key(SYNTH_CONFIG, GENERATE_CONFIG),
                   lambda d: run_nsgraph("generate", "--quiet", "--config", GENERATE_CONFIG, "--dataroot", release,
                                         "--version", "v1.0-mini", "--out", d, "--threads", "2", "--layout", layout))


def ladder_dataset():
    """The e2e dataset with an observation ladder (generate --ladder: rungs 1, 2, 4, all)."""
    release = e2e_release()
    return _cached("py_dataset_e2e_ladder", _build_key(SYNTH_CONFIG, GENERATE_CONFIG),
                   lambda d: run_nsgraph("generate", "--quiet", "--config", GENERATE_CONFIG, "--dataroot", release,
                                         "--version", "v1.0-mini", "--out", d, "--threads", "2", "--ladder"))


if __name__ == "__main__":  # the CTest fixture step: make both layouts once
    print(e2e_dataset("tar"))
    print(e2e_dataset("folder"))
    print(ladder_dataset())
