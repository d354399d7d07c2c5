"""The repository stands alone: checks on the tracked files themselves.

1. No file refers to a path outside the repository: the team's workbench next to the
   clone, or an absolute path on a developer's machine (a user who clones only this
   repository has neither).
2. Code comments say what and why, not which tracker issue asked for it.
3. Every Markdown document a file names (`docs/metrics.md`, `README.md`, ...) exists in the
   repository: a reader must be able to open what the code cites.
4. The README's Layout block names every module under lib/ and every top-level folder,
   and every folder it names exists.
5. Every relative link in a Markdown file ([text](path) or [text](path#anchor)) leads to a
   file or folder that exists, and an anchor to a heading of the linked Markdown file
   (GitHub's heading ids). Links inside fenced code blocks are not links.
6. Every figure has a producer. A figure marker is a line of its own,
       <!-- figures: make TARGET (PATH, PATH, ...) YYYY-MM-DD -->
   naming the make target and/or the committed scripts that produce the figures below it,
   and the date they were measured. In README.md and docs/, each marker's make targets
   must be Makefile targets, its paths must exist, and it must name at least one of them
   and a date. In README.md, a Markdown table with a figure in a row (a number with a
   unit: s, ms, min, sweeps/s, tiles/s, MB, MiB, GB, GiB, %, ×, ... or a decimal such as
   0.369) must have a marker above its header row (blank lines and one paragraph may lie
   between).
7. The contributor guides (docs/architecture.md's "Adding …" sections) describe today's
   code: every file they name exists, every code name (`kSemanticClasses`,
   `crop_option_table()`, `Table::check`) occurs in the code and every ctest name in the
   tests; "Adding an option" is done by tests/unit/core/test_adding_an_option.cpp with the
   guide's own declaration line.

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
GENERATED_MD = {"bench.md", "ablation.md", "baselines.md", "ladder.md", "map-update.md"}
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


FENCE = re.compile(r"^\s*(```|~~~)")
LINK = re.compile(r"\[[^\]]*\]\(([^()\s]+)\)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


def prose_lines(text):
    """(line number, line) of a Markdown text outside its fenced code blocks."""
    fenced = False
    for number, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            yield number, line


def heading_ids(text):
    """GitHub's ids of a Markdown text's headings: lower case, punctuation dropped, spaces
    to hyphens, a repeated id numbered -1, -2, ..."""
    ids, seen = set(), {}
    for _, line in prose_lines(text):
        m = HEADING.match(line)
        if not m:
            continue
        title = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", m.group(2))  # a link's text
        slug = re.sub(r"[^\w\- ]", "", title.lower().replace("`", "")).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        ids.add(slug if n == 0 else f"{slug}-{n}")
    return ids


def check_links(root, files):
    findings = []
    anchors = {}
    for rel in files:
        if not rel.endswith(".md"):
            continue
        text = read_text(os.path.join(root, rel)) or ""
        for number, line in prose_lines(text):
            for target in LINK.findall(line):
                if re.match(r"[a-z][a-z0-9+.-]*:", target):  # https:, mailto:, ...
                    continue
                path, _, anchor = target.partition("#")
                linked = os.path.normpath(os.path.join(os.path.dirname(rel), path)) if path else rel
                if not os.path.exists(os.path.join(root, linked)):
                    findings.append(f"{rel}:{number}: links to {target}, which does not exist")
                    continue
                if anchor and linked.endswith(".md"):
                    if linked not in anchors:
                        anchors[linked] = heading_ids(read_text(os.path.join(root, linked)) or "")
                    if anchor not in anchors[linked]:
                        findings.append(f"{rel}:{number}: links to {target}, a heading {linked} does not have")
    return findings


FIGURE_MARKER = re.compile(r"^\s*<!--\s*figures:\s*(.*?)\s*-->\s*$")
DATE = re.compile(r"\b\d{4}-\d{2}-\d{2}\b")
# A number with a unit, or a decimal (a score): what a table row states as a measurement.
FIGURE = re.compile(r"\d(?:[\d,.]|\s(?=\d))*\s?(?:µs|ms|s|min|h|[kKMG]?B|MiB|GiB|(?:sweeps|tiles|images|frames)/s"
                    r"|MB/s|%|×)(?![\w/])|\b\d+\.\d+\b")


def makefile_targets(root):
    text = read_text(os.path.join(root, "Makefile")) or ""
    return set(re.findall(r"^([\w.-]+)\s*:(?!=)", text, re.M))


def check_marker(rel, number, body, root, targets):
    """Findings for one marker's text: its make targets, its paths and its date."""
    findings = []
    makes = re.findall(r"\bmake\s+([\w.-]+)", body)
    paths = [p.strip() for group in re.findall(r"\(([^)]*)\)", body) for p in group.split(",") if p.strip()]
    for target in makes:
        if target not in targets:
            findings.append(f"{rel}:{number}: figure marker names make {target}, which the Makefile does not define")
    for path in paths:
        if not os.path.exists(os.path.join(root, path)):
            findings.append(f"{rel}:{number}: figure marker names {path}, which is not in the repository")
    if not makes and not paths:
        findings.append(f"{rel}:{number}: figure marker names no make target or script")
    if not DATE.search(body):
        findings.append(f"{rel}:{number}: figure marker has no date (YYYY-MM-DD)")
    return findings


