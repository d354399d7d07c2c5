"""The repository stands alone: checks on the tracked files themselves.

1. No file refers to a path outside the repository: the team's workbench next to the
   clone, or an absolute path on a developer's machine (a user who clones only this
   repository has neither).
2. Code comments say what and why, not which tracker issue asked for it.
3. Every Markdown document a file names (`docs/metrics.md`, `README.md`, ...) exists in the
   repository: a reader must be able to open what the code cites.
4. The README's Layout block names every module under lib/ and every top-level folder,
   and every folder it names exists.

Run from anywhere: python3 tests/repo/check_repository.py [REPO_ROOT]. Exit 0 clean, 1 with
a list of "path:line: what" findings.
"""
import os
import re
import subprocess
import sys

# Spelled in pieces so that this file does not match its own patterns.
WORKBENCH = re.compile(re.escape("../" + "shared") + r"\b")
MACHINE_PATH = re.compile(r"(?<![\w.~-])/(?:" + "|".join(["work", "root", "home", "Users"]) + r")/")
MARKDOWN_NAME = re.compile(r"(?<![\w/.-])((?:[\w.-]+/)*[\w-]+\.md)\b")
# Reports the project writes (make bench, make ablation, make baselines), not documents.
GENERATED_MD = {"bench.md", "ablation.md", "baselines.md"}
ISSUE_NUMBER = re.compile(r"\b[Ii]ssues? #?\d+|\b[Ii]ssues \d+ and \d+")
CODE_SUFFIXES = (".cpp", ".h", ".hpp", ".py", ".sh", ".cmake", ".txt", ".toml", ".in")
CODE_NAMES = ("Makefile", "CMakeLists.txt", "run")
SKIP_DIRS = {".git", "build", "build-fuzz", "demo-out", "bench-out", "__pycache__"}


def tracked_files(root):
    """git ls-files when the tree is a clone; otherwise every file outside build output."""
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], check=True,
                             capture_output=True).stdout
        return [p for p in out.decode().split("\0") if p]
    except (OSError, subprocess.CalledProcessError):
        files = []
        for dirpath, dirnames, filenames in os.walk(root):
            dirnames[:] = [d for d in dirnames if d not in SKIP_DIRS and not d.startswith("build")]
            files += [os.path.relpath(os.path.join(dirpath, f), root) for f in filenames]
        return sorted(files)


def read_text(path):
    """The file's text, or None for binary files (images, models, sensor data)."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError:
        return None
    if b"\0" in data[:8192]:
        return None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def is_code(rel):
    name = os.path.basename(rel)
    return name.endswith(CODE_SUFFIXES) or name in CODE_NAMES


def check_paths_and_comments(root, files):
    findings = []
    names = {os.path.basename(f) for f in files}
    for rel in files:
        text = read_text(os.path.join(root, rel))
        if text is None:
            continue
        code = is_code(rel)
        for number, line in enumerate(text.splitlines(), 1):
            if WORKBENCH.search(line):
                findings.append(f"{rel}:{number}: refers to a folder outside the repository")
            if MACHINE_PATH.search(line):
                findings.append(f"{rel}:{number}: absolute path on a developer's machine")
            for doc in MARKDOWN_NAME.findall(line):
                if os.path.basename(doc) not in names | GENERATED_MD:
                    findings.append(f"{rel}:{number}: names {doc}, which is not in the repository")
            if code and ISSUE_NUMBER.search(line):
                findings.append(f"{rel}:{number}: cites a tracker issue number (say what and why)")
    return findings


def layout_block(readme_text):
    """The first fenced block after the '## Layout' heading."""
    section = readme_text.split("\n## Layout", 1)
    if len(section) < 2:
        return None
    match = re.search(r"```\n(.*?)```", section[1], re.S)
    return match.group(1) if match else None


def check_layout(root, files):
    readme = read_text(os.path.join(root, "README.md")) or ""
    block = layout_block(readme)
    if block is None:
        return ["README.md: no '## Layout' section with a fenced block"]
    findings = []
    words = set(re.findall(r"[\w.-]+", block))
    modules = sorted({f.split("/")[1] for f in files if f.startswith("lib/") and f.count("/") >= 2})
    for module in modules:
        if module not in words:
            findings.append(f"README.md: Layout does not name the module lib/{module}")
    top = sorted({f.split("/")[0] for f in files if "/" in f and not f.startswith(".")})
    for folder in top:
        if not re.search(r"(^|\s)" + re.escape(folder) + "/", block, re.M):
            findings.append(f"README.md: Layout does not name the folder {folder}/")
    for named in re.findall(r"(?:^|\s)((?:[\w.-]+/)+)(?=\s|$)", block, re.M):
        if "<" in named or not os.path.isdir(os.path.join(root, named)):
            if "<" not in named:
                findings.append(f"README.md: Layout names {named}, which does not exist")
    return findings


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                           os.path.join(os.path.dirname(__file__), "..", ".."))
    files = tracked_files(root)
    if not files:
        print(f"{root}: no files found", file=sys.stderr)
        return 2
    findings = check_paths_and_comments(root, files) + check_layout(root, files)
    for f in findings:
        print(f)
    print(f"{len(files)} files checked, {len(findings)} findings")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
