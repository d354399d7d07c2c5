"""The PEP 517 build backend of the `nsgraph` Python package (pyproject.toml names it).

The package is what CMake assembles in <build>/python/nsgraph: the pure-Python modules, the
pybind11 extension _nsgraph and the schemas the submission checks need. This backend builds
that one CMake target and zips the folder into a wheel. It needs nothing but the standard
library of the interpreter that runs pip (no setuptools, no `wheel` package, nothing
downloaded), so `pip install .` works from a venv of any CPython >= 3.9; the C++ dependencies
are Debian packages (cmake/debian-packages.txt, `make deps`).

The extension is built for the interpreter running the backend. The project's build folder
(NSGRAPH_BUILD_DIR, default ./build, the one `make` uses) is reused when its interpreter has
the same extension ABI (EXT_SUFFIX, e.g. any CPython 3.11 against Debian's); another ABI gets
its own build folder <build>/python-abi/<EXT_SUFFIX> configured for this interpreter, which
compiles the libraries once more (about 15 minutes on two cores, once per interpreter).
"""
import ast
import base64
import hashlib
import io
import os
import re
import subprocess
import sys
import sysconfig
import tarfile
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
NAME = "nsgraph"
# Fixed timestamp for every zip member: the same build gives the same wheel bytes.
ZIP_TIME = (2020, 1, 1, 0, 0, 0)


class BuildError(RuntimeError):
    """A build step failed; the message says which and what to do."""


def _project_version():
    """The version of CMakeLists.txt's project(): one number for the library and the package."""
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(nsgraph VERSION ([0-9.]+)", f.read())
    if not match:
        raise BuildError("CMakeLists.txt: expected `project(nsgraph VERSION x.y.z ...)`")
    return match.group(1)


def _pyproject_field(pattern):
    with open(os.path.join(ROOT, "pyproject.toml"), encoding="utf-8") as f:
        match = re.search(pattern, f.read(), re.MULTILINE)
    return match.group(1) if match else None


def _table(text, name):
    """The body of the TOML table `[name]` (up to the next table header), or ""."""
    match = re.search(r"^\[" + re.escape(name) + r"\][ \t]*$(.*?)(?=^\[|\Z)", text, re.MULTILINE | re.DOTALL)
    return match.group(1) if match else ""


def _string_array(value, where):
    """A TOML array of plain strings, e.g. ["numpy", "torch>=2"] (the only form these tables use)."""
    try:
        items = ast.literal_eval(value)
    except (ValueError, SyntaxError):
        items = None
    if not isinstance(items, list) or not all(isinstance(i, str) for i in items):
        raise BuildError(f"pyproject.toml: {where}: expected an array of strings, got {value!r}")
    return items


def _dependencies():
    """[project] dependencies and [project.optional-dependencies], read from pyproject.toml so
    the wheel's metadata says what the project file says."""
    with open(os.path.join(ROOT, "pyproject.toml"), encoding="utf-8") as f:
        text = f.read()
    match = re.search(r"^dependencies\s*=\s*(\[.*?\])", _table(text, "project"), re.MULTILINE | re.DOTALL)
    dependencies = _string_array(match.group(1), "project.dependencies") if match else []
    extras = {}
    for m in re.finditer(r"^([A-Za-z0-9_.-]+)\s*=\s*(\[.*?\])", _table(text, "project.optional-dependencies"),
                         re.MULTILINE | re.DOTALL):
        extras[m.group(1)] = _string_array(m.group(2), "project.optional-dependencies." + m.group(1))
    return dependencies, extras


def _metadata():
    """METADATA (core metadata 2.1) from pyproject.toml's [project] table, read by pattern:
    tomllib is 3.11+, and the table holds only the plain fields below."""
    lines = ["Metadata-Version: 2.1", f"Name: {NAME}", f"Version: {_project_version()}"]
    summary = _pyproject_field(r'^description\s*=\s*"(.*)"')
    if summary:
        lines.append(f"Summary: {summary}")
    requires_python = _pyproject_field(r'^requires-python\s*=\s*"(.*)"')
    if requires_python:
        lines.append(f"Requires-Python: {requires_python}")
    dependencies, extras = _dependencies()
    lines += [f"Requires-Dist: {d}" for d in dependencies]
    for extra, requirements in extras.items():
        lines.append(f"Provides-Extra: {extra}")
        lines += [f'Requires-Dist: {d}; extra == "{extra}"' for d in requirements]
    readme = os.path.join(ROOT, "python", "README.md")
    body = ""
    if os.path.exists(readme):
        lines.append("Description-Content-Type: text/markdown")
        with open(readme, encoding="utf-8") as f:
            body = "\n" + f.read()
    return "\n".join(lines) + "\n" + body


def _interpreter_ext_suffix(python):
    out = subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_config_var('EXT_SUFFIX'))"],
                         capture_output=True, text=True)
    return out.stdout.strip() if out.returncode == 0 else None


def _cached_python(build_dir):
    cache = os.path.join(build_dir, "CMakeCache.txt")
    if not os.path.exists(cache):
        return None
    with open(cache, encoding="utf-8", errors="replace") as f:
        match = re.search(r"^Python3_EXECUTABLE:[A-Z]+=(.*)$", f.read(), re.MULTILINE)
    return match.group(1).strip() if match else None