def marked_above(lines, header):
    """Whether a figure marker lies above line index `header`: blank lines, at most one
    paragraph, blank lines, then the marker."""
    i, paragraphs = header - 1, 0
    while i >= 0:
        if FIGURE_MARKER.match(lines[i]):
            return True
        if lines[i].strip():
            if paragraphs == 1:
                return False
            paragraphs = 1
            while i >= 0 and lines[i].strip() and not FIGURE_MARKER.match(lines[i]):
                i -= 1
            continue
        i -= 1
    return False


def check_figures(root, files):
    findings = []
    targets = makefile_targets(root)
    for rel in files:
        if not (rel == "README.md" or (rel.startswith("docs/") and rel.endswith(".md"))):
            continue
        text = read_text(os.path.join(root, rel)) or ""
        for number, line in prose_lines(text):
            m = FIGURE_MARKER.match(line)
            if m:
                findings += check_marker(rel, number, m.group(1), root, targets)
        if rel != "README.md":
            continue
        # Tables of README.md: runs of prose lines starting with '|'; the first is the header.
        lines = text.splitlines()
        prose = dict(prose_lines(text))
        number = 1
        while number <= len(lines):
            if not (number in prose and lines[number - 1].lstrip().startswith("|")):
                number += 1
                continue
            header = number
            while number <= len(lines) and number in prose and lines[number - 1].lstrip().startswith("|"):
                number += 1
            rows = range(header + 2, number)  # after the header and its rule
            figure_rows = [r for r in rows if FIGURE.search(lines[r - 1])]
            if figure_rows and not marked_above(lines, header - 1):
                findings += [f"{rel}:{r}: a figure with no producer marker" for r in figure_rows]
    return findings


# Guides whose names and paths must exist (docs/architecture.md's "Adding …" sections), and
# the test that does what "Adding an option" shows with the guide's own declaration line.
GUIDE = "docs/architecture.md"
GUIDE_DONE = {"Adding an option": "tests/unit/core/test_adding_an_option.cpp"}
CODE_SPAN = re.compile(r"`([^`]+)`", re.S)
CODE_NAME = re.compile(r"[A-Za-z_][\w:./*-]*")
# Spans that are examples of what a contributor would add, not names of today's code.
GUIDE_EXAMPLE = re.compile(r"foo|<name>|\bheight\b")


def guide_sections(text):
    """(title, first line number, body) of each "## Adding …" section."""
    sections, start = [], None
    lines = text.split("\n")
    for number, line in enumerate(lines + ["## end"], 1):
        if line.startswith("## "):
            if start is not None:
                sections.append((lines[start - 1][3:], start, "\n".join(lines[start:number - 1])))
            start = number if line.startswith("## Adding ") else None
    return sections


def names_a_file(root, files, token):
    """A path as the guides write it: from the root, from lib/, or the tail of a module's path."""
    token = token.rstrip(".,:;")
    if any(os.path.exists(os.path.join(root, c)) for c in (token, "lib/" + token)):
        return True
    return any(f.endswith("/" + token) or f.startswith(token.rstrip("/") + "/") for f in files)


def check_guides(root, files):
    """7. Every path and code name in the guides exists; a guide with a test is done there."""
    text = read_text(os.path.join(root, GUIDE)) or ""
    code = "\n".join(read_text(os.path.join(root, f)) or "" for f in files
                     if is_code(f) or f.endswith((".json", ".js")))
    tests = "\n".join(read_text(os.path.join(root, f)) or "" for f in files if f.startswith("tests/"))
    findings = []
    for title, first, body in guide_sections(text):
        for span in CODE_SPAN.findall(body):
            if GUIDE_EXAMPLE.search(span):
                continue
            for token in CODE_NAME.findall(span):
                line = first + body[:body.find(span)].count("\n") + 1
                if re.fullmatch(r"\w+/[A-Z]\w*\.\w+", token):  # a ctest name: module/Suite.Test
                    if not re.search(r"\b" + r",\s*".join(token.split("/")[1].split(".")) + r"\)", tests):
                        findings.append(f"{GUIDE}:{line}: {title}: `{token}` is no test of the repository")
                elif "/" in token and "." in token.split("/")[-1] or token.endswith("/"):
                    if not names_a_file(root, files, token):
                        findings.append(f"{GUIDE}:{line}: {title}: `{token}` is no file of the repository")
                elif re.fullmatch(r"k[A-Z]\w*\*?|\w+_\w+|\w+(::\w+)+", token):
                    name = token.split("::")[-1].rstrip("*")
                    if not re.search(r"\b" + re.escape(name) + ("" if token.endswith("*") else r"\b"), code):
                        findings.append(f"{GUIDE}:{line}: {title}: `{token}` is named nowhere in the code")
        test = GUIDE_DONE.get(title)
        if test:
            shown = ["".join(s.split()) for s in CODE_SPAN.findall(body) if s.startswith("t.")]
            done = "".join((read_text(os.path.join(root, test)) or "").split())
            findings += [f"{GUIDE}:{first}: {title}: its declaration `{s}` is not what {test} does"
                         for s in shown if s not in done]
    return findings


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                           os.path.join(os.path.dirname(__file__), "..", ".."))
    files = tracked_files(root)
    if not files:
        print(f"{root}: no files found", file=sys.stderr)
        return 2
    findings = (check_paths_and_comments(root, files) + check_layout(root, files) + check_links(root, files)
                + check_figures(root, files) + check_guides(root, files))
    for f in findings:
        print(f)
    print(f"{len(files)} files checked, {len(findings)} findings")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