def _run(argv):
    print("nsgraph build:", " ".join(argv), flush=True)
    result = subprocess.run(argv, stdout=sys.stderr)
    if result.returncode != 0:
        raise BuildError(f"`{' '.join(argv)}` exited {result.returncode}; its output is above. The C++ "
                         "dependencies come from `make deps` (Debian packages, cmake/debian-packages.txt).")


def _build_folder():
    """The CMake build folder whose extension this interpreter can load (see the module doc)."""
    project_build = os.path.abspath(os.environ.get("NSGRAPH_BUILD_DIR", os.path.join(ROOT, "build")))
    mine = sysconfig.get_config_var("EXT_SUFFIX")
    cached = _cached_python(project_build)
    if cached is None or _interpreter_ext_suffix(cached) == mine:
        return project_build, cached is None
    abi = re.sub(r"[^A-Za-z0-9_.-]", "_", mine.strip("."))
    return os.path.join(project_build, "python-abi", abi), True


def _build_package():
    build_dir, configure_for_me = _build_folder()
    if not os.path.exists(os.path.join(build_dir, "CMakeCache.txt")):
        argv = ["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release", "-DNSG_BUILD_TESTS=OFF",
                "-DNSG_BUILD_BENCH=OFF"]
        if configure_for_me:
            argv.append(f"-DPython3_EXECUTABLE={sys.executable}")
        _run(argv)
    jobs = os.environ.get("NSGRAPH_BUILD_JOBS", str(os.cpu_count() or 1))
    _run(["cmake", "--build", build_dir, "--target", "nsgraph_python", "-j", jobs])
    package = os.path.join(build_dir, "python", NAME)
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    if not os.path.exists(os.path.join(package, "_nsgraph" + suffix)):
        raise BuildError(f"{package}: the build made no _nsgraph{suffix} for {sys.executable}")
    return package


def _wheel_tag():
    """cpXY-cpXY<abiflags>-<platform>: the extension binds the wheel to one interpreter ABI."""
    version = f"{sys.version_info.major}{sys.version_info.minor}"
    platform = re.sub(r"[^A-Za-z0-9]", "_", sysconfig.get_platform())
    return f"cp{version}", f"cp{version}{getattr(sys, 'abiflags', '')}", platform


def _record_line(path, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{path},sha256={digest},{len(data)}"


def _write_member(archive, path, data, records, mode=0o644):
    info = zipfile.ZipInfo(path, date_time=ZIP_TIME)
    info.external_attr = (0o100000 | mode) << 16
    info.compress_type = zipfile.ZIP_DEFLATED
    archive.writestr(info, data)
    records.append(_record_line(path, data))


def _package_files(package):
    files = []
    for folder, dirs, names in os.walk(package):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(names):
            full = os.path.join(folder, name)
            files.append((os.path.relpath(full, os.path.dirname(package)).replace(os.sep, "/"), full))
    return files


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    package = _build_package()
    python_tag, abi_tag, platform_tag = _wheel_tag()
    version = _project_version()
    wheel_name = f"{NAME}-{version}-{python_tag}-{abi_tag}-{platform_tag}.whl"
    dist_info = f"{NAME}-{version}.dist-info"
    os.makedirs(wheel_directory, exist_ok=True)
    target = os.path.join(wheel_directory, wheel_name)
    records = []
    with zipfile.ZipFile(target + ".part", "w") as archive:
        for rel, full in _package_files(package):
            with open(full, "rb") as f:
                data = f.read()
            _write_member(archive, rel, data, records, 0o755 if os.access(full, os.X_OK) else 0o644)
        _write_member(archive, f"{dist_info}/METADATA", _metadata().encode(), records)
        wheel = (f"Wheel-Version: 1.0\nGenerator: nsgraph_build\nRoot-Is-Purelib: false\n"
                 f"Tag: {python_tag}-{abi_tag}-{platform_tag}\n")
        _write_member(archive, f"{dist_info}/WHEEL", wheel.encode(), records)
        records.append(f"{dist_info}/RECORD,,")
        info = zipfile.ZipInfo(f"{dist_info}/RECORD", date_time=ZIP_TIME)
        info.external_attr = (0o100644) << 16
        archive.writestr(info, "\n".join(records) + "\n")
    os.replace(target + ".part", target)
    return wheel_name


def build_sdist(sdist_directory, config_settings=None):
    """The tracked files (git ls-files): the sources CMake needs, nothing built."""
    listing = subprocess.run(["git", "-C", ROOT, "ls-files", "-z"], capture_output=True)
    if listing.returncode != 0:
        raise BuildError(f"{ROOT}: an sdist is made from a git checkout (git ls-files failed)")
    base = f"{NAME}-{_project_version()}"
    target = os.path.join(sdist_directory, base + ".tar.gz")
    with tarfile.open(target + ".part", "w:gz", format=tarfile.PAX_FORMAT) as archive:
        pkg_info = _metadata().encode()
        info = tarfile.TarInfo(f"{base}/PKG-INFO")
        info.size, info.mode = len(pkg_info), 0o644
        archive.addfile(info, io.BytesIO(pkg_info))
        for rel in sorted(p for p in listing.stdout.decode().split("\0") if p):
            info = archive.gettarinfo(os.path.join(ROOT, rel), arcname=f"{base}/{rel}")
            info.mtime, info.uid, info.gid, info.uname, info.gname = 0, 0, 0, "", ""
            if info.isreg():
                with open(os.path.join(ROOT, rel), "rb") as f:
                    archive.addfile(info, f)
            else:
                archive.addfile(info)
    os.replace(target + ".part", target)
    return os.path.basename(target)


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []
